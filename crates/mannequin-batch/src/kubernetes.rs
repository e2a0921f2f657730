//! The Kubernetes engine: a `batch/v1` Job in Indexed completion mode, a completion per person
//! (the index is `JOB_COMPLETION_INDEX`), `parallelism` at once, each pod mounting the shared
//! volume that holds the run folder and the inputs at the same path as here. A person who fails
//! uses up only their own index's retries (`backoffLimitPerIndex`), never the others'.

use std::path::Path;

use super::plan::Plan;

/// How the Job reaches the run: its container image, the claim of the shared volume and where
/// the pods mount it.
pub struct Cluster<'a> {
    pub image: &'a str,
    pub claim: &'a str,
    pub mount: &'a Path,
    pub parallelism: u32,
}

/// A Job name: lower-case letters, digits and `-`, at most 63 characters, from the run folder's.
fn job_name(run: &Path) -> String {
    let raw = run.file_name().map_or("run".to_string(), |n| n.to_string_lossy().to_ascii_lowercase());
    let cleaned: String = raw.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
    let name = format!("mannequin-{}", cleaned.trim_matches('-'));
    name.chars().take(52).collect::<String>().trim_end_matches('-').to_string()
}

/// A YAML string in double quotes (JSON's escapes are YAML's).
fn quoted(text: &str) -> String {
    serde_json::to_string(text).expect("a string serialises")
}

/// The Job of `plan` for the run folder `run`.
pub fn job(plan: &Plan, run: &Path, cluster: &Cluster) -> String {
    let n = plan.people.len();
    let needs = plan.needs;
    let command = ["mannequin", "batch", "task", "--run", &run.to_string_lossy()].map(quoted).join(", ");
    format!(
        "# Mannequin batch run: {n} people from {manifest}. Apply with `kubectl apply -f {file}`;\n\
         # applying it again (after deleting the finished Job) finishes only what is left.\n\
         apiVersion: batch/v1\n\
         kind: Job\n\
         metadata:\n  name: {name}\n  labels:\n    app.kubernetes.io/name: mannequin\n\
         spec:\n\
         \x20 completionMode: Indexed\n\
         \x20 completions: {n}\n\
         \x20 parallelism: {parallelism}\n\
         \x20 backoffLimitPerIndex: 2\n\
         \x20 maxFailedIndexes: {n}\n\
         \x20 template:\n\
         \x20   metadata:\n      labels:\n        app.kubernetes.io/name: mannequin\n\
         \x20   spec:\n\
         \x20     restartPolicy: Never\n\
         \x20     containers:\n\
         \x20       - name: task\n\
         \x20         image: {image}\n\
         \x20         command: [{command}]\n\
         \x20         env:\n\
         \x20           - name: RAYON_NUM_THREADS\n\
         \x20             value: \"{cpus}\"\n\
         \x20         resources:\n\
         \x20           requests:\n              cpu: \"{cpus}\"\n              memory: {mem}Gi\n\
         \x20           limits:\n              memory: {mem}Gi\n\
         \x20         volumeMounts:\n\
         \x20           - name: runs\n\
         \x20             mountPath: {mount}\n\
         \x20     volumes:\n\
         \x20       - name: runs\n\
         \x20         persistentVolumeClaim:\n\
         \x20           claimName: {claim}\n",
        manifest = plan.manifest.display(),
        file = run.join("job.yaml").display(),
        name = job_name(run),
        parallelism = cluster.parallelism.min(n as u32),
        image = quoted(cluster.image),
        cpus = needs.cpus,
        mem = needs.memory_gib,
        mount = quoted(&cluster.mount.to_string_lossy()),
        claim = quoted(cluster.claim),
    )
}
