//! A sweep through a real scheduler: `contact-sweep slurm --submit` on the one-node Slurm that
//! the project's `tests/slurm/start-local-slurm.sh` brings up (installing slurm-wlm and munge
//! if needed; needs root, as in CI). Three array tasks write shards into one folder; the
//! dependent summary job summarizes them. The cluster stays up between tests (the script is
//! idempotent); `tests/slurm/stop-local-slurm.sh` stops it.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{assert_complete, cli, write};
use contact_sweep::sink::read_runs;

const SWEEP: &str = r#"
name = "slurm-test"
scene = "bar1d"
[fixed]
T = 3.0
courant = 1.0
[grid]
h = [0.0625, 0.03125, 0.015625, 0.0078125]
method = [
  { space = "mixed", mass = "mod3", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hybrid" },
  { space = "mixed", mass = "zero-contact", scheme = "crank-nicolson" },
]
"#;

/// Bring up (or find up) the one-node cluster of `tests/slurm/start-local-slurm.sh`; its output
/// is shown when it fails (the install log and the daemons' logs' tails).
fn start_local_slurm() {
    let start = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/slurm/start-local-slurm.sh");
    let up = Command::new("bash")
        .arg(&start)
        .env("SLURM_LOCAL_MIN_JOB_AGE", "600")
        .output()
        .expect("bash runs");
    assert!(
        up.status.success(),
        "local Slurm did not start:\n{}\n{}",
        String::from_utf8_lossy(&up.stdout),
        String::from_utf8_lossy(&up.stderr)
    );
}

#[test]
fn a_job_array_runs_the_sweep_in_shards_and_summarizes_it() {
    start_local_slurm();

    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "s.toml", SWEEP);
    let out = tmp.path().join("out");
    let o = cli(
        tmp.path(),
        &[
            "slurm",
            "s.toml",
            "--tasks",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--submit",
        ],
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("submitted array job"), "{stdout}");

    // The summary job runs after every array task succeeded (afterok).
    let done = out.join("summary/convergence.parquet");
    let t0 = Instant::now();
    while !done.exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(240),
            "the summary job did not finish; squeue:\n{}",
            String::from_utf8_lossy(
                &Command::new("squeue")
                    .args(["-t", "all"])
                    .output()
                    .unwrap()
                    .stdout
            )
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    assert_complete(&out, 12);
    let runs = read_runs(&out).unwrap();
    assert!(
        runs.column("status")
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .all(|s| s == Some("ok"))
    );
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    let mut shards: Vec<String> = manifest["sessions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["shard"].as_str().unwrap().to_string())
        .collect();
    shards.sort();
    assert_eq!(shards, ["0/3", "1/3", "2/3"]);
    // The frozen copy of the sweep file is what the tasks ran.
    assert_eq!(
        std::fs::read_to_string(out.join("slurm/sweep.toml")).unwrap(),
        SWEEP
    );
}

#[test]
fn a_bad_sweep_never_reaches_the_queue() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "bad.toml",
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = -1.0\ndt = 0.1\n",
    );
    let o = cli(
        tmp.path(),
        &[
            "slurm", "bad.toml", "--tasks", "2", "--out", "o", "--submit",
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("fixed.h"));
    assert!(!tmp.path().join("o").exists());
}

/// contract §1.2 on a cluster: a reference job computes the sweep's reference run once; the array
/// tasks depend on it (afterok) and read the stored solution instead of computing it again.
#[test]
fn a_reference_job_runs_before_the_array_and_every_task_reuses_it() {
    start_local_slurm();
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "b.toml",
        r#"
name = "slurm-ref"
scene = "bar2d"
reference = { h = 0.0125, dt = 0.00625, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
h = 0.05
dt = 0.025
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
"#,
    );
    let out = tmp.path().join("out");
    let o = cli(
        tmp.path(),
        &[
            "slurm",
            "b.toml",
            "--tasks",
            "2",
            "--out",
            out.to_str().unwrap(),
            "--submit",
        ],
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("submitted reference job"), "{stdout}");
    let done = out.join("summary/convergence.parquet");
    let t0 = Instant::now();
    while !done.exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(240),
            "the summary job did not finish"
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    assert_complete(&out, 4);
    let runs = read_runs(&out).unwrap();
    let errs = runs.column("err_u_linfl2").unwrap();
    assert_eq!(
        errs.null_count(),
        0,
        "every run measured against the reference"
    );
    let refs: Vec<_> = std::fs::read_dir(out.join("references"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "ref").then_some(p)
        })
        .collect();
    assert_eq!(refs.len(), 1);
    // The array tasks found the reference stored; only the reference job computed it.
    let logs: Vec<String> = std::fs::read_dir(out.join("slurm"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "log"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    let computing = logs.iter().filter(|l| l.contains("computing")).count();
    let reused = logs.iter().filter(|l| l.contains("stored, reused")).count();
    assert_eq!((computing, reused), (1, 2), "{logs:#?}");
}

/// 72 runs of 0.1–0.5 s (a task ≈ 5 s): long enough for a task to be cancelled in the middle.
const SCALE: &str = r#"
name = "slurm-scale"
scene = "bar1d"
series_every = 100
[fixed]
T = 12.0
courant = 1.0
[grid]
h = [0.001, 0.0005]
method = [
  { space = "mixed", mass = "mod3", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hybrid" },
  { space = "mixed", mass = "zero-contact", scheme = "backward-euler" },
]
amplitude = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2]
"#;

fn squeue(args: &[&str]) -> String {
    String::from_utf8_lossy(&Command::new("squeue").args(args).output().unwrap().stdout)
        .trim()
        .to_string()
}

/// Rows sorted by run_id without the columns that time the run.
fn rows_without_timing(dir: &Path) -> polars::prelude::DataFrame {
    use polars::prelude::SortMultipleOptions;
    let df = read_runs(dir).unwrap();
    let keep: Vec<String> = df
        .get_column_names()
        .into_iter()
        .map(|s| s.to_string())
        .filter(|c| !c.starts_with("wall_time") && !c.ends_with("time_s"))
        .collect();
    df.select(keep)
        .unwrap()
        .sort(["run_id"], SortMultipleOptions::default())
        .unwrap()
}

/// Cluster scale on the local Slurm: a 4-task array, split into two arrays by a MaxArraySize
/// of 3 and throttled to 2 tasks at once, gives the single-machine rows; one task cancelled
/// mid-run (scancel) leaves its shard incomplete, `status` names it and prints the
/// resubmission, which completes the folder with no duplicate.
#[test]
fn a_cancelled_task_is_completed_by_the_resubmission_status_prints() {
    start_local_slurm();
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "s.toml", SCALE);

    let single = tmp.path().join("single");
    let o = cli(
        tmp.path(),
        &[
            "run",
            "s.toml",
            "--out",
            single.to_str().unwrap(),
            "--no-summary",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let out = tmp.path().join("arr");
    let o = cli(
        tmp.path(),
        &[
            "slurm",
            "s.toml",
            "--tasks",
            "4",
            "--max-parallel",
            "2",
            "--max-array-size",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--submit",
        ],
    );
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{stdout}\n{stderr}");
    assert!(stderr.contains("2 array(s) of at most 3"), "{stderr}");
    // "submitted array job A, B and summary job S (afterok:A:B)"
    let ids: Vec<String> = stdout
        .split("submitted array job ")
        .nth(1)
        .and_then(|s| s.split(" and summary").next())
        .unwrap()
        .split(", ")
        .map(String::from)
        .collect();
    assert_eq!(ids.len(), 2, "{stdout}");
    let array_spec = std::fs::read_to_string(out.join("slurm/tasks-0.txt")).unwrap();
    assert_eq!(array_spec, "0/4\n1/4\n2/4\n3/4\n");

    // Task 1 of the first array (shard 1/4): cancel it two seconds into its run.
    let victim = format!("{}_1", ids[0]);
    let t0 = Instant::now();
    while squeue(&["-h", "-t", "all", "-j", &victim, "-o", "%T"]) != "RUNNING" {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "{victim} never ran"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    std::thread::sleep(Duration::from_secs(2));
    let c = Command::new("scancel").arg(&victim).output().unwrap();
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    // Wait for both arrays to leave the queue (the summary is cancelled: a task failed).
    let both = ids.join(",");
    let t0 = Instant::now();
    while !squeue(&["-h", "-j", &both, "-o", "%i"]).is_empty() {
        assert!(
            t0.elapsed() < Duration::from_secs(300),
            "arrays still queued"
        );
        std::thread::sleep(Duration::from_millis(500));
    }

    let o = cli(tmp.path(), &["status", out.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{text}");
    let st = contact_sweep::exec::status::status(&out, None).unwrap();
    assert_eq!(st.shards, 4, "{text}");
    assert_eq!(
        st.missing_shards(),
        [1],
        "only the cancelled shard misses runs:\n{text}"
    );
    assert!(st.missing > 0 && st.duplicate_rows == 0, "{text}");
    // The printed resubmission, run as printed.
    let line = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Slurm: "))
        .unwrap_or_else(|| panic!("no Slurm command in\n{text}"));
    let cmd = line.split("   (").next().unwrap();
    assert!(cmd.contains("--only-shards 1/4 --submit"), "{cmd}");
    let args: Vec<&str> = cmd.split_whitespace().skip(1).collect();
    let o = cli(tmp.path(), &args);
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let done = out.join("summary/convergence.parquet");
    let t0 = Instant::now();
    while !done.exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(300),
            "the resubmission's summary did not finish; squeue:\n{}",
            squeue(&["-t", "all"])
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    assert_complete(&out, 72);
    // The array's rows are the single machine's, bit for bit (timings aside).
    let (a, b) = (rows_without_timing(&out), rows_without_timing(&single));
    assert_eq!(a.height(), 72);
    let differ: Vec<String> = b
        .get_column_names()
        .iter()
        .filter(|c| {
            !a.column(c.as_str()).is_ok_and(|x| {
                x.as_materialized_series()
                    .equals_missing(b.column(c.as_str()).unwrap().as_materialized_series())
            })
        })
        .map(|c| c.to_string())
        .collect();
    assert!(
        differ.is_empty(),
        "array and single-machine rows differ in {differ:?}"
    );
    let st = contact_sweep::exec::status::status(&out, None).unwrap();
    assert_eq!((st.missing, st.duplicate_rows), (0, 0));
    // Shard 1 ran twice: the cancelled session and the resubmitted one.
    let shard1 = st
        .sessions
        .iter()
        .filter(|s| s.shard.as_deref() == Some("1/4"))
        .count();
    assert_eq!(shard1, 2);
}
