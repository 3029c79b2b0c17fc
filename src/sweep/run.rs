//! Running variants: each one is the `annual` subcommand of the sunlit executable in a child
//! process, up to `jobs` at a time, writing into the output folder.
//!
//! A child process per variant makes each output byte for byte what a separate annual run
//! writes (it is one), isolates a variant's failure (its exit code is recorded, the others go
//! on), and is what a Slurm task runs as well; on the 2-core machine it measured no slower than
//! counting variants in one process (docs/guide-sweeps.md). The annual run writes its files
//! atomically; the done record follows, so a killed sweep loses only the variants in flight.
//! On Linux a child gets SIGTERM when the sweep dies (even by SIGKILL), and its own handler
//! removes its temporary file: nothing partial stays behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use super::manifest::Variant;
use super::record::{self, Done, Failed, Fingerprint};
use super::summary;
use crate::error::{Error, Result};

/// How to run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// The sunlit executable whose `annual` subcommand counts a variant.
    pub exe: PathBuf,
    /// The output folder (absolute).
    pub dir: PathBuf,
    /// Variants counted side by side (at least 1).
    pub jobs: usize,
}

/// What a run did, by id.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    /// Counted by this run.
    pub counted: Vec<String>,
    /// Finished before (their record matched): not counted again.
    pub skipped: Vec<String>,
    /// Failed in this run.
    pub failed: Vec<Failed>,
}

/// Counts every variant of `variants` that is not finished in `options.dir`.
pub fn run(variants: &[&Variant], options: &RunOptions) -> Result<Outcome> {
    if options.jobs == 0 {
        return Err(Error::argument("jobs", "must be at least 1"));
    }
    record::prepare(&options.dir)?;
    let outcome = Mutex::new(Outcome::default());
    let next = AtomicUsize::new(0);
    let total = variants.len();
    let worker = || {
        loop {
            let k = next.fetch_add(1, Ordering::SeqCst);
            let Some(variant) = variants.get(k) else { break };
            let result = one(variant, options);
            let mut o = outcome.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            match result {
                Ok(Some(seconds)) => {
                    eprintln!("[{}/{total}] {}: counted in {seconds:.1} s", k + 1, variant.id);
                    o.counted.push(variant.id.clone());
                }
                Ok(None) => {
                    eprintln!("[{}/{total}] {}: finished before, skipped", k + 1, variant.id);
                    o.skipped.push(variant.id.clone());
                }
                Err(failed) => {
                    eprintln!("[{}/{total}] {}: FAILED: {}", k + 1, variant.id, failed.reason);
                    o.failed.push(failed);
                }
            }
        }
    };
    std::thread::scope(|s| {
        for _ in 0..options.jobs.min(total.max(1)) {
            s.spawn(worker);
        }
    });
    Ok(outcome.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner))
}

/// Counts one variant unless it is finished: `Some(seconds)` counted, `None` skipped.
fn one(variant: &Variant, options: &RunOptions) -> std::result::Result<Option<f64>, Failed> {
    let dir = &options.dir;
    if record::finished(dir, variant).is_some() {
        return Ok(None);
    }
    record::forget(dir, &variant.id);
    let log = record::log_path(dir, &variant.id);
    let fail = |exit_code: Option<i32>, reason: String| {
        let failed = Failed { id: variant.id.clone(), exit_code, reason, log: log.display().to_string() };
        if let Err(e) = record::write_failed(dir, &failed) {
            log::warn!("{e}");
        }
        failed
    };
    let fingerprint = Fingerprint::of(variant);
    let start = Instant::now();
    let args: Vec<String> = std::iter::once("annual".to_string()).chain(variant.args_into(dir)).collect();
    let status = spawn_sunlit(&options.exe, &args, &log).map_err(|e| fail(None, e.to_string()))?;
    if !status.success() {
        return Err(fail(status.code(), last_error(&log, status)));
    }
    let seconds = start.elapsed().as_secs_f64();
    let surfaces = summary::means_of(dir, variant).map_err(|e| fail(None, e.to_string()))?;
    let outputs = variant.outputs(dir).iter().filter_map(|p| p.file_name()).map(|n| n.to_string_lossy().into_owned()).collect();
    let hash = fingerprint.hash();
    let done = Done { id: variant.id.clone(), fingerprint, hash, outputs, seconds, surfaces };
    record::write_done(dir, &done).map_err(|e| fail(None, e.to_string()))?;
    Ok(Some(seconds))
}

/// Runs `exe ARGS` (a subcommand and its arguments) with its stderr in `log`, and waits for it.
pub fn spawn_sunlit(exe: &Path, args: &[String], log: &Path) -> Result<std::process::ExitStatus> {
    let io = |source: std::io::Error, path: &Path| Error::Io { path: path.to_path_buf(), source };
    let log_file = std::fs::File::create(log).map_err(|e| io(e, log))?;
    let mut command = Command::new(exe);
    command.args(args).stdin(Stdio::null()).stdout(Stdio::null()).stderr(log_file);
    die_with_parent(&mut command);
    let mut child = command.spawn().map_err(|e| io(e, exe))?;
    child.wait().map_err(|e| io(e, exe))
}

/// On Linux, the child gets SIGTERM when this thread's process dies (even by SIGKILL), so no
/// annual run outlives a killed sweep; its handler removes its temporary file.
#[cfg(target_os = "linux")]
fn die_with_parent(command: &mut Command) {
    use std::os::unix::process::CommandExt;
    let parent = std::process::id() as libc::pid_t;
    // SAFETY: prctl and getppid are async-signal-safe; nothing else runs between fork and exec.
    unsafe {
        command.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            // The parent died before prctl took effect: stop now.
            if libc::getppid() != parent {
                return Err(std::io::Error::other("sweep ended before the variant started"));
            }
            Ok(())
        });
    }
}

#[cfg(not(target_os = "linux"))]
fn die_with_parent(_command: &mut Command) {}

/// The failed run's last `error:` line from its log, else how it ended.
pub fn last_error(log: &Path, status: std::process::ExitStatus) -> String {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let line = text.lines().rev().find(|l| l.starts_with("error:") || l.contains("interrupted") || l.contains("panicked"));
    match line {
        Some(l) => l.trim_start_matches("error:").trim().to_string(),
        None => format!("ended with {status} (log: {})", log.display()),
    }
}
