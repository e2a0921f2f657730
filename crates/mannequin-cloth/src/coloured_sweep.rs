//! Projects coloured constraints: colour after colour, and within a colour on all threads. The
//! constraints of a colour share no particle, so they write disjoint positions, and the sweep gives
//! the same bits whatever the number of threads.

use std::marker::PhantomData;
use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

/// Constraints per parallel task: large enough to amortise scheduling, small enough to balance.
const CHUNK: usize = 256;

/// Positions shared by the threads sweeping one colour.
pub(crate) struct ColourAccess<'a> {
    ptr: *mut [f32; 3],
    len: usize,
    _positions: PhantomData<&'a mut [[f32; 3]]>,
}

// SAFETY: every access goes through `get`/`set`, whose contract (one colour's constraints never
// share a particle) makes concurrent accesses touch disjoint elements.
unsafe impl Sync for ColourAccess<'_> {}

impl ColourAccess<'_> {
    /// # Safety
    /// No other thread may write particle `i` while this colour is swept.
    pub unsafe fn get(&self, i: u32) -> Vec3 {
        assert!((i as usize) < self.len);
        // SAFETY: in bounds (checked above); no concurrent writer by the contract.
        Vec3::from(unsafe { *self.ptr.add(i as usize) })
    }

    /// # Safety
    /// No other thread may read or write particle `i` while this colour is swept.
    pub unsafe fn set(&self, i: u32, v: Vec3) {
        assert!((i as usize) < self.len);
        // SAFETY: in bounds (checked above); exclusive by the contract.
        unsafe { *self.ptr.add(i as usize) = v.to_array() };
    }
}

/// Runs `project(constraint, its λ, positions)` for every constraint, colour by colour.
/// `items` and `lambda` are in colour order; `items[k]` must only touch the particles listed for
/// slot k when it was coloured.
pub(crate) fn sweep<T: Sync>(
    colours: &[Range<usize>],
    items: &[T],
    lambda: &mut [f32],
    positions: &mut [[f32; 3]],
    project: impl Fn(&T, &mut f32, &ColourAccess) + Sync,
) {
    let access = ColourAccess { ptr: positions.as_mut_ptr(), len: positions.len(), _positions: PhantomData };
    for range in colours {
        items[range.clone()].par_chunks(CHUNK).zip(lambda[range.clone()].par_chunks_mut(CHUNK)).for_each(
            |(items, lambdas)| {
                for (item, l) in items.iter().zip(lambdas) {
                    project(item, l, &access);
                }
            },
        );
    }
}
