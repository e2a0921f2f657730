//! Isotropic remeshing (Botsch & Kobbelt 2004, "A remeshing approach to multiresolution
//! modeling"): split edges longer than 4/3·L, collapse edges shorter than 4/5·L, flip edges
//! towards valence 6 (4 on a boundary), relax vertices tangentially, and put every vertex back
//! on the surface being remeshed. Cloth needs the near-uniform triangles that come out: the body
//! mesh's range from 2 mm to 5 cm, and an XPBD step is as stiff as its shortest edge allows.

use glam::Vec3;

use crate::TriMesh;

/// Edge-length bounds relative to the target, Botsch & Kobbelt's 4/3 and 4/5.
const LONG: f32 = 4.0 / 3.0;
const SHORT: f32 = 4.0 / 5.0;
/// An edge is split only if each face on it has twice its area at least this share of the
/// edge's length squared (an angle of about 3° at the opposite corner of a right triangle).
const MIN_SPLIT_SINE: f32 = 0.05;
/// A flip may not make a face whose twice-area is below this share of the new edge's length
/// squared.
const MIN_FLIP_SINE: f32 = 1e-3;
/// A flip or collapse may not turn a face by more than this (cosine of about 60°).
const MIN_NORMAL_DOT: f32 = 0.5;

/// Remeshes an open or closed manifold mesh to edge length ≈ `target` with `iterations` rounds;
/// `project` takes a point near the surface to the surface. Boundaries keep their place (their
/// vertices only slide along them through splits and collapses of boundary edges).
pub fn remesh(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    target: f32,
    iterations: usize,
    project: impl Fn(Vec3) -> Vec3,
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut mesh = Working::new(positions, faces);
    for _ in 0..iterations {
        mesh.split_long_edges(LONG * target);
        mesh.collapse_short_edges(SHORT * target, LONG * target);
        mesh.flip_to_regular_valence(|_| true);
        mesh.relax();
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            if !mesh.incident[v].is_empty() {
                *p = project(*p);
            }
        }
    }
    mesh.compact()
}

/// NGD's adaptive step (§3.2): splits each of `edges` at its midpoint, then flips edges toward
/// valence 6 (4 on a boundary) where that brings the four vertices involved closer to it, among
/// the edges at the split ones' ends. No vertex moves (a flip changes the surface only where its
/// two faces are not coplanar); the old vertices keep their indices and the new ones follow.
pub fn split_and_flip(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    edges: &[[u32; 2]],
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut mesh = Working::new(positions, faces);
    let mut touched = vec![false; positions.len()];
    for &[a, b] in edges {
        // A sliver's halves would be slivers again, down to faces f32 cannot tell from lines.
        let sliver = mesh.edge_faces(a, b).into_iter().any(|f| {
            let area = mesh.normal(mesh.faces[f as usize]).length();
            area < MIN_SPLIT_SINE * mesh.length((a, b)).powi(2)
        });
        if !sliver && mesh.split(a, b).is_some() {
            touched[a as usize] = true;
            touched[b as usize] = true;
        }
    }
    touched.resize(mesh.positions.len(), true);
    mesh.flip_to_regular_valence(|(a, b)| touched[a as usize] || touched[b as usize]);
    mesh.compact()
}

/// Faces with per-vertex incidence lists, edited in place; dead faces are flagged.
struct Working {
    positions: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
    alive: Vec<bool>,
    incident: Vec<Vec<u32>>,
}

impl Working {
    fn new(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Self {
        let mut incident = vec![Vec::new(); positions.len()];
        for (f, tri) in faces.iter().enumerate() {
            for &v in tri {
                incident[v as usize].push(f as u32);
            }
        }
        Self {
            positions: positions.iter().map(|&p| Vec3::from(p)).collect(),
            faces: faces.to_vec(),
            alive: vec![true; faces.len()],
            incident,
        }
    }

    /// Faces holding both a and b.
    fn edge_faces(&self, a: u32, b: u32) -> Vec<u32> {
        self.incident[a as usize].iter().copied().filter(|&f| self.faces[f as usize].contains(&b)).collect()
    }

    fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.incident[v as usize]
            .iter()
            .flat_map(|&f| self.faces[f as usize])
            .filter(|&u| u != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    fn is_boundary(&self, v: u32) -> bool {
        self.neighbours(v).into_iter().any(|u| self.edge_faces(v, u).len() == 1)
    }

    /// Every live edge once, as (low, high).
    fn edges(&self) -> Vec<(u32, u32)> {
        let mut e: Vec<(u32, u32)> = self
            .faces
            .iter()
            .zip(&self.alive)
            .filter(|(_, alive)| **alive)
            .flat_map(|(t, _)| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        e.sort_unstable();
        e.dedup();
        e
    }

    fn length(&self, (a, b): (u32, u32)) -> f32 {
        self.positions[a as usize].distance(self.positions[b as usize])
    }

    fn normal(&self, tri: [u32; 3]) -> Vec3 {
        let [a, b, c] = tri.map(|i| self.positions[i as usize]);
        (b - a).cross(c - a)
    }

    fn opposite(&self, f: u32, a: u32, b: u32) -> u32 {
        self.faces[f as usize].into_iter().find(|&v| v != a && v != b).unwrap_or(a)
    }

    fn split_long_edges(&mut self, long: f32) {
        let mut long_edges: Vec<((u32, u32), f32)> =
            self.edges().into_iter().map(|e| (e, self.length(e))).filter(|&(_, l)| l > long).collect();
        long_edges.sort_by(|x, y| y.1.total_cmp(&x.1));
        // Each split halves an edge; the halves go round again until none is long.
        while !long_edges.is_empty() {
            let mut next = Vec::new();
            for ((a, b), _) in long_edges {
                let Some(m) = self.split(a, b) else { continue };
                for e in [(a, m), (m, b)] {
                    let l = self.length(e);
                    if l > long {
                        next.push((e, l));
                    }
                }
            }
            long_edges = next;
        }
    }

    /// Splits edge a–b at its midpoint (each face on it into two); the new vertex, or None where
    /// the edge is gone or has more than two faces.
    fn split(&mut self, a: u32, b: u32) -> Option<u32> {
        let around = self.edge_faces(a, b);
        if around.is_empty() || around.len() > 2 {
            return None;
        }
        let m = self.positions.len() as u32;
        self.positions.push(0.5 * (self.positions[a as usize] + self.positions[b as usize]));
        self.incident.push(Vec::new());
        for f in around {
            let tri = self.faces[f as usize];
            let c = self.opposite(f, a, b);
            let g = self.faces.len() as u32;
            self.faces.push(tri.map(|v| if v == a { m } else { v }));
            self.alive.push(true);
            self.faces[f as usize] = tri.map(|v| if v == b { m } else { v });
            self.incident[b as usize].retain(|&h| h != f);
            self.incident[b as usize].push(g);
            self.incident[c as usize].push(g);
            self.incident[m as usize].extend([f, g]);
        }
        Some(m)
    }

    fn collapse_short_edges(&mut self, short: f32, long: f32) {
        let mut short_edges: Vec<((u32, u32), f32)> =
            self.edges().into_iter().map(|e| (e, self.length(e))).filter(|&(_, l)| l < short).collect();
        short_edges.sort_by(|x, y| x.1.total_cmp(&y.1));
        for ((a, b), _) in short_edges {
            if self.incident[a as usize].is_empty() || self.incident[b as usize].is_empty() {
                continue;
            }
            let around = self.edge_faces(a, b);
            if around.is_empty() || around.len() > 2 || self.length((a, b)) >= short {
                continue;
            }
            let (boundary_a, boundary_b) = (self.is_boundary(a), self.is_boundary(b));
            let (keep, gone, at) = match (boundary_a, boundary_b) {
                (true, true) if around.len() == 1 => {
                    (a, b, 0.5 * (self.positions[a as usize] + self.positions[b as usize]))
                }
                (true, true) => continue,
                (true, false) => (a, b, self.positions[a as usize]),
                (false, true) => (b, a, self.positions[b as usize]),
                (false, false) => (a, b, 0.5 * (self.positions[a as usize] + self.positions[b as usize])),
            };
            if self.collapse_is_valid(keep, gone, at, &around, long) {
                self.collapse(keep, gone, at, &around);
            }
        }
    }

    /// The link condition (the two ends share exactly the neighbours across the edge's faces),
    /// no edge made long, and no face turned over.
    fn collapse_is_valid(&self, keep: u32, gone: u32, at: Vec3, around: &[u32], long: f32) -> bool {
        let (nk, ng) = (self.neighbours(keep), self.neighbours(gone));
        let shared = nk.iter().filter(|v| ng.contains(v)).count();
        if shared != around.len() {
            return false;
        }
        if ng
            .iter()
            .chain(&nk)
            .any(|&v| v != keep && v != gone && self.positions[v as usize].distance(at) > long)
        {
            return false;
        }
        for v in [keep, gone] {
            for &f in &self.incident[v as usize] {
                if around.contains(&f) {
                    continue;
                }
                let tri = self.faces[f as usize];
                let before = self.normal(tri);
                let moved = tri.map(|u| if u == keep || u == gone { u32::MAX } else { u });
                let corners = moved.map(|u| if u == u32::MAX { at } else { self.positions[u as usize] });
                let after = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
                if before.normalize_or_zero().dot(after.normalize_or_zero()) < MIN_NORMAL_DOT {
                    return false;
                }
            }
        }
        true
    }

    fn collapse(&mut self, keep: u32, gone: u32, at: Vec3, around: &[u32]) {
        for &f in around {
            self.alive[f as usize] = false;
            for v in self.faces[f as usize] {
                self.incident[v as usize].retain(|&h| h != f);
            }
        }
        for f in std::mem::take(&mut self.incident[gone as usize]) {
            self.faces[f as usize] = self.faces[f as usize].map(|v| if v == gone { keep } else { v });
            self.incident[keep as usize].push(f);
        }
        self.positions[keep as usize] = at;
    }

    /// Flips the edges `consider` accepts toward regular valence.
    fn flip_to_regular_valence(&mut self, consider: impl Fn((u32, u32)) -> bool) {
        for (a, b) in self.edges().into_iter().filter(|&e| consider(e)) {
            let around = self.edge_faces(a, b);
            let [f, g] = around[..] else { continue };
            let (c, d) = (self.opposite(f, a, b), self.opposite(g, a, b));
            if c == d || self.neighbours(c).contains(&d) {
                continue;
            }
            let deviation = |w: &Self, v: u32, change: i32| {
                let target = if w.is_boundary(v) { 4 } else { 6 };
                (w.neighbours(v).len() as i32 + change - target).abs()
            };
            let before: i32 = [a, b, c, d].iter().map(|&v| deviation(self, v, 0)).sum();
            let after = deviation(self, a, -1)
                + deviation(self, b, -1)
                + deviation(self, c, 1)
                + deviation(self, d, 1);
            if after >= before {
                continue;
            }
            // Orient so that f = (a, b, c) and g = (b, a, d) in their winding.
            let tri = self.faces[f as usize];
            let k = tri.iter().position(|&v| v == a).unwrap_or(0);
            let (a, b) = if tri[(k + 1) % 3] == b { (a, b) } else { (b, a) };
            let (new_f, new_g) = ([c, a, d], [d, b, c]);
            let old = self.normal(self.faces[f as usize]).normalize_or_zero()
                + self.normal(self.faces[g as usize]).normalize_or_zero();
            // A face with no area (c, d and a corner in line: after a split, the split edge's
            // ends and its midpoint) has a normal of rounding noise, which may pass the turn test.
            let flat = MIN_FLIP_SINE * self.length((c, d)).powi(2);
            if [new_f, new_g].iter().any(|&t| {
                let n = self.normal(t);
                n.length() < flat || n.normalize_or_zero().dot(old.normalize_or_zero()) < MIN_NORMAL_DOT
            }) {
                continue;
            }
            self.faces[f as usize] = new_f;
            self.faces[g as usize] = new_g;
            self.incident[a as usize].retain(|&h| h != g);
            self.incident[b as usize].retain(|&h| h != f);
            self.incident[c as usize].push(g);
            self.incident[d as usize].push(f);
        }
    }

    /// Moves each interior vertex to its neighbours' centroid within its tangent plane.
    fn relax(&mut self) {
        let moved: Vec<Option<Vec3>> = (0..self.positions.len() as u32)
            .map(|v| {
                if self.incident[v as usize].is_empty() || self.is_boundary(v) {
                    return None;
                }
                let ring = self.neighbours(v);
                let centroid =
                    ring.iter().map(|&u| self.positions[u as usize]).sum::<Vec3>() / ring.len() as f32;
                let normal = self.incident[v as usize]
                    .iter()
                    .map(|&f| self.normal(self.faces[f as usize]))
                    .sum::<Vec3>()
                    .normalize_or_zero();
                let step = centroid - self.positions[v as usize];
                Some(self.positions[v as usize] + step - normal * normal.dot(step))
            })
            .collect();
        for (p, m) in self.positions.iter_mut().zip(moved) {
            if let Some(m) = m {
                *p = m;
            }
        }
    }

    /// Live faces and the vertices they use, renumbered in order.
    fn compact(self) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let live: Vec<usize> = (0..self.faces.len()).filter(|&f| self.alive[f]).collect();
        let positions = self.positions.iter().map(|p| p.to_array()).collect();
        let (mesh, _) = TriMesh::new(positions, self.faces).submesh(&live);
        (mesh.positions, mesh.faces)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adjacency::edges;

    /// Boundary edges (in one face only), each as (low, high).
    fn boundary_edges(faces: &[[u32; 3]]) -> Vec<(u32, u32)> {
        let mut count = std::collections::HashMap::new();
        for t in faces {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        count.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect()
    }

    /// A cylinder of radius 0.1 made of long thin triangles (8 around, 2 along 0.3 m) becomes
    /// near-uniform at L = 2 cm: every vertex on the cylinder, edge lengths within Botsch &
    /// Kobbelt's bounds (a few flips aside), consistent winding (every interior edge in two
    /// faces with opposite directions), and boundary circles as long as before.
    #[test]
    fn makes_a_thin_triangle_cylinder_uniform() {
        let (around, radius, height) = (8, 0.1f32, 0.3f32);
        let mut positions = Vec::new();
        for ring in 0..3 {
            for k in 0..around {
                let t = k as f32 / around as f32 * std::f32::consts::TAU;
                positions.push([radius * t.cos(), ring as f32 * height / 2.0, radius * t.sin()]);
            }
        }
        let mut faces = Vec::new();
        for ring in 0..2u32 {
            for k in 0..around as u32 {
                let (a, b) = (ring * 8 + k, ring * 8 + (k + 1) % 8);
                faces.push([a, b + 8, b]);
                faces.push([a, a + 8, b + 8]);
            }
        }
        let on_cylinder = |p: Vec3| {
            let r = Vec3::new(p.x, 0.0, p.z);
            Vec3::new(0.0, p.y, 0.0) + r.normalize() * radius
        };
        let target = 0.02;
        let (positions, faces) = remesh(&positions, &faces, target, 8, on_cylinder);
        for p in &positions {
            let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
            assert!((r - radius).abs() < 1e-5, "off the cylinder: r = {r}");
        }
        let lengths: Vec<f32> = edges(&faces)
            .iter()
            .map(|&[a, b]| Vec3::from(positions[a as usize]).distance(Vec3::from(positions[b as usize])))
            .collect();
        let outside = lengths.iter().filter(|&&l| !(0.5 * target..=1.5 * target).contains(&l)).count();
        assert!(outside * 50 < lengths.len(), "{outside} of {} edges far from {target}", lengths.len());
        let mean = lengths.iter().sum::<f32>() / lengths.len() as f32;
        assert!((mean - target).abs() < 0.2 * target, "mean edge {mean}");
        let mut directed = std::collections::HashSet::new();
        for t in &faces {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                assert!(directed.insert((a, b)), "edge {a}→{b} twice: inconsistent winding");
            }
        }
        let boundary = boundary_edges(&faces);
        let circumference: f32 = boundary
            .iter()
            .map(|&(a, b)| Vec3::from(positions[a as usize]).distance(Vec3::from(positions[b as usize])))
            .sum();
        // Two circles; the chords of a 2 cm polygon are within 0.2 % of the circle.
        let expected = 2.0 * std::f32::consts::TAU * radius;
        assert!((circumference - expected).abs() < 0.01 * expected, "{circumference} vs {expected}");
    }

    /// A fan round a centre (valence 9) whose rim edge 2–3 has been split at vertex 1: flipping
    /// the spoke 0–1 looks good for valence, but would lay a face along the rim through the
    /// midpoint, with no area. In several orientations (the rounding noise that is a flat face's
    /// normal differs with each), no face of the result may be flat.
    #[test]
    fn flips_make_no_flat_face() {
        for k in 0..12 {
            let turn =
                glam::Quat::from_axis_angle(Vec3::new(1.0, 0.3 * k as f32, 2.0).normalize(), 0.37 * k as f32);
            // Away from the origin, as a garment is, so that differences round.
            let centre = Vec3::new(0.37, -0.21, 0.15);
            let rim = |i: u32| {
                let a = i as f32 * std::f32::consts::TAU / 8.0;
                centre + turn * Vec3::new(0.1 * a.cos(), 0.1 * a.sin(), 0.0)
            };
            let mut positions = vec![centre, 0.5 * (rim(0) + rim(1))];
            positions.extend((0..8).map(rim));
            let positions: Vec<[f32; 3]> = positions.iter().map(|p| p.to_array()).collect();
            let mut faces = vec![[0, 2, 1], [0, 1, 3]];
            faces.extend((1..8).map(|i| [0, 2 + i, 2 + (i + 1) % 8]));
            let mut mesh = Working::new(&positions, &faces);
            mesh.flip_to_regular_valence(|_| true);
            let (p, f) = mesh.compact();
            for t in &f {
                let [a, b, c] = t.map(|v| Vec3::from(p[v as usize]));
                let longest = (b - a).length().max((c - b).length()).max((a - c).length());
                let sine = (b - a).cross(c - a).length() / longest.powi(2);
                assert!(sine > 1e-3, "orientation {k}: face {t:?} is flat (twice-area / longest² = {sine})");
            }
        }
    }

    /// NGD's adaptive step on a flat grid with a boundary, turned out of the axes (so that
    /// rounding gives a flat face a normal of noise): the chosen edges are split, every old
    /// vertex stays where it was, the result is still an oriented manifold with one boundary loop
    /// of the same length, and the area is unchanged (flat, so flips cannot change it) with no
    /// face of (nearly) none.
    #[test]
    fn split_and_flip_keeps_a_manifold_and_its_boundary() {
        let n = 8u32;
        let turn = glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let up = turn * Vec3::Z;
        let positions: Vec<[f32; 3]> = (0..=n)
            .flat_map(|y| {
                (0..=n).map(move |x| (turn * Vec3::new(x as f32 * 0.1, y as f32 * 0.1, 0.0)).to_array())
            })
            .collect();
        let at = |x: u32, y: u32| y * (n + 1) + x;
        let faces: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| {
                (0..n).flat_map(move |x| {
                    [[at(x, y), at(x + 1, y), at(x + 1, y + 1)], [at(x, y), at(x + 1, y + 1), at(x, y + 1)]]
                })
            })
            .collect();
        // Every edge of the faces in the lower-left quarter, boundary edges among them.
        let chosen: Vec<[u32; 2]> = edges(&faces)
            .into_iter()
            .filter(|&[a, b]| [a, b].iter().all(|&v| v % (n + 1) <= n / 2 && v / (n + 1) <= n / 2))
            .collect();
        let (new_positions, new_faces) = split_and_flip(&positions, &faces, &chosen);
        assert_eq!(new_positions.len(), positions.len() + chosen.len());
        assert_eq!(&new_positions[..positions.len()], &positions[..]);
        crate::manifold::check_manifold(&new_positions, &new_faces).unwrap();
        let loops = crate::adjacency::boundary_loops(&new_faces);
        assert_eq!(loops.len(), 1);
        let perimeter: f32 = boundary_edges(&new_faces)
            .iter()
            .map(|&(a, b)| {
                Vec3::from(new_positions[a as usize]).distance(Vec3::from(new_positions[b as usize]))
            })
            .sum();
        assert!((perimeter - 3.2).abs() < 1e-5, "perimeter {perimeter}");
        let twice_areas: Vec<f32> =
            new_faces.iter().map(|&t| crate::normals::face_area_normal(&new_positions, t).dot(up)).collect();
        let area = twice_areas.iter().sum::<f32>() * 0.5;
        assert!((area - 0.64).abs() < 1e-5, "area {area} (a negative share means a face turned over)");
        let thinnest = twice_areas.iter().copied().fold(f32::INFINITY, f32::min);
        assert!(thinnest > 1e-4, "a face with (nearly) no area: twice-area {thinnest}");
        let shortest = edges(&new_faces)
            .iter()
            .map(|&[a, b]| {
                Vec3::from(new_positions[a as usize]).distance(Vec3::from(new_positions[b as usize]))
            })
            .fold(f32::INFINITY, f32::min);
        assert!((shortest - 0.05).abs() < 1e-6, "the split edges' halves are 5 cm: {shortest}");
    }
}
