//! Planar images that many threads fill at once, one tile each. Tiles do not overlap and each
//! is composited exactly once, so no two threads ever touch the same element; this wrapper only
//! lets the compiler see that.

use std::marker::PhantomData;

use crate::TILE;
use crate::composite::TileRect;

/// `planes` row-major `w × h` images in one buffer, writable by tile from several threads.
pub(crate) struct TilePlanes<'a, U> {
    ptr: *mut U,
    len: usize,
    w: usize,
    plane: usize,
    _borrow: PhantomData<&'a mut [U]>,
}

// SAFETY: writes go through `write`, whose contract forbids two threads writing one tile.
unsafe impl<U: Send> Sync for TilePlanes<'_, U> {}

impl<'a, U: Copy> TilePlanes<'a, U> {
    pub fn new(data: &'a mut [U], w: usize, h: usize) -> Self {
        TilePlanes { ptr: data.as_mut_ptr(), len: data.len(), w, plane: w * h, _borrow: PhantomData }
    }

    /// Copies a tile's values (16 per tile row, row-major) into `rect` of plane `plane`.
    ///
    /// # Safety
    /// No other thread may write the same `rect` of the same plane while this runs.
    pub unsafe fn write(&self, rect: &TileRect, plane: usize, src: &[U]) {
        for r in 0..rect.h {
            let start = plane * self.plane + (rect.y0 + r) * self.w + rect.x0;
            assert!(start + rect.w <= self.len && r * TILE + rect.w <= src.len(), "tile outside its image");
            // SAFETY: in bounds (checked above); exclusive by the caller's contract.
            unsafe { std::ptr::copy_nonoverlapping(src.as_ptr().add(r * TILE), self.ptr.add(start), rect.w) };
        }
    }
}
