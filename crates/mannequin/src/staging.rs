//! A command's outputs built apart and moved into place together (issue 42: a failing command
//! leaves no new file it did not finish). Every output is written into a hidden folder inside
//! the output folder and renamed over its final name only once all are finished; dropped
//! unfinished, the hidden folder goes, and so do the output folder and its parents if this
//! made them and they are empty.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

pub struct Staging {
    out: PathBuf,
    dir: PathBuf,
    /// The folders this made, innermost first.
    made: Vec<PathBuf>,
    committed: bool,
}

impl Staging {
    /// A staging folder for outputs that go into `out`.
    pub fn new(out: &Path) -> Result<Self> {
        let made = out
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        let dir = out.join(format!(".staging-{}", std::process::id()));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self { out: out.to_path_buf(), dir, made, committed: false })
    }

    /// The folder to write the outputs into, under the names they take in the output folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Moves every staged output to its place in the output folder, replacing what was there; a
    /// place taken by a folder where a file goes (or the reverse) is found before anything moves.
    pub fn commit(mut self) -> Result<()> {
        let reading = || format!("reading {}", self.dir.display());
        let staged = std::fs::read_dir(&self.dir)
            .with_context(reading)?
            .map(|entry| entry.map(|e| (e.path(), self.out.join(e.file_name()))))
            .collect::<std::io::Result<Vec<_>>>()
            .with_context(reading)?;
        if let Some((_, to)) = staged.iter().find(|(from, to)| to.exists() && to.is_dir() != from.is_dir()) {
            let what = if to.is_dir() { "a folder" } else { "a file" };
            bail!("{}: {what} is in the way of the output of that name", to.display());
        }
        for (from, to) in &staged {
            if to.is_dir() {
                std::fs::remove_dir_all(to).with_context(|| format!("replacing {}", to.display()))?;
            }
            std::fs::rename(from, to).with_context(|| format!("writing {}", to.display()))?;
        }
        self.committed = true;
        std::fs::remove_dir(&self.dir).with_context(|| format!("removing {}", self.dir.display()))
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
}
