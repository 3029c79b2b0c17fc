//! `sunlit sweep`, the CLI's edge of [`sunlit::sweep`]: its flags, the manifest keys read from
//! `annual`'s own clap definition, each line checked as `annual` would check it, and the command
//! lines the Slurm tasks and the merge job run. The library owns the manifest, the records, the
//! runs and the submission.

use super::*;

#[derive(Args)]
pub(super) struct SweepArgs {
    /// The manifest: one JSON object a line, "id" (a file name) plus `annual`'s long options as
    /// keys ("models": [...], "north": 90, "receivers": ["WIN_*"], "idf-out": true); relative
    /// paths resolve against its folder.
    #[arg(value_name = "MANIFEST.jsonl")]
    manifest: PathBuf,
    /// Output folder: <id>.csv (and <id>.idf/.epJSON) per variant, summary.csv, failed.csv, and
    /// the records of finished variants (.done/), so a second run counts only what is missing.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    output: PathBuf,
    /// Variants counted side by side, each an `annual` child process.
    #[arg(long, value_name = "N", default_value_t = 1)]
    jobs: usize,
    /// Submit a Slurm job array (a task per --per-task variants) and a merge job instead of
    /// counting here; only tasks with unfinished variants are submitted.
    #[arg(long, conflicts_with_all = ["index", "merge"])]
    slurm: bool,
    /// With --slurm: at most K array tasks at once.
    #[arg(long, value_name = "K", requires = "slurm")]
    array_max: Option<usize>,
    /// Variants an array task counts (--slurm, --index).
    #[arg(long, value_name = "M", default_value_t = 1)]
    per_task: usize,
    /// With --slurm: further sbatch options for both jobs, split at spaces
    /// (e.g. "--partition=cpu --time=2:00:00").
    #[arg(long, value_name = "ARGS", requires = "slurm", allow_hyphen_values = true)]
    sbatch: Option<String>,
    /// Count only array task INDEX's variants (what a Slurm task runs); no summary.
    #[arg(long, value_name = "INDEX", conflicts_with = "merge")]
    index: Option<usize>,
    /// Only write summary.csv (and failed.csv, the unfinished variants with their exit codes)
    /// from the records; exit 1 when a variant is unfinished.
    #[arg(long)]
    merge: bool,
}

/// `annual`'s arguments alone, for checking a sweep line as the command line would.
#[derive(Parser)]
#[command(name = "sunlit annual")]
struct AnnualLine {
    #[command(flatten)]
    args: AnnualArgs,
}

/// The manifest keys: `annual`'s long options, read from its clap definition, so an option added
/// there is a sweep key at once.
fn annual_schema() -> sunlit::sweep::Schema {
    use clap::{ArgAction, CommandFactory, ValueHint};
    use sunlit::sweep::{OptionKind, OptionSpec};
    let mut command = AnnualLine::command();
    command.build();
    let options = command
        .get_arguments()
        .filter(|a| !a.is_positional())
        .filter_map(|a| {
            let kind = match a.get_action() {
                ArgAction::SetTrue => OptionKind::Flag,
                ArgAction::Append => OptionKind::Repeated,
                ArgAction::Set => OptionKind::Value,
                _ => return None, // --help, --version
            };
            Some(OptionSpec { key: a.get_long()?.to_string(), kind, path: a.get_value_hint() == ValueHint::AnyPath })
        })
        .collect();
    sunlit::sweep::Schema { options }
}

/// Why a sweep line's annual run would be refused before counting, if it would: clap's parse of
/// its arguments, then the checks `annual` makes before loading the models.
fn sweep_line_problem(variant: &sunlit::sweep::Variant, dir: &std::path::Path) -> Option<String> {
    let argv = std::iter::once("annual".to_string()).chain(variant.args_into(dir));
    let line = match AnnualLine::try_parse_from(argv) {
        Ok(line) => line,
        Err(e) => {
            // clap's first paragraph, without "error: " and the usage that follows.
            let text = e.render().to_string();
            let first: Vec<&str> = text.lines().take_while(|l| !l.trim().is_empty()).map(str::trim).collect();
            return Some(first.join(" ").trim_start_matches("error:").trim().to_string());
        }
    };
    annual_refusals(&line.args).err().map(|e| e.render(&flag))
}

/// The checks `annual` makes before loading the models (its settings resolved, the hook, lanes).
fn annual_refusals(args: &AnnualArgs) -> Result<()> {
    let settings = args.settings()?.resolve()?;
    settings.options(None)?;
    args.hook.as_deref().map(Hook::parse).transpose()?;
    if args.lanes == Some(0) {
        return Err(Error::argument("lanes", "must be at least 1"));
    }
    Ok(())
}

pub(super) fn sweep(args: SweepArgs) -> Result<()> {
    use sunlit::sweep::{self, Manifest, Problem, run, slurm};
    let io = |source: std::io::Error, path: &std::path::Path| Error::Io { path: path.to_path_buf(), source };
    let dir = std::path::absolute(&args.output).map_err(|e| io(e, &args.output))?;
    if args.jobs == 0 {
        return Err(Error::argument("jobs", "must be at least 1"));
    }
    if args.per_task == 0 {
        return Err(Error::argument("per_task", "must be at least 1"));
    }
    // Every line is checked, and every problem reported, before anything is counted.
    let mut manifest = Manifest::read(&args.manifest, &annual_schema())?;
    let problems: Vec<Problem> =
        manifest.variants.iter().filter_map(|v| sweep_line_problem(v, &dir).map(|reason| Problem { line: v.line, reason })).collect();
    manifest.add_problems(problems);
    manifest.check()?;
    sweep::record::prepare(&dir)?;
    let exe = std::env::current_exe().map_err(|e| io(e, std::path::Path::new("sunlit")))?;
    if args.merge {
        return sweep_merge(&manifest, &dir);
    }
    if args.slurm {
        let tasks = slurm::pending_tasks(&manifest.variants, &dir, args.per_task);
        if tasks.is_empty() {
            eprintln!("every variant is finished; nothing submitted");
            return sweep_merge(&manifest, &dir);
        }
        // The tasks and the merge job run this same program on the same manifest and folder.
        let sweep = |more: &[&str]| -> Vec<String> {
            let mut words = vec![exe.display().to_string(), "sweep".into(), manifest.path.display().to_string(), "-o".into()];
            words.push(dir.display().to_string());
            words.extend(more.iter().map(|w| w.to_string()));
            words
        };
        let (per_task, jobs) = (args.per_task.to_string(), args.jobs.to_string());
        let options = slurm::SlurmOptions {
            dir: dir.clone(),
            task_command: sweep(&["--per-task", &per_task, "--jobs", &jobs, "--index"]),
            merge_command: sweep(&["--merge"]),
            array_max: args.array_max,
            sbatch: args.sbatch.as_deref().unwrap_or("").split_whitespace().map(String::from).collect(),
        };
        let s = slurm::submit(&options, &tasks)?;
        let list = slurm::array_list(&s.tasks);
        println!("array job {}: tasks {list} ({} variant(s) a task, of {})", s.array, args.per_task, manifest.variants.len());
        println!("merge job {}: after job {} ends, writes {}", s.merge, s.array, dir.join(sweep::summary::SUMMARY).display());
        println!(
            "follow: squeue -j {},{}   logs: {}/   failed variants: {}",
            s.array,
            s.merge,
            s.logs.display(),
            dir.join(sweep::FAILED_CSV).display()
        );
        return Ok(());
    }
    let variants: Vec<&sweep::Variant> = match args.index {
        Some(i) => sweep::chunk(&manifest.variants, i, args.per_task)?,
        None => manifest.variants.iter().collect(),
    };
    let outcome = run::run(&variants, &run::RunOptions { exe, dir: dir.clone(), jobs: args.jobs })?;
    eprintln!("counted {}, finished before {}, failed {}", outcome.counted.len(), outcome.skipped.len(), outcome.failed.len());
    if args.index.is_none() {
        let merged = sweep::merge(&manifest, &dir)?;
        eprintln!("wrote {} ({} variants)", dir.join(sweep::summary::SUMMARY).display(), merged.finished);
    }
    if outcome.failed.is_empty() {
        return Ok(());
    }
    let ids: Vec<String> = outcome
        .failed
        .iter()
        .map(|f| format!("{} (exit {}: {})", f.id, f.exit_code.map_or("-".into(), |c| c.to_string()), f.reason))
        .collect();
    Err(Error::argument(
        "sweep",
        format!("{} variant(s) failed: {}; logs in {}", ids.len(), ids.join("; "), dir.join(sweep::record::LOGS).display()),
    ))
}

/// Writes summary.csv and failed.csv; fails listing the unfinished variants.
fn sweep_merge(manifest: &sunlit::sweep::Manifest, dir: &std::path::Path) -> Result<()> {
    let merged = sunlit::sweep::merge(manifest, dir)?;
    eprintln!(
        "wrote {} ({} of {} variants)",
        dir.join(sunlit::sweep::summary::SUMMARY).display(),
        merged.finished,
        manifest.variants.len()
    );
    if merged.unfinished.is_empty() {
        return Ok(());
    }
    let list: Vec<String> = merged
        .unfinished
        .iter()
        .map(|u| format!("{} (exit {}): {}", u.id, u.exit_code.map_or("-".into(), |c| c.to_string()), u.reason))
        .collect();
    Err(Error::argument(
        "sweep",
        format!(
            "{} variant(s) unfinished (listed in {}):\n  {}",
            list.len(),
            dir.join(sunlit::sweep::FAILED_CSV).display(),
            list.join("\n  ")
        ),
    ))
}
