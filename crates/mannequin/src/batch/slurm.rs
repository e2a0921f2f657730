//! The Slurm engine: one `sbatch` script whose job array has a task per person (the index is
//! `SLURM_ARRAY_TASK_ID`), with what each task asks for and how many run at once (`%`).
//! Submitting it again finishes only what is left.

use std::path::Path;

use super::plan::Plan;
use super::resources::Needs;
use super::step::Step;

/// Where Slurm writes task `%a`'s output.
pub const LOG_PATTERN: &str = "logs/task-%a.log";

/// A word the shell takes as it is.
pub fn shell_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The `sbatch` script of `plan` for the run folder `run`; `throttle` caps the tasks running at
/// once, and `partition` picks one.
pub fn script(
    plan: &Plan,
    run: &Path,
    mannequin: &Path,
    throttle: Option<u32>,
    partition: Option<&str>,
) -> String {
    let n = plan.people.len();
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
         # Mannequin batch run `{name}`: {n} people from {manifest}.\n\
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
        script = run.join("slurm.sbatch").display(),
        per_step = per_step.join("\n"),
        last = n - 1,
        hours = minutes / 60,
        mins = minutes % 60,
        log = run.join(LOG_PATTERN).display(),
    );
    if let Some(p) = partition {
        out.push_str(&format!("#SBATCH --partition={p}\n"));
    }
    out.push_str(&format!(
        "\nexport RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"\n\
         exec {exe} batch task --run {run}\n",
        exe = shell_quote(&mannequin.to_string_lossy()),
        run = shell_quote(&run.to_string_lossy()),
    ));
    out
}
