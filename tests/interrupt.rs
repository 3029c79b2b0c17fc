//! Output atomicity under interruption: `sunlit annual` stopped by Ctrl-C (SIGINT), SIGTERM or
//! SIGKILL mid-run leaves neither a partial CSV nor a temporary file beside it.

#![cfg(unix)]
#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
use common::runtime_dir;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use sunlit::model::office::office;

/// A scratch folder for one test: removed when the test passes, kept when it fails.
fn scratch(name: &str) -> common::Scratch {
    common::Scratch::new("interrupt", name)
}

/// A dense annual run on the example office, counted by the GPU path: tens of seconds on lavapipe
/// (the exact engine that `auto` picks for this model would finish before the signal).
fn start_annual(dir: &Path) -> Child {
    std::fs::write(dir.join("office.glb"), office(2).to_glb()).unwrap();
    Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args([
            "annual",
            "office.glb",
            "--location",
            "40,-105,-7",
            "--dense",
            "--engine",
            "gpu",
            "--timesteps-per-hour",
            "4",
            "-o",
            "out.csv",
        ])
        .current_dir(dir)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Sends `signal` once the run has been counting for a while; returns its exit status and stderr.
fn interrupt(child: &mut Child, signal: &str) -> (std::process::ExitStatus, String) {
    std::thread::sleep(Duration::from_secs(3));
    assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be interrupted");
    let sent = Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap();
    assert!(sent.success());
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(start.elapsed() < Duration::from_secs(60), "sunlit did not stop on {signal}");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output_ref()
}

trait WaitRef {
    fn wait_with_output_ref(&mut self) -> (std::process::ExitStatus, String);
}

impl WaitRef for Child {
    fn wait_with_output_ref(&mut self) -> (std::process::ExitStatus, String) {
        use std::io::Read;
        let status = self.wait().unwrap();
        let mut err = String::new();
        self.stderr.take().unwrap().read_to_string(&mut err).unwrap();
        (status, err)
    }
}

/// Only the model is left in the folder.
fn assert_nothing_written(dir: &Path) {
    let left: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(left, ["office.glb"], "files left behind");
}

#[test]
fn ctrl_c_exits_130_and_leaves_nothing() {
    for signal in ["-INT", "-TERM"] {
        let dir = scratch(&signal[1..]);
        let mut child = start_annual(&dir);
        let (status, stderr) = interrupt(&mut child, signal);
        assert_eq!(status.code(), Some(130), "{signal}: {stderr}");
        assert!(stderr.contains("interrupted") && !stderr.contains("panicked"), "{signal}: {stderr}");
        assert_nothing_written(&dir);
    }
}

#[test]
fn kill_leaves_nothing() {
    use std::os::unix::process::ExitStatusExt;
    let dir = scratch("KILL");
    let mut child = start_annual(&dir);
    let (status, _) = interrupt(&mut child, "-KILL");
    assert_eq!(status.signal(), Some(9));
    assert_nothing_written(&dir);
}
