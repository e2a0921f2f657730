//! A spatial hash of boxes for finding overlapping pairs: cells as wide as the boxes are on
//! average, each box listed in every cell it covers, and an overlapping pair met only in the cell
//! of its intersection's lowest corner, which both boxes cover, so each pair is met once. Cells as
//! wide as the widest box instead (one listing a box) make a query of a cloth's swept boxes walk
//! hundreds of entries for the few it keeps wherever one box is long.

use glam::IVec3;

use crate::box_hash::{Aabb, Grid};

#[derive(Debug, Clone, Default)]
pub(crate) struct CornerGrid {
    grid: Grid,
    /// `entries[starts[h]..starts[h + 1]]` are the (box, cell) listings that hash to bucket h; the
    /// cell tells a box from another cell's in the same bucket.
    starts: Vec<u32>,
    entries: Vec<(u32, IVec3)>,
}

impl CornerGrid {
    /// Lists `boxes`, reusing the arrays of the previous build.
    pub fn build(&mut self, boxes: &[Aabb]) {
        let mean = boxes.iter().map(|b| b.extent().max_element()).sum::<f32>() / boxes.len().max(1) as f32;
        let table = (4 * boxes.len()).next_power_of_two().max(1024);
        let grid = Grid { inverse_cell: 1.0 / mean.max(f32::MIN_POSITIVE), mask: table as u32 - 1 };
        self.grid = grid;
        self.starts.clear();
        self.starts.resize(table + 1, 0);
        for b in boxes {
            grid.for_each_cell(b, |c| self.starts[grid.bucket(c) + 1] += 1);
        }
        for h in 0..table {
            self.starts[h + 1] += self.starts[h];
        }
        let mut next = self.starts[..table].to_vec();
        self.entries.clear();
        self.entries.resize(self.starts[table] as usize, (0, IVec3::ZERO));
        for (k, b) in boxes.iter().enumerate() {
            grid.for_each_cell(b, |c| {
                let h = grid.bucket(c);
                self.entries[next[h] as usize] = (k as u32, c);
                next[h] += 1;
            });
        }
    }

    /// Calls `visit` once with each box of `boxes` (the ones built from) that overlaps `query`.
    pub fn for_each_overlapping(&self, boxes: &[Aabb], query: &Aabb, mut visit: impl FnMut(u32)) {
        if self.starts.is_empty() {
            return;
        }
        let grid = self.grid;
        grid.for_each_cell(query, |cell| {
            let h = grid.bucket(cell);
            for &(b, listed) in &self.entries[self.starts[h] as usize..self.starts[h + 1] as usize] {
                let other = &boxes[b as usize];
                if listed == cell && other.overlaps(query) && grid.cell_of(other.min.max(query.min)) == cell {
                    visit(b);
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Against every pair tested directly: boxes of many sizes, each overlapping box met once.
    #[test]
    fn finds_exactly_the_overlapping_boxes_once() {
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
