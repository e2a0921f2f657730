//! A folder written under a temporary name and moved into place only when whole, so a command
//! that fails leaves neither half a folder nor an emptied old one where its result belongs.

use std::path::{Path, PathBuf};

use crate::error::DataError;

/// A folder being written at `path()`, destined for `target`; removed on drop unless kept.
pub struct StagedDir {
    temp: PathBuf,
    target: PathBuf,
    kept: bool,
}

impl StagedDir {
    /// Stages `target` in `temp`, a folder of its own on the same file system (emptied first:
    /// one left by a killed run).
    pub fn new(temp: PathBuf, target: PathBuf) -> Result<Self, DataError> {
        if temp.exists() {
            std::fs::remove_dir_all(&temp).map_err(|e| DataError::os(&temp, e))?;
        }
        Ok(Self { temp, target, kept: false })
    }

    /// Where the folder is written meanwhile.
    pub fn path(&self) -> &Path {
        &self.temp
    }

    /// Replaces `target`, and whatever it held, with the staged folder.
    pub fn keep(mut self) -> Result<(), DataError> {
        if self.target.exists() {
            std::fs::remove_dir_all(&self.target).map_err(|e| DataError::os(&self.target, e))?;
        }
        if let Some(parent) = self.target.parent() {
            std::fs::create_dir_all(parent).map_err(|e| DataError::os(parent, e))?;
        }
        std::fs::rename(&self.temp, &self.target).map_err(|e| DataError::os(&self.target, e))?;
        self.kept = true;
        Ok(())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.kept {
            let _ = std::fs::remove_dir_all(&self.temp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_stage_leaves_the_old_folder_and_a_kept_one_replaces_it() {
        let root = std::env::temp_dir().join(format!("mq-staged-{}", std::process::id()));
        let (temp, target) = (root.join(".out.partial"), root.join("sub").join("out"));
        std::fs::create_dir_all(&target).unwrap();
        std::fs::write(target.join("old.txt"), b"old").unwrap();
        let stage = StagedDir::new(temp.clone(), target.clone()).unwrap();
        std::fs::create_dir_all(stage.path()).unwrap();
        std::fs::write(stage.path().join("half.txt"), b"half").unwrap();
        drop(stage);
        assert!(!temp.exists() && target.join("old.txt").exists());

        let stage = StagedDir::new(temp.clone(), target.clone()).unwrap();
        std::fs::create_dir_all(stage.path()).unwrap();
        std::fs::write(stage.path().join("new.txt"), b"new").unwrap();
        stage.keep().unwrap();
        assert!(!temp.exists() && !target.join("old.txt").exists() && target.join("new.txt").exists());
        std::fs::remove_dir_all(root).unwrap();
    }
}
