//! A 3-D k-d tree for exact nearest-neighbour queries: points sorted in place around median
//! splits on the widest axis, searched depth-first with pruning on the splitting plane.

use glam::DVec3;

pub struct KdTree {
    points: Vec<DVec3>,
    /// `order[i]` is the input index of the point stored at tree position `i`.
    order: Vec<u32>,
    /// Splitting axis of the subtree whose median sits at each position (leaves unused).
    axis: Vec<u8>,
}

const LEAF: usize = 8;

impl KdTree {
    pub fn new(points: &[DVec3]) -> Self {
        let mut order: Vec<u32> = (0..points.len() as u32).collect();
        let mut axis = vec![0u8; points.len()];
        build(points, &mut order, &mut axis);
        let sorted = order.iter().map(|&i| points[i as usize]).collect();
        Self { points: sorted, order, axis }
    }

    /// The input index of the nearest point and its squared distance (`None` for an empty tree).
    pub fn nearest(&self, q: DVec3) -> Option<(usize, f64)> {
        self.k_nearest(q, 1).first().copied()
    }

    /// The input indices of the `k` nearest points (fewer if the tree holds fewer) and their
    /// squared distances, nearest first.
    pub fn k_nearest(&self, q: DVec3, k: usize) -> Vec<(usize, f64)> {
        let mut best = Vec::with_capacity(k + 1);
        if k > 0 {
            self.search(q, 0, self.points.len(), k, &mut best);
        }
        best.into_iter().map(|(i, d)| (self.order[i] as usize, d)).collect()
    }

    /// The squared distance a point must beat to enter `best`.
    fn bound(best: &[(usize, f64)], k: usize) -> f64 {
        if best.len() < k { f64::INFINITY } else { best[k - 1].1 }
    }

    fn offer(best: &mut Vec<(usize, f64)>, k: usize, i: usize, d: f64) {
        if d < Self::bound(best, k) {
            let at = best.partition_point(|&(_, e)| e <= d);
            best.insert(at, (i, d));
            best.truncate(k);
        }
    }

    fn search(&self, q: DVec3, lo: usize, hi: usize, k: usize, best: &mut Vec<(usize, f64)>) {
        if hi - lo <= LEAF {
            for i in lo..hi {
                Self::offer(best, k, i, self.points[i].distance_squared(q));
            }
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let ax = self.axis[mid] as usize;
        let diff = q[ax] - self.points[mid][ax];
        Self::offer(best, k, mid, self.points[mid].distance_squared(q));
        let (near, far) = if diff < 0.0 { ((lo, mid), (mid + 1, hi)) } else { ((mid + 1, hi), (lo, mid)) };
        self.search(q, near.0, near.1, k, best);
        if diff * diff < Self::bound(best, k) {
            self.search(q, far.0, far.1, k, best);
        }
    }
}

fn build(points: &[DVec3], order: &mut [u32], axis: &mut [u8]) {
    if order.len() <= LEAF {
        return;
    }
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &i in order.iter() {
        lo = lo.min(points[i as usize]);
        hi = hi.max(points[i as usize]);
    }
    let ext = hi - lo;
    let ax = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| points[a as usize][ax].total_cmp(&points[b as usize][ax]));
    axis[mid] = ax as u8;
    let (left, right) = order.split_at_mut(mid);
    let (axis_left, axis_right) = axis.split_at_mut(mid);
    build(points, left, axis_left);
    build(points, &mut right[1..], &mut axis_right[1..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force() {
        let mut r = mannequin_io::rng::SplitMix64::new(5);
        let mut pt = || DVec3::new(r.normal(), r.normal() * 0.3, r.uniform());
        let points: Vec<DVec3> = (0..2000).map(|_| pt()).collect();
        let tree = KdTree::new(&points);
        for _ in 0..500 {
            let q = pt() * 1.2;
            let (i, d) = tree.nearest(q).unwrap();
            let brute = points.iter().map(|p| p.distance_squared(q)).fold(f64::INFINITY, f64::min);
            assert_eq!(d, brute);
            assert_eq!(points[i].distance_squared(q), d);
        }
        assert!(KdTree::new(&[]).nearest(DVec3::ZERO).is_none());
    }

    #[test]
    fn k_nearest_matches_brute_force() {
        let mut r = mannequin_io::rng::SplitMix64::new(7);
        let mut pt = || DVec3::new(r.normal(), r.uniform(), r.normal() * 2.0);
        let points: Vec<DVec3> = (0..1500).map(|_| pt()).collect();
        let tree = KdTree::new(&points);
        for _ in 0..200 {
            let q = pt();
            let mut brute: Vec<f64> = points.iter().map(|p| p.distance_squared(q)).collect();
            brute.sort_by(f64::total_cmp);
            let found = tree.k_nearest(q, 5);
            assert_eq!(found.iter().map(|x| x.1).collect::<Vec<_>>(), brute[..5]);
            assert!(found.iter().all(|&(i, d)| points[i].distance_squared(q) == d));
        }
        assert_eq!(KdTree::new(&points[..3]).k_nearest(DVec3::ZERO, 5).len(), 3);
    }
}
