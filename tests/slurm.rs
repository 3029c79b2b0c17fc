//! `sunlit sweep --slurm` on a real one-node Slurm cluster started here (Debian's munge,
//! slurmctld, slurmd, slurm-client; installed with apt-get when missing, so it must run as
//! root): the array's results equal the local sweep's, a task cancelled mid-run is listed as
//! unfinished by the merge job, and a resubmission counts only it. The daemons stop afterwards,
//! even when the test fails.

#![allow(clippy::unwrap_used, clippy::expect_used)] // Tests may panic on the unexpected.

mod common;
mod sweep_fixture;
use sweep_fixture::*;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Runs a command (Slurm's clients read `SLURM_CONF`), returning its stdout; panics with its
/// stderr when it fails.
fn sh(conf: &Path, program: &str, args: &[&str]) -> String {
    let out = Command::new(program).args(args).env("SLURM_CONF", conf).output().unwrap_or_else(|e| panic!("{program}: {e}"));
    assert!(out.status.success(), "{program} {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Whether `program` is on the PATH (or in /usr/sbin, where Debian puts the daemons).
fn installed(program: &str) -> bool {
    ["/usr/sbin", "/usr/bin", "/sbin", "/bin"].iter().any(|d| Path::new(d).join(program).exists())
}

/// Installs the packages when missing; a clear failure where that cannot be done.
fn ensure_packages() {
    if installed("slurmctld") && installed("slurmd") && installed("sbatch") && installed("munged") {
        return;
    }
    let uid = Command::new("id").arg("-u").output().unwrap();
    assert_eq!(
        String::from_utf8_lossy(&uid.stdout).trim(),
        "0",
        "the Slurm test installs munge, slurmctld, slurmd and slurm-client with apt-get and runs the daemons: run it as root (CI does)"
    );
    assert!(installed("apt-get"), "the Slurm test needs apt-get to install munge, slurmctld, slurmd and slurm-client");
    let status = Command::new("apt-get")
        .args(["install", "-y", "--no-install-recommends", "munge", "slurmctld", "slurmd", "slurm-client"])
        .env("DEBIAN_FRONTEND", "noninteractive")
        .status()
        .unwrap();
    assert!(status.success(), "apt-get install munge slurmctld slurmd slurm-client failed");
}

/// A free TCP port (bound and released), so the cluster does not collide with another.
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// The cluster; dropping it stops the daemons it started.
struct Cluster {
    conf: PathBuf,
    state: PathBuf,
    started_munged: bool,
}

impl Cluster {
    fn start(state: &Path) -> Self {
        ensure_packages();
        let uid = Command::new("id").arg("-u").output().unwrap();
        assert_eq!(String::from_utf8_lossy(&uid.stdout).trim(), "0", "the Slurm test runs slurmctld and slurmd: run it as root (CI does)");
        let munge_works = || Command::new("sh").args(["-c", "munge -n | unmunge"]).output().is_ok_and(|o| o.status.success());
        let started_munged = !munge_works();
        if started_munged {
            let setup = "[ -s /etc/munge/munge.key ] || mungekey --create; chown munge: /etc/munge/munge.key; chmod 400 /etc/munge/munge.key; \
                         install -d -o munge -g munge -m 0755 /run/munge; runuser -u munge -- /usr/sbin/munged";
            let out = Command::new("sh").args(["-c", setup]).output().unwrap();
            assert!(out.status.success(), "munged: {}", String::from_utf8_lossy(&out.stderr));
            assert!(munge_works(), "munged started but munge -n | unmunge fails");
        }
        let host = String::from_utf8_lossy(&Command::new("hostname").arg("-s").output().unwrap().stdout).trim().to_string();
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap();
        let total_kib: u64 =
            meminfo.lines().find_map(|l| l.strip_prefix("MemTotal:")).unwrap().trim().trim_end_matches("kB").trim().parse().unwrap();
        let memory = (total_kib / 1024).saturating_sub(1024).max(512);
        for sub in ["ctld", "d", "log"] {
            std::fs::create_dir_all(state.join(sub)).unwrap();
        }
        let s = |p: &str| state.join(p).display().to_string();
        let conf = state.join("slurm.conf");
        let text = format!(
            "ClusterName=sweeptest\nSlurmctldHost={host}\nSlurmctldPort={}\nSlurmdPort={}\nSlurmUser=root\nSlurmdUser=root\n\
             StateSaveLocation={}\nSlurmdSpoolDir={}\nSlurmctldPidFile={}\nSlurmdPidFile={}\nSlurmctldLogFile={}\nSlurmdLogFile={}\n\
             ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nJobAcctGatherType=jobacct_gather/none\n\
             AccountingStorageType=accounting_storage/none\nJobCompType=jobcomp/filetxt\nJobCompLoc={}\nMpiDefault=none\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nReturnToService=2\nKillWait=5\n\
             NodeName={host} CPUs={cpus} RealMemory={memory} State=UNKNOWN\nPartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP\n",
            free_port(),
            free_port(),
            s("ctld"),
            s("d"),
            s("slurmctld.pid"),
            s("slurmd.pid"),
            s("log/slurmctld.log"),
            s("log/slurmd.log"),
            s("log/jobcomp.log"),
        );
        std::fs::write(&conf, text).unwrap();
        let cluster = Cluster { conf: conf.clone(), state: state.to_path_buf(), started_munged };
        sh(&conf, "slurmctld", &["-c"]);
        sh(&conf, "slurmd", &[]);
        let start = Instant::now();
        loop {
            let out = Command::new("sinfo").args(["-h", "-o", "%T"]).env("SLURM_CONF", &conf).output().unwrap();
            if String::from_utf8_lossy(&out.stdout).lines().any(|l| l.trim() == "idle") {
                break;
            }
            assert!(start.elapsed() < Duration::from_secs(60), "the node is not idle after 60 s; see {}", s("log"));
            std::thread::sleep(Duration::from_millis(300));
        }
        cluster
    }

    /// Slurm's state of job `id` (`RUNNING`, `PENDING`, …), `None` once it left the queue.
    fn states(&self, id: &str) -> Vec<String> {
        let out = Command::new("squeue").args(["-h", "-j", id, "-o", "%i %T"]).env("SLURM_CONF", &self.conf).output().unwrap();
        String::from_utf8_lossy(&out.stdout).lines().map(str::to_string).collect()
    }

    /// Waits until jobs `ids` left the queue.
    fn wait_gone(&self, ids: &str, limit: Duration) {
        let start = Instant::now();
        while !self.states(ids).is_empty() {
            assert!(start.elapsed() < limit, "jobs {ids} still queued after {limit:?}: {:?}", self.states(ids));
            std::thread::sleep(Duration::from_millis(500));
        }
    }

    fn pid(&self, file: &str) -> Option<String> {
        std::fs::read_to_string(self.state.join(file)).ok().map(|p| p.trim().to_string())
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new("scontrol").arg("shutdown").env("SLURM_CONF", &self.conf).output();
        let pids: Vec<String> = ["slurmctld.pid", "slurmd.pid"].iter().filter_map(|f| self.pid(f)).collect();
        let start = Instant::now();
        while pids.iter().any(|p| Path::new("/proc").join(p).exists()) && start.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(200));
        }
        for p in &pids {
            let _ = Command::new("kill").args(["-9", p]).output();
        }
        if self.started_munged
            && let Ok(pid) = std::fs::read_to_string("/run/munge/munged.pid")
        {
            let _ = Command::new("kill").arg(pid.trim()).output();
        }
    }
}

/// The job ids from `sunlit sweep --slurm`'s output ("array job N: …", "merge job M: …").
fn job_ids(stdout: &str) -> (String, String) {
    let id = |prefix: &str| {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .and_then(|r| r.split(':').next())
            .unwrap_or_else(|| panic!("'{prefix}' in {stdout}"))
            .to_string()
    };
    (id("array job "), id("merge job "))
}

/// One cluster at a time: the tests here each start their own.
static ONE_CLUSTER: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn slurm_array_equals_the_local_sweep_and_a_cancelled_task_is_all_a_resubmission_counts() {
    let _one = ONE_CLUSTER.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let dir = scratch("sweep-slurm");
    let cluster = Cluster::start(&dir.join("slurm"));
    let fast = variants(&dir);
    // The seventh variant counts every timestep densely on the GPU path (the exact engine would finish it
    // in a second): slow enough to be cancelled running.
    let slow = r#"{"id": "slow", "models": ["office.glb", "louvres-50.glb"], "dense": true, "engine": "gpu", "location": "46.5,11.35,1", "resolution": 64, "timesteps-per-hour": 2}"#.to_string();
    let local = write_manifest(&dir, "local.jsonl", &fast);
    let all: Vec<String> = fast.iter().cloned().chain([slow]).collect();
    let ids = ids(&all);
    let manifest = write_manifest(&dir, "sweep.jsonl", &all);
    let (local_out, out) = (dir.join("local"), dir.join("out"));
    let run = sunlit(&["sweep", &local.display().to_string(), "-o", &local_out.display().to_string(), "--jobs", "2"]);
    assert!(run.status.success(), "{}", stderr(&run));

    let (m, o) = (manifest.display().to_string(), out.display().to_string());
    let submit = || {
        let out = Command::new(env!("CARGO_BIN_EXE_sunlit"))
            .args(["sweep", &m, "-o", &o, "--slurm"])
            .env("SLURM_CONF", &cluster.conf)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let first = submit();
    assert!(first.contains("tasks 0-6 (1 variant(s) a task, of 7)") && first.contains("follow: squeue -j"), "{first}");
    let (array, merge) = job_ids(&first);

    // Cancel the slow task once it is counting.
    let task = format!("{array}_6");
    let start = Instant::now();
    while !(cluster.states(&task).iter().any(|s| s.ends_with("RUNNING")) && out.join(".logs/slow.log").exists()) {
        assert!(start.elapsed() < Duration::from_secs(300), "task {task} never ran: {:?}", cluster.states(&array));
        std::thread::sleep(Duration::from_millis(200));
    }
    std::thread::sleep(Duration::from_secs(1));
    sh(&cluster.conf, "scancel", &[&task]);
    cluster.wait_gone(&format!("{array},{merge}"), Duration::from_secs(300));

    // The merge job ran after the array: six variants in the summary, the slow one listed.
    let failed = std::fs::read_to_string(out.join("failed.csv"))
        .unwrap_or_else(|_| panic!("failed.csv; merge log in {}", out.join(".slurm/logs").display()));
    assert!(failed.starts_with("id,exit_code,reason\nslow,"), "{failed}");
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 1 + 6 * 10, "{summary}");
    assert!(!summary.contains("\nslow,"));
    let before = record_times(&out, &ids);
    assert!(before[..6].iter().all(Option::is_some) && before[6].is_none(), "{before:?}");
    assert!(!out.join("slow.csv").exists() && partial_files(&out).is_empty(), "a cancelled task leaves nothing partial");

    // Resubmitted: only the cancelled task runs; nothing else is counted twice.
    let second = submit();
    assert!(second.contains("tasks 6 (1 variant(s) a task, of 7)"), "{second}");
    let (array2, merge2) = job_ids(&second);
    cluster.wait_gone(&format!("{array2},{merge2}"), Duration::from_secs(300));
    let after = record_times(&out, &ids);
    assert_eq!(after[..6], before[..6], "finished variants were not counted again");
    assert!(after[6].is_some(), "the slow variant finished on resubmission");
    assert!(!out.join("failed.csv").exists(), "every variant finished");
    assert_eq!(std::fs::read_to_string(out.join("summary.csv")).unwrap().lines().count(), 1 + 7 * 10);

    // The array's results are the local sweep's, file for file and row for row.
    for id in &ids[..6] {
        let a = std::fs::read(out.join(format!("{id}.csv"))).unwrap();
        assert!(a == std::fs::read(local_out.join(format!("{id}.csv"))).unwrap(), "{id}: Slurm's CSV differs from the local sweep's");
    }
    let local_summary = std::fs::read_to_string(local_out.join("summary.csv")).unwrap();
    let slurm_summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    for row in local_summary.lines().skip(1) {
        // The settings columns differ (the slow line adds `dense`): compare id, surface, mean.
        let key: String = row.split(',').take(4).collect::<Vec<_>>().join(",");
        assert!(slurm_summary.lines().any(|r| r.starts_with(&key)), "{key} in {slurm_summary}");
    }
    // Resubmitting a finished sweep submits nothing.
    let out3 = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args(["sweep", &m, "-o", &o, "--slurm"])
        .env("SLURM_CONF", &cluster.conf)
        .output()
        .unwrap();
    assert!(out3.status.success() && stderr(&out3).contains("nothing submitted"), "{}", stderr(&out3));
    drop(cluster);
}

/// `sunlit district --slurm`: an array task a tile and a merge job; its cadastre equals the
/// one-process run's (one tile holding the whole district) within 1e-9, with the exact engine and
/// a context reaching across the district, and so does its `--year-table` (byte for byte: the
/// tasks write their parts, the merge job merges them).
#[test]
fn slurm_district_tiles_equal_the_one_process_run() {
    let _one = ONE_CLUSTER.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let dir = scratch("district-slurm");
    let cluster = Cluster::start(&dir.join("slurm"));
    let city = dir.join("district.city.json");
    std::fs::write(&city, sunlit::model::city_write::district_cityjson(3, 3, 7)).unwrap();
    let epw = dir.join("site.epw");
    std::fs::write(&epw, varying_epw()).unwrap();
    let (one, tiled) = (dir.join("one"), dir.join("tiled"));
    let args = |out: &Path, tile: &str| -> Vec<String> {
        let words = ["district", city.to_str().unwrap(), "--epw", epw.to_str().unwrap(), "-o", out.to_str().unwrap(), "--tile", tile];
        let small = ["--context", "1000", "--engine", "exact", "--days-per-year", "4", "--samples-per-day", "5", "--year-table"];
        words.iter().chain(&small).map(|w| w.to_string()).collect()
    };
    let run = Command::new(env!("CARGO_BIN_EXE_sunlit")).args(args(&one, "1000")).output().unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    let submit = Command::new(env!("CARGO_BIN_EXE_sunlit"))
        .args(args(&tiled, "30"))
        .arg("--slurm")
        .env("SLURM_CONF", &cluster.conf)
        .output()
        .unwrap();
    assert!(submit.status.success(), "{}", stderr(&submit));
    let stdout = String::from_utf8_lossy(&submit.stdout).into_owned();
    let (array, merge) = job_ids(&stdout);
    cluster.wait_gone(&format!("{array},{merge}"), Duration::from_secs(300));
    assert!(tiled.join("cadastre.city.json").exists(), "the merge job wrote the cadastre; logs in {}", tiled.join(".slurm/logs").display());
    let (a, b) = (tile_rows(&one), tile_rows(&tiled));
    assert_eq!(a.len(), b.len());
    for ((name, x), (other, y)) in a.iter().zip(&b) {
        assert_eq!(name, other);
        assert!(x.iter().zip(y).all(|(x, y)| (x - y).abs() <= 1e-9), "{name}: {x:?} against {y:?}");
    }
    assert!(std::fs::read_dir(tiled.join(".done")).unwrap().count() >= 4, "several tiles");
    let table = |out: &Path| std::fs::read_to_string(out.join("cadastre-year.csv")).unwrap();
    let (whole, tasks) = (table(&one), table(&tiled));
    assert_eq!(whole.lines().count(), 8761);
    assert!(whole == tasks, "the year tables differ");
    drop(cluster);
}
