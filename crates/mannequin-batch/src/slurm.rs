//! The Slurm engine: an `sbatch` script whose job array has a task per person (the index is
//! `SLURM_ARRAY_TASK_ID`), with what each task asks for and how many run at once (`%`).
//! Submitting it again finishes only what is left. Slurm refuses array indices from its
//! MaxArraySize on (1001 by default), so a larger run is split into scripts of that many people,
//! each task adding its script's first person to the index.

use std::path::{Path, PathBuf};

use super::plan::Plan;
use super::resources::Needs;
use super::step::Step;

/// Slurm's default MaxArraySize: array indices run from 0 to 1000.
pub const MAX_ARRAY_SIZE: usize = 1001;

/// One script's part of the run: its people are `first..first + count`.
struct Chunk {
    first: usize,
    count: usize,
    /// The script's name and its tasks' log pattern.
    file: String,
    log: String,
}

/// The scripts of `plan` for the run folder `run`, at most `array_max` people each: `slurm.sbatch`
/// when one is enough, else `slurm-<k>.sbatch`.
pub fn scripts(
    plan: &Plan,
    run: &Path,
    mannequin: &Path,
    throttle: Option<u32>,
    partition: Option<&str>,
    array_max: usize,
) -> Vec<(PathBuf, String)> {
    let n = plan.people.len();
    let chunks: Vec<Chunk> = if n <= array_max {
        vec![Chunk { first: 0, count: n, file: "slurm.sbatch".into(), log: "logs/task-%a.log".into() }]
    } else {
        (0..n.div_ceil(array_max))
            .map(|k| Chunk {
                first: k * array_max,
                count: array_max.min(n - k * array_max),
                file: format!("slurm-{k}.sbatch"),
                log: format!("logs/slurm-{k}-task-%a.log"),
            })
            .collect()
    };
    chunks.iter().map(|c| (run.join(&c.file), script(plan, run, mannequin, throttle, partition, c))).collect()
}

/// A word the shell takes as it is.
pub fn shell_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The `sbatch` script of `chunk`; `throttle` caps the tasks running at once, and `partition`
/// picks one.
fn script(
    plan: &Plan,
    run: &Path,
    mannequin: &Path,
    throttle: Option<u32>,
    partition: Option<&str>,
    chunk: &Chunk,
) -> String {
    let n = chunk.count;
    let Needs { cpus, memory_gib, minutes } = plan.needs;
    let name = run.file_name().map_or("run".to_string(), |n| n.to_string_lossy().into_owned());
    let per_step: Vec<String> = Step::ALL
        .iter()
        .filter(|s| plan.people.iter().any(|p| p.runs(**s)))
        .map(|s| {
            let n = Needs::of(*s);
            format!("#   {:<9} {} CPUs, {} GiB, {} min", s.name(), n.cpus, n.memory_gib, n.minutes)
        })
        .collect();
    let throttle = throttle.map_or(String::new(), |t| format!("%{t}"));
    let mut out = format!(
        "#!/bin/bash\n\
         # Mannequin batch run `{name}`: {n} people ({from} to {to} of {all}) from {manifest}.\n\
         # Submit with `sbatch {script}`; submitting again finishes only what is left (finished\n\
         # steps are skipped, a stopped one resumes from its checkpoint). Per step, at the defaults:\n\
         {per_step}\n\
         #SBATCH --job-name=mannequin-{name}\n\
         #SBATCH --array=0-{last}{throttle}\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --mem={memory_gib}G\n\
         #SBATCH --time={hours:02}:{mins:02}:00\n\
         #SBATCH --output={log}\n\
         #SBATCH --open-mode=append\n",
        manifest = plan.manifest.display(),
        script = run.join(&chunk.file).display(),
        from = chunk.first,
        to = chunk.first + n - 1,
        all = plan.people.len(),
        per_step = per_step.join("\n"),
        last = n - 1,
        hours = minutes / 60,
        mins = minutes % 60,
        log = run.join(&chunk.log).display(),
    );
    if let Some(p) = partition {
        out.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    out.push_str(&format!(
        "\nexport RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"\n\
         exec {exe} batch task --run {run} --offset {first}\n",
        exe = shell_quote(&mannequin.to_string_lossy()),
        run = shell_quote(&run.to_string_lossy()),
        first = chunk.first,
    ));
    out
}
