//! A spatial hash that lists each box once, in the cell of its lowest corner, with cells as wide
//! as the widest box. A box overlapping a query then has its lowest corner within one widest box
//! below the query's, a block of at most 3 × 3 × 3 cells, and each box is met once. Listing a box
//! in every cell it covers instead makes a query of a cloth's swept boxes walk hundreds of
//! entries for the few it keeps.

use glam::{IVec3, Vec3};

use crate::box_hash::Aabb;

#[derive(Debug, Clone, Default)]
pub(crate) struct CornerGrid {
    inverse_cell: f32,
    widest: Vec3,
    mask: u32,
    /// `items[starts[h]..starts[h + 1]]` are the boxes whose lowest corner hashes to bucket h.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Each box's cell, to tell it from another cell's box in the same bucket.
    cells: Vec<IVec3>,
}

impl CornerGrid {
    fn cell_of(&self, p: Vec3) -> IVec3 {
        (p * self.inverse_cell).floor().as_ivec3()
    }

    fn bucket(&self, c: IVec3) -> usize {
        let h = (c.x as u32).wrapping_mul(73_856_093)
            ^ (c.y as u32).wrapping_mul(19_349_663)
            ^ (c.z as u32).wrapping_mul(83_492_791);
        (h & self.mask) as usize
    }

    /// Lists `boxes`, reusing the arrays of the previous build.
    pub fn build(&mut self, boxes: &[Aabb]) {
        self.widest = boxes.iter().fold(Vec3::ZERO, |w, b| w.max(b.extent()));
        self.inverse_cell = 1.0 / self.widest.max_element().max(f32::MIN_POSITIVE);
        let table = (2 * boxes.len()).next_power_of_two().max(1024);
        self.mask = table as u32 - 1;
        let cells: Vec<IVec3> = boxes.iter().map(|b| self.cell_of(b.min)).collect();
        self.starts.clear();
        self.starts.resize(table + 1, 0);
        for &c in &cells {
            let h = self.bucket(c);
            self.starts[h + 1] += 1;
        }
        for h in 0..table {
            self.starts[h + 1] += self.starts[h];
        }
        let mut next = self.starts[..table].to_vec();
        self.items.clear();
        self.items.resize(boxes.len(), 0);
        for (k, &c) in cells.iter().enumerate() {
            let h = self.bucket(c);
            self.items[next[h] as usize] = k as u32;
            next[h] += 1;
        }
        self.cells = cells;
    }

    /// Calls `visit` once with each box of `boxes` (the ones built from) that overlaps `query`.
    pub fn for_each_overlapping(&self, boxes: &[Aabb], query: &Aabb, mut visit: impl FnMut(u32)) {
        if self.starts.is_empty() {
            return;
        }
        let (lo, hi) = (self.cell_of(query.min - self.widest), self.cell_of(query.max));
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let cell = IVec3::new(x, y, z);
                    let h = self.bucket(cell);
                    for &b in &self.items[self.starts[h] as usize..self.starts[h + 1] as usize] {
                        if self.cells[b as usize] == cell && boxes[b as usize].overlaps(query) {
                            visit(b);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against every pair tested directly: boxes of many sizes, each overlapping box met once.
    #[test]
    fn finds_exactly_the_overlapping_boxes() {
        let boxes: Vec<Aabb> = (0..400)
            .map(|k| {
                let f = k as f32;
                let min = Vec3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 0.13).sin()) * 0.5;
                Aabb {
                    min,
                    max: min + Vec3::new(0.01 + 0.1 * (f * 0.7).sin().abs(), 0.05, 0.02 * (k % 5) as f32),
                }
            })
            .collect();
        let mut grid = CornerGrid::default();
        grid.build(&boxes);
        for query in &boxes {
            let mut found = Vec::new();
            grid.for_each_overlapping(&boxes, query, |b| found.push(b));
            found.sort_unstable();
            let direct: Vec<u32> =
                (0..boxes.len() as u32).filter(|&b| boxes[b as usize].overlaps(query)).collect();
            assert_eq!(found, direct);
        }
    }
}
