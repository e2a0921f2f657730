//! A mesh's index tables on a GPU: built on the host as compressed rows (CSR, so kernels gather
//! instead of scattering with atomics), uploaded to each device once and kept there while the
//! mesh lives.

use std::sync::{Arc, Mutex, PoisonError, Weak};

use burn_cubecl::CubeDevice;

/// Offsets `[n + 1]` and entries of the lists of `n` rows, from `(row, entry)` pairs in the
/// order each row's list keeps: row `i` is `entries[start[i] .. start[i + 1]]`.
pub(crate) fn csr(n: usize, pairs: impl Iterator<Item = (usize, u32)> + Clone) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n + 1];
    for (row, _) in pairs.clone() {
        start[row + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut entries = vec![0u32; start[n] as usize];
    for (row, e) in pairs {
        entries[fill[row] as usize] = e;
        fill[row] += 1;
    }
    (start, entries)
}

/// Tables of type `T` per (mesh, device). An entry holds a `Weak` of its mesh, which keeps the
/// allocation and so its address from being reused while the entry exists; entries of dropped
/// meshes go at the next lookup.
pub(crate) type TableCache<M, T> = Mutex<Vec<(Weak<M>, CubeDevice, T)>>;

/// The tables of `mesh` on `device` from `cache`, made by `upload` on first use.
pub(crate) fn cached<M, T: Clone>(
    cache: &TableCache<M, T>,
    mesh: &Arc<M>,
    device: &CubeDevice,
    upload: impl FnOnce() -> T,
) -> T {
    let mut entries = cache.lock().unwrap_or_else(PoisonError::into_inner);
    entries.retain(|(m, _, _)| m.strong_count() > 0);
    let key = Arc::downgrade(mesh);
    if let Some((_, _, t)) = entries.iter().find(|(m, d, _)| m.ptr_eq(&key) && d == device) {
        return t.clone();
    }
    let t = upload();
    entries.push((key, device.clone(), t.clone()));
    t
}
