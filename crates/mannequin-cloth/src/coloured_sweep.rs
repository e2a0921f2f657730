//! Projects coloured constraints: colour after colour, and within a colour on all threads. The
//! constraints of a colour share no particle, so they write disjoint positions, and the sweep gives
//! the same bits whatever the number of threads.

use std::marker::PhantomData;
use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

/// Constraints per parallel task: large enough to amortise scheduling, small enough to balance.
const CHUNK: usize = 256;
/// A colour with fewer constraints is swept on the calling thread. Handing each colour to the
/// thread pool costs more than it saves on a garment's colours (a few thousand constraints
/// each): on `dress` (pants and T-shirt, 4 s walk, 2 cores) stretch took 2.8 s swept in parallel
/// against 0.7 s on one thread, and bending 10.0 s against 6.5 s.
const PARALLEL_MIN: usize = 4096;

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
    let run = |items: &[T], lambdas: &mut [f32]| {
        for (item, l) in items.iter().zip(lambdas) {
            project(item, l, &access);
        }
    };
    for range in colours {
        let (items, lambdas) = (&items[range.clone()], &mut lambda[range.clone()]);
        if items.len() < PARALLEL_MIN {
            run(items, lambdas);
        } else {
            items.par_chunks(CHUNK).zip(lambdas.par_chunks_mut(CHUNK)).for_each(|(i, l)| run(i, l));
        }
    }
}
