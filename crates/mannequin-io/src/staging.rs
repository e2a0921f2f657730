//! Outputs built apart and moved into place only when whole (issue 42: a failing command leaves
//! no new file it did not finish, and no emptied old one). Two uses of the one idea:
//! [`Staging`] writes a command's outputs into a hidden folder inside the output folder and
//! renames each over its final name once all are finished (`cloth simulate`, `dress`);
//! [`StagedDir`] writes a whole folder under a temporary name and replaces the old folder with it
//! (`eval`'s predictions). Dropped unfinished, either leaves things as they were.

use std::path::{Path, PathBuf};

/// A step of staging that failed, naming the file or folder.
#[derive(Debug, thiserror::Error)]
pub enum StagingError {
    /// An operating-system error while `doing` (creating, reading, writing…) `path`.
    #[error("{doing} {}", path.display())]
    Step { doing: &'static str, path: PathBuf, source: std::io::Error },
    /// An operating-system error at `path`, said in one line.
    #[error("{}: {error}", path.display())]
    Path { path: PathBuf, error: std::io::Error },
    /// A folder where a file goes, or the reverse.
    #[error("{}: {what} is in the way of the output of that name", path.display())]
    InTheWay { path: PathBuf, what: &'static str },
}

/// `Err(e)` of an operating-system call while `doing` to `path`, as a [`StagingError::Step`].
fn step<T>(doing: &'static str, path: &Path, r: std::io::Result<T>) -> Result<T, StagingError> {
    r.map_err(|source| StagingError::Step { doing, path: path.to_path_buf(), source })
}

/// `Err(e)` of an operating-system call at `path`, as a [`StagingError::Path`].
fn at<T>(path: &Path, r: std::io::Result<T>) -> Result<T, StagingError> {
    r.map_err(|error| StagingError::Path { path: path.to_path_buf(), error })
}

/// Outputs staged for the folder `out`, merged into it on [`Staging::commit`]. Dropped
/// uncommitted, the hidden folder goes, and so do the output folder and its parents if this made
/// them and they are empty.
pub struct Staging {
    out: PathBuf,
    dir: PathBuf,
    /// The folders this made, innermost first.
    made: Vec<PathBuf>,
    committed: bool,
}

impl Staging {
    /// A staging folder for outputs that go into `out`.
    pub fn new(out: &Path) -> Result<Self, StagingError> {
        let made = out
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        let dir = out.join(format!(".staging-{}", std::process::id()));
        step("creating", &dir, std::fs::create_dir_all(&dir))?;
        Ok(Self { out: out.to_path_buf(), dir, made, committed: false })
    }

    /// The folder to write the outputs into, under the names they take in the output folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Moves every staged output to its place in the output folder, replacing what was there; a
    /// place taken by a folder where a file goes (or the reverse) is found before anything moves.
    pub fn commit(mut self) -> Result<(), StagingError> {
        let entries = step("reading", &self.dir, std::fs::read_dir(&self.dir))?;
        let staged = step(
            "reading",
            &self.dir,
            entries
                .map(|entry| entry.map(|e| (e.path(), self.out.join(e.file_name()))))
                .collect::<Result<Vec<_>, _>>(),
        )?;
        if let Some((_, to)) = staged.iter().find(|(from, to)| to.exists() && to.is_dir() != from.is_dir()) {
            let what = if to.is_dir() { "a folder" } else { "a file" };
            return Err(StagingError::InTheWay { path: to.clone(), what });
        }
        for (from, to) in &staged {
            if to.is_dir() {
                step("replacing", to, std::fs::remove_dir_all(to))?;
            }
            step("writing", to, std::fs::rename(from, to))?;
        }
        self.committed = true;
        step("removing", &self.dir, std::fs::remove_dir(&self.dir))
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        std::fs::remove_dir_all(&self.dir).ok();
        for d in &self.made {
            // Only an empty folder goes: a checkpoint written meanwhile stays.
            if std::fs::remove_dir(d).is_err() {
                break;
            }
        }
    }
}

/// A folder being written at [`StagedDir::path`], destined for `target`, which it replaces whole
/// on [`StagedDir::keep`]; removed on drop unless kept.
pub struct StagedDir {
    temp: PathBuf,
    target: PathBuf,
    kept: bool,
}

impl StagedDir {
    /// Stages `target` in `temp`, a folder of its own on the same file system (emptied first:
    /// one left by a killed run).
    pub fn new(temp: PathBuf, target: PathBuf) -> Result<Self, StagingError> {
        if temp.exists() {
            at(&temp, std::fs::remove_dir_all(&temp))?;
        }
        Ok(Self { temp, target, kept: false })
    }

    /// Where the folder is written meanwhile.
    pub fn path(&self) -> &Path {
        &self.temp
    }

    /// Replaces `target`, and whatever it held, with the staged folder.
    pub fn keep(mut self) -> Result<(), StagingError> {
        if self.target.exists() {
            at(&self.target, std::fs::remove_dir_all(&self.target))?;
        }
        if let Some(parent) = self.target.parent() {
            at(parent, std::fs::create_dir_all(parent))?;
        }
        at(&self.target, std::fs::rename(&self.temp, &self.target))?;
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

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("mq-staging-{name}-{}", std::process::id()));
        std::fs::remove_dir_all(&d).ok();
        d
    }

    #[test]
    fn outputs_appear_together_on_commit() {
        let root = scratch("commit");
        let out = root.join("a/b");
        std::fs::create_dir_all(out.join("frames")).unwrap();
        std::fs::write(out.join("frames/old.png"), "old").unwrap();
        let staging = Staging::new(&out).unwrap();
        std::fs::write(staging.dir().join("x.txt"), "x").unwrap();
        std::fs::create_dir(staging.dir().join("frames")).unwrap();
        std::fs::write(staging.dir().join("frames/new.png"), "new").unwrap();
        assert!(!out.join("x.txt").exists(), "nothing in place before the commit");
        staging.commit().unwrap();
        assert_eq!(std::fs::read_to_string(out.join("x.txt")).unwrap(), "x");
        assert!(out.join("frames/new.png").exists() && !out.join("frames/old.png").exists());
        let left: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left.len(), 2, "{left:?}");
        std::fs::remove_dir_all(root).unwrap();
    }

    /// A folder where a file goes stops the commit before any output moves.
    #[test]
    fn a_blocked_output_moves_nothing() {
        let root = scratch("blocked");
        std::fs::create_dir_all(root.join("b.txt")).unwrap();
        let staging = Staging::new(&root).unwrap();
        for name in ["a.txt", "b.txt", "c.txt"] {
            std::fs::write(staging.dir().join(name), name).unwrap();
        }
        let e = staging.commit().unwrap_err().to_string();
        assert!(e.ends_with("b.txt: a folder is in the way of the output of that name"), "{e}");
        let left: Vec<_> = std::fs::read_dir(&root).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left, vec![std::ffi::OsString::from("b.txt")]);
        std::fs::remove_dir_all(root).unwrap();
    }

    /// Dropped before its commit, a staging leaves nothing: not its files, nor the folders it made.
    #[test]
    fn an_unfinished_staging_leaves_nothing() {
        let root = scratch("drop");
        std::fs::create_dir_all(&root).unwrap();
        let staging = Staging::new(&root.join("a/b")).unwrap();
        std::fs::write(staging.dir().join("x.txt"), "x").unwrap();
        drop(staging);
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 0);
        std::fs::remove_dir_all(root).unwrap();
    }

    #[test]
    fn a_dropped_stage_leaves_the_old_folder_and_a_kept_one_replaces_it() {
        let root = scratch("staged-dir");
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

    /// A failed step reads as the command's error line always read: what was being done to which
    /// path, then the operating system's reason (the cause, one link down the chain).
    #[test]
    fn a_failed_step_names_its_path_and_keeps_the_cause() {
        let e = step("reading", Path::new("/x"), Err::<(), _>(std::io::Error::other("gone"))).unwrap_err();
        assert_eq!(e.to_string(), "reading /x");
        assert_eq!(std::error::Error::source(&e).unwrap().to_string(), "gone");
        let e = at(Path::new("/x"), Err::<(), _>(std::io::Error::other("gone"))).unwrap_err();
        assert_eq!(e.to_string(), "/x: gone");
        assert!(std::error::Error::source(&e).is_none());
    }
}
