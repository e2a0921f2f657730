//! A spatial hash of boxes in flat arrays: each box is listed in every grid cell it overlaps, cells
//! are hashed into a table, and a counting sort lays the table's lists end to end. A point's query
//! is the list of its cell's bucket, a superset of the boxes that contain it (hash collisions add
//! strangers, and a box may be listed twice), so callers test what they get.

use glam::{IVec3, Vec3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub fn around(points: &[Vec3]) -> Self {
        let mut b = Aabb { min: points[0], max: points[0] };
        for &p in &points[1..] {
            b.min = b.min.min(p);
            b.max = b.max.max(p);
        }
        b
    }

    pub fn union(self, other: Aabb) -> Self {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    pub fn inflated(self, by: f32) -> Self {
        Aabb { min: self.min - by, max: self.max + by }
    }

    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
}

/// Grid cells hashed into a table of `mask + 1` buckets.
#[derive(Debug, Clone, Copy, Default)]
struct Grid {
    inverse_cell: f32,
    mask: u32,
}

impl Grid {
    fn cell_of(&self, p: Vec3) -> IVec3 {
        (p * self.inverse_cell).floor().as_ivec3()
    }

    fn bucket(&self, c: IVec3) -> usize {
        let h = (c.x as u32).wrapping_mul(73_856_093)
            ^ (c.y as u32).wrapping_mul(19_349_663)
            ^ (c.z as u32).wrapping_mul(83_492_791);
        (h & self.mask) as usize
    }

    fn for_each_bucket(&self, b: &Aabb, mut visit: impl FnMut(usize)) {
        let (lo, hi) = (self.cell_of(b.min), self.cell_of(b.max));
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    visit(self.bucket(IVec3::new(x, y, z)));
                }
            }
        }
    }
}

#[derive(Debug, Clone, Default)]
pub(crate) struct BoxHash {
    grid: Grid,
    /// `items[starts[h]..starts[h + 1]]` are the boxes listed in bucket h.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Fill cursor per bucket, kept to reuse its allocation.
    next: Vec<u32>,
}

impl BoxHash {
    /// Lists `boxes` by cells of side `cell`. Reuses the arrays of the previous build.
    pub fn build(&mut self, boxes: &[Aabb], cell: f32) {
        let table = (2 * boxes.len()).next_power_of_two().max(1024);
        let grid = Grid { inverse_cell: 1.0 / cell, mask: table as u32 - 1 };
        self.grid = grid;
        self.starts.clear();
        self.starts.resize(table + 1, 0);
        for b in boxes {
            grid.for_each_bucket(b, |h| self.starts[h + 1] += 1);
        }
        for h in 0..table {
            self.starts[h + 1] += self.starts[h];
        }
        self.items.clear();
        self.items.resize(self.starts[table] as usize, 0);
        self.next.clear();
        self.next.extend_from_slice(&self.starts[..table]);
        for (k, b) in boxes.iter().enumerate() {
            grid.for_each_bucket(b, |h| {
                self.items[self.next[h] as usize] = k as u32;
                self.next[h] += 1;
            });
        }
    }

    /// Boxes listed in the bucket of `p`'s cell, in ascending order.
    pub fn query(&self, p: Vec3) -> &[u32] {
        if self.starts.is_empty() {
            return &[];
        }
        let h = self.grid.bucket(self.grid.cell_of(p));
        &self.items[self.starts[h] as usize..self.starts[h + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_box_containing_a_point_is_listed() {
        let boxes: Vec<Aabb> = (0..300)
            .map(|k| {
                let t = k as f32;
                let c = Vec3::new((t * 0.37).sin(), (t * 0.71).cos(), (t * 1.13).sin());
                Aabb { min: c, max: c + Vec3::splat(0.05 + 0.2 * (t * 0.5).sin().abs()) }
            })
            .collect();
        let mut hash = BoxHash::default();
        hash.build(&boxes, 0.1);
        for k in 0..2000 {
            let t = k as f32;
            let p = Vec3::new((t * 0.19).sin(), (t * 0.29).cos(), (t * 0.43).sin()) * 1.1;
            let listed = hash.query(p);
            for (i, b) in boxes.iter().enumerate() {
                if b.contains(p) {
                    assert!(listed.contains(&(i as u32)), "box {i} contains {p} but is not listed");
                }
            }
        }
    }
}
