//! A scratch folder for one test, removed when the test ends (also when it fails), so test runs
//! leave nothing behind in the system temp folder.

use std::path::{Path, PathBuf};

pub struct Scratch(PathBuf);

impl Scratch {
    /// `<temp>/mq-body-<name>-<pid>`: one per test, so parallel tests never share (or delete)
    /// each other's files.
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mq-body-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    pub fn join(&self, file: impl AsRef<Path>) -> PathBuf {
        self.0.join(file)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}
