//! A sweep through a real scheduler: `contact-sweep slurm --submit` on the one-node Slurm that
//! `../shared/slurm/start-local-slurm.sh` brings up (installing slurm-wlm and munge if needed;
//! needs root, as in CI). Three array tasks write shards into one folder; the dependent summary
//! job summarizes them.

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

#[test]
fn a_job_array_runs_the_sweep_in_shards_and_summarizes_it() {
    let start = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/slurm/start-local-slurm.sh");
    assert!(
        start.exists(),
        "{} not found (shared/ beside the checkout)",
        start.display()
    );
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

/// SPEC §1.2 on a cluster: a reference job computes the sweep's reference run once; the array
/// tasks depend on it (afterok) and read the stored solution instead of computing it again.
#[test]
fn a_reference_job_runs_before_the_array_and_every_task_reuses_it() {
    let start = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/slurm/start-local-slurm.sh");
    let up = Command::new("bash")
        .arg(&start)
        .env("SLURM_LOCAL_MIN_JOB_AGE", "600")
        .output()
        .expect("bash runs");
    assert!(up.status.success(), "local Slurm did not start");
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
