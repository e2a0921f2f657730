//! A run folder: the checked manifest as `plan.json` (each person's input, steps and flags), the
//! file its engine submits, and a folder per person. Planning again onto a run with the same
//! people keeps their finished steps; another manifest is refused.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use mannequin_io::atomic::write_atomic;
use serde::{Deserialize, Serialize};

use super::person::Person;
use super::resources::Needs;

/// The plan file's format name, checked on load.
const FORMAT: &str = "mannequin-batch/1";

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Engine {
    Slurm,
    Kubernetes,
    Local,
}

#[derive(Debug, Serialize, Deserialize)]
pub struct Plan {
    pub format: String,
    /// The manifest it was made from.
    pub manifest: PathBuf,
    pub engine: Engine,
    /// What every task asks for.
    pub needs: Needs,
    pub people: Vec<Person>,
}

pub fn plan_path(run: &Path) -> PathBuf {
    run.join("plan.json")
}

impl Plan {
    pub fn new(manifest: &Path, engine: Engine, needs: Needs, people: Vec<Person>) -> Plan {
        Plan { format: FORMAT.to_string(), manifest: manifest.to_path_buf(), engine, needs, people }
    }

    /// The plan of the run folder `run`.
    pub fn load(run: &Path) -> Result<Plan> {
        let path = plan_path(run);
        let text = std::fs::read_to_string(&path).with_context(|| {
            format!(
                "{}: cannot read; is {} a run folder made by `mannequin batch plan`?",
                path.display(),
                run.display()
            )
        })?;
        let plan: Plan =
            serde_json::from_str(&text).with_context(|| format!("{}: not a batch plan", path.display()))?;
        if plan.format != FORMAT {
            bail!("{}: field `format`: expected {FORMAT}, found {}", path.display(), plan.format);
        }
        Ok(plan)
    }

    /// Writes `plan.json`, unless the folder holds the plan of other people or steps.
    pub fn save(&self, run: &Path) -> Result<()> {
        let path = plan_path(run);
        if path.exists() {
            let old = Plan::load(run)?;
            if old.people != self.people {
                bail!(
                    "{}: holds a plan of other people or steps (from {}); use another --out, or remove the folder to start over",
                    path.display(),
                    old.manifest.display()
                );
            }
        }
        let text = serde_json::to_string_pretty(self).expect("a plan serialises");
        write_atomic(&path, text.as_bytes()).with_context(|| format!("{}: cannot write", path.display()))
    }
}
