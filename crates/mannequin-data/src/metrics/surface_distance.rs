//! Exact point-to-surface distance against a triangle mesh: a bounding-volume hierarchy over the
//! triangles, searched nearest-box-first and pruned by box distance.

use glam::DVec3;

use super::point_triangle::closest_point_on_triangle;

struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: triangles `order[start..start + count]`. Inner (count 0): children `left`, `left + 1`.
    start: u32,
    count: u32,
    left: u32,
}

pub struct TriangleBvh {
    tris: Vec<[DVec3; 3]>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

const LEAF: usize = 4;

/// The closest surface point to a query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    pub face: usize,
    pub point: DVec3,
    pub distance_squared: f64,
}

fn box_distance_squared(p: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    (lo - p).max(p - hi).max(DVec3::ZERO).length_squared()
}

impl TriangleBvh {
    pub fn new(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Self {
        let tris: Vec<[DVec3; 3]> =
            faces.iter().map(|f| f.map(|i| DVec3::from(positions[i as usize].map(f64::from)))).collect();
        let mut bvh = Self { order: (0..tris.len() as u32).collect(), tris, nodes: Vec::new() };
        if !bvh.tris.is_empty() {
            bvh.nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, start: 0, count: 0, left: 0 });
            bvh.build(0, 0, bvh.tris.len());
        }
        bvh
    }

    fn build(&mut self, node: usize, start: usize, end: usize) {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &t in &self.order[start..end] {
            let tri = &self.tris[t as usize];
            for v in tri {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
            let c = (tri[0] + tri[1] + tri[2]) / 3.0;
            clo = clo.min(c);
            chi = chi.max(c);
        }
        self.nodes[node].lo = lo;
        self.nodes[node].hi = hi;
        if end - start <= LEAF {
            self.nodes[node].start = start as u32;
            self.nodes[node].count = (end - start) as u32;
            return;
        }
        let ext = chi - clo;
        let ax = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = (end - start) / 2;
        let tris = &self.tris;
        let centroid = |t: u32| tris[t as usize].iter().map(|v| v[ax]).sum::<f64>();
        self.order[start..end].select_nth_unstable_by(mid, |&a, &b| centroid(a).total_cmp(&centroid(b)));
        let left = self.nodes.len();
        self.nodes[node].left = left as u32;
        for _ in 0..2 {
            self.nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, start: 0, count: 0, left: 0 });
        }
        self.build(left, start, start + mid);
        self.build(left + 1, start + mid, end);
    }

    /// The closest point of the surface to `p` (`None` for a mesh without faces).
    pub fn closest(&self, p: DVec3) -> Option<SurfaceHit> {
        let mut best: Option<SurfaceHit> = None;
        let mut best_d = f64::INFINITY;
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let Some(node) = self.nodes.get(n) else { continue };
            if box_distance_squared(p, node.lo, node.hi) >= best_d {
                continue;
            }
            if node.count > 0 {
                for &t in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    let [a, b, c] = self.tris[t as usize];
                    let q = closest_point_on_triangle(p, a, b, c);
                    let d = q.distance_squared(p);
                    if d < best_d {
                        best_d = d;
                        best = Some(SurfaceHit { face: t as usize, point: q, distance_squared: d });
                    }
                }
                continue;
            }
            let (l, r) = (node.left as usize, node.left as usize + 1);
            let dl = box_distance_squared(p, self.nodes[l].lo, self.nodes[l].hi);
            let dr = box_distance_squared(p, self.nodes[r].lo, self.nodes[r].hi);
            // Push the farther child first so the nearer one is searched first.
            if dl < dr {
                stack.extend([r, l]);
            } else {
                stack.extend([l, r]);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force_over_all_triangles() {
        let mut r = mannequin_io::rng::SplitMix64::new(9);
        let positions: Vec<[f32; 3]> = (0..300).map(|_| [0; 3].map(|_| r.normal() as f32)).collect();
        let faces: Vec<[u32; 3]> = (0..200).map(|_| [0; 3].map(|_| r.below(300) as u32)).collect();
        let bvh = TriangleBvh::new(&positions, &faces);
        for _ in 0..300 {
            let p = DVec3::new(r.normal(), r.normal(), r.normal()) * 1.5;
            let hit = bvh.closest(p).unwrap();
            let brute = faces
                .iter()
                .map(|f| {
                    let [a, b, c] = f.map(|i| DVec3::from(positions[i as usize].map(f64::from)));
                    closest_point_on_triangle(p, a, b, c).distance_squared(p)
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(hit.distance_squared, brute);
        }
        assert!(TriangleBvh::new(&positions, &[]).closest(DVec3::ZERO).is_none());
    }
}
