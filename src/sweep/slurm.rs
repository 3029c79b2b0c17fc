//! A sweep as a Slurm job array: one task per `per_task` variants, each running the caller's task
//! command with the task's index appended (the CLI gives `sunlit sweep … --index`), and a merge job
//! after the array (`afterany`) that writes the summary and lists what failed. The commands are
//! the edge's: this module quotes them for the shell, writes the scripts and calls `sbatch`.
//!
//! Only tasks with unfinished variants are submitted, so resubmitting after a failure or a
//! cancellation runs just what is missing. The scripts and logs live in `DIR/.slurm/`; the
//! output folder must be on a file system the nodes share. Submission is `sbatch`, nothing else:
//! the scheduler does the rest.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::manifest::Variant;
use super::record;
use crate::error::{Error, Result};
use crate::export::write_atomic;

/// Scripts and logs inside the output folder.
pub const SLURM: &str = ".slurm";
/// Slurm's default largest array index (MaxArraySize 1001).
const MAX_ARRAY_INDEX: usize = 1000;

/// What to submit.
#[derive(Debug, Clone)]
pub struct SlurmOptions {
    /// The output folder (absolute, shared by the nodes): scripts and logs go in `DIR/.slurm/`.
    pub dir: PathBuf,
    /// What an array task runs (program and arguments, paths as the nodes see them); the task's
    /// index follows as one more argument.
    pub task_command: Vec<String>,
    /// What the merge job runs.
    pub merge_command: Vec<String>,
    /// At most this many tasks at once (`%K` of `--array`).
    pub array_max: Option<usize>,
    /// Further sbatch arguments for both jobs (partition, account, time, …).
    pub sbatch: Vec<String>,
}

/// What was submitted.
#[derive(Debug, Clone, PartialEq)]
pub struct Submitted {
    /// The array job's id.
    pub array: String,
    /// The merge job's id.
    pub merge: String,
    /// The task indices submitted.
    pub tasks: Vec<usize>,
    /// Where the logs go.
    pub logs: PathBuf,
}

/// Task indices (of `per_task` variants each) that hold an unfinished variant.
pub fn pending_tasks(variants: &[Variant], dir: &Path, per_task: usize) -> Vec<usize> {
    let per_task = per_task.max(1);
    variants
        .chunks(per_task)
        .enumerate()
        .filter(|(_, chunk)| chunk.iter().any(|v| record::finished(dir, v).is_none()))
        .map(|(i, _)| i)
        .collect()
}

/// Indices as Slurm's `--array` list: runs as ranges, `0-3,5,7-9`.
pub fn array_list(indices: &[usize]) -> String {
    let mut parts = Vec::new();
    let mut k = 0;
    while k < indices.len() {
        let start = indices[k];
        let mut end = start;
        while k + 1 < indices.len() && indices[k + 1] == end + 1 {
            k += 1;
            end += 1;
        }
        parts.push(if start == end { start.to_string() } else { format!("{start}-{end}") });
        k += 1;
    }
    parts.join(",")
}

/// `text` quoted for a POSIX shell.
fn quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// A command line quoted word by word for a POSIX shell.
fn shell_command(words: &[String]) -> String {
    words.iter().map(|w| quote(w)).collect::<Vec<_>>().join(" ")
}

/// The array task's script.
pub fn task_script(options: &SlurmOptions) -> String {
    format!(
        "#!/bin/sh\n# A task of a sunlit sweep's job array: counts the unfinished variants of task\n# $SLURM_ARRAY_TASK_ID.\nexec {} \"$SLURM_ARRAY_TASK_ID\"\n",
        shell_command(&options.task_command)
    )
}

/// The merge job's script.
pub fn merge_script(options: &SlurmOptions) -> String {
    format!(
        "#!/bin/sh\n# The merge job of a sunlit sweep: summary.csv, and failed.csv listing unfinished\n# variants with their exit codes.\nexec {}\n",
        shell_command(&options.merge_command)
    )
}

/// Writes the scripts into `DIR/.slurm/` and submits the tasks in `tasks` and the merge job.
pub fn submit(options: &SlurmOptions, tasks: &[usize]) -> Result<Submitted> {
    if let Some(&last) = tasks.last().filter(|&&t| t > MAX_ARRAY_INDEX) {
        return Err(Error::argument(
            "per_task",
            format!("task index {last} is past Slurm's usual array limit ({MAX_ARRAY_INDEX}); put more variants in a task"),
        ));
    }
    if tasks.is_empty() {
        return Err(Error::argument("tasks", "nothing to submit: every variant is finished"));
    }
    let folder = options.dir.join(SLURM);
    let logs = folder.join("logs");
    std::fs::create_dir_all(&logs).map_err(|source| Error::Io { path: logs.clone(), source })?;
    let task = folder.join("task.sh");
    let merge = folder.join("merge.sh");
    write_atomic(&task, task_script(options).as_bytes())?;
    write_atomic(&merge, merge_script(options).as_bytes())?;
    let mut array = array_list(tasks);
    if let Some(k) = options.array_max {
        array.push_str(&format!("%{k}"));
    }
    let array_id = sbatch(
        &["--job-name=sunlit-sweep".into(), format!("--array={array}"), format!("--output={}", logs.join("%A_%a.out").display())],
        options,
        &task,
    )?;
    let merge_id = sbatch(
        &[
            "--job-name=sunlit-sweep-merge".into(),
            format!("--dependency=afterany:{array_id}"),
            format!("--output={}", logs.join("merge-%j.out").display()),
        ],
        options,
        &merge,
    )?;
    Ok(Submitted { array: array_id, merge: merge_id, tasks: tasks.to_vec(), logs })
}

/// Runs `sbatch --parsable ARGS EXTRA SCRIPT` and returns the job id.
fn sbatch(args: &[String], options: &SlurmOptions, script: &Path) -> Result<String> {
    let output = Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .args(&options.sbatch)
        .arg(script)
        .output()
        .map_err(|source| Error::Io { path: PathBuf::from("sbatch"), source })?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        let err = String::from_utf8_lossy(&output.stderr);
        return Err(Error::argument("sbatch", format!("{} ({})", err.trim(), output.status)));
    }
    // --parsable prints "ID" or "ID;CLUSTER".
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::argument("sbatch", format!("unexpected output '{}'", stdout.trim())));
    }
    Ok(id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_lists_are_compressed_runs() {
        assert_eq!(array_list(&[0, 1, 2, 3, 5, 7, 8, 9]), "0-3,5,7-9");
        assert_eq!(array_list(&[4]), "4");
        assert_eq!(array_list(&[]), "");
    }

    #[test]
    fn scripts_quote_paths_for_the_shell() {
        let words = |w: &[&str]| w.iter().map(|w| w.to_string()).collect::<Vec<_>>();
        let options = SlurmOptions {
            dir: "/d/out".into(),
            task_command: words(&["/opt/sun lit/sunlit", "sweep", "/d/it's.jsonl", "-o", "/d/out", "-x", "2"]),
            merge_command: words(&["/opt/sun lit/sunlit", "sweep", "/d/it's.jsonl", "-m"]),
            array_max: None,
            sbatch: vec![],
        };
        let s = task_script(&options);
        assert!(s.starts_with("#!/bin/sh\n"));
        assert!(
            s.contains(r#"exec '/opt/sun lit/sunlit' 'sweep' '/d/it'\''s.jsonl' '-o' '/d/out' '-x' '2' "$SLURM_ARRAY_TASK_ID""#),
            "{s}"
        );
        assert!(merge_script(&options).ends_with("'/d/it'\\''s.jsonl' '-m'\n"));
    }
}
