//! A training checkpoint read back. Its record and counters are checked against the run before
//! the views load, and its arrays as they load ([`crate::Trainer::resume`]), so an edited or
//! corrupt file is refused naming the field instead of resuming into NaN.

use std::path::{Path, PathBuf};

use mannequin_io::Npz;

use crate::error::AvatarError;
use crate::run::TrainingRun;

/// A checkpoint of this run whose iteration lies within it.
pub struct Checkpoint {
    pub npz: Npz,
    /// Iterations done: at most the run's, and as many as the optimiser's steps.
    pub iteration: usize,
}

impl Checkpoint {
    /// Reads `path`, refusing it unless its record matches `run` in every setting but
    /// `undecided` and its iteration and optimiser step agree and lie within the run.
    pub fn open(path: &Path, run: &TrainingRun, undecided: &[&str]) -> Result<Self, AvatarError> {
        let npz = Npz::read(path)?;
        run.check(&npz, undecided)?;
        let iterations = run.options.iterations;
        let iteration = counter(&npz, "iteration", iterations)?;
        let step = counter(&npz, "adam_step", iterations)?;
        if step != iteration {
            let reason = format!("expected {iteration} (one optimiser step per iteration), found {step}");
            return Err(npz.field_error("adam_step", reason).into());
        }
        Ok(Self { npz, iteration })
    }
}

/// The one integer under `key`, refused unless it lies in `0..=max`.
fn counter(npz: &Npz, key: &str, max: usize) -> Result<usize, AvatarError> {
    let a = npz.require(key)?;
    let value = match (a.shape.as_slice(), a.to_i64()) {
        ([1], Some(v)) => v[0],
        _ => {
            let found = format!("found dtype {} shape {:?}", a.dtype_name(), a.shape);
            return Err(npz.field_error(key, format!("expected one integer, {found}")).into());
        }
    };
    usize::try_from(value).ok().filter(|&v| v <= max).ok_or_else(|| {
        let reason = format!("expected an iteration from 0 to {max} (the run's --iters), found {value}");
        npz.field_error(key, reason).into()
    })
}

/// Where a model directory keeps its training checkpoint.
pub fn checkpoint_path(dir: &Path) -> PathBuf {
    dir.join("checkpoint.npz")
}
