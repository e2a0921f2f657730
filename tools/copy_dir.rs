//! Copying a folder whole (included with `#[path]` by the CLI tests and benches).

use std::path::Path;

/// Copies the folder `from` to `to` (files and subfolders), for a case that mutates a fixture or
/// a copy holding part of a dataset.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}
