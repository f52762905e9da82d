//! Plans and runs are sized before anything is allocated: a plan above `--max-runs` is refused
//! from the counts of the file (not after expanding it), a run whose estimated memory exceeds
//! `--max-run-memory` is refused at plan time naming the key that makes it big, and the run
//! timeout covers the setup.

mod common;

use std::time::{Duration, Instant};

use common::{cli, write};
use contact_sweep::run::RunOptions;
use contact_sweep::run::{RunConfig, Status, simulate};
use contact_sweep::sweep::{SweepFile, expand};

fn list(n: usize, f: impl Fn(usize) -> String) -> String {
    (0..n).map(f).collect::<Vec<_>>().join(", ")
}

#[test]
fn a_billion_combinations_are_refused_at_once_naming_the_axes_and_the_count() {
    let tmp = tempfile::tempdir().unwrap();
    let text = format!(
        "name = \"huge\"\nscene = \"bar1d\"\n[fixed]\nh = 0.01\nspace = \"nitsche\"\n[grid]\ndt = [{}]\nT = [{}]\nnitsche_gamma0 = [{}]\n",
        list(1000, |i| format!("{}", 1e-3 * (i + 1) as f64)),
        list(1000, |i| format!("{}.0", i + 1)),
        list(1000, |i| format!("{}", 1e-6 * (i + 1) as f64)),
    );
    write(tmp.path(), "huge.toml", &text);
    for cmd in ["plan", "run"] {
        let t0 = Instant::now();
        let o = cli(
            tmp.path(),
            &[cmd, "huge.toml", "--out", "o"][..if cmd == "plan" { 2 } else { 4 }],
        );
        // Counting three axes is instantaneous; 2 s leaves room for a loaded machine and
        // the process start, and is far below what expanding 10⁹ combinations takes.
        assert!(
            t0.elapsed() < Duration::from_secs(2),
            "{cmd} took {:?}",
            t0.elapsed()
        );
        assert_eq!(o.status.code(), Some(2), "{cmd}");
        let err = String::from_utf8_lossy(&o.stderr);
        for needle in [
            "1000000000",
            "grid.dt (1000)",
            "grid.T (1000)",
            "grid.nitsche_gamma0 (1000)",
            "--max-runs",
        ] {
            assert!(err.contains(needle), "{cmd}: `{needle}` not in {err}");
        }
        assert!(!tmp.path().join("o").exists(), "nothing written");
    }
}

#[test]
fn max_runs_is_a_limit_the_user_can_lower_and_raise() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"s\"\nscene = \"bar1d\"\n[fixed]\ndt = 0.1\nT = 1.0\n[grid]\nh = [0.25, 0.125, 0.0625]\nmass = [\"consistent\", \"mod3\"]\n",
    );
    let o = cli(tmp.path(), &["plan", "s.toml", "--max-runs", "5"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("6 (6.0e0) combinations") && err.contains("grid.h (3) × grid.mass (2)"),
        "{err}"
    );
    let o = cli(tmp.path(), &["plan", "s.toml", "--max-runs", "6"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_run_that_cannot_fit_in_memory_is_refused_at_plan_time_naming_elements() {
    let tmp = tempfile::tempdir().unwrap();
    let text = "name = \"big\"\nscene = \"bar1d\"\n[fixed]\nelements = 100000000\ndt = 0.01\n";
    write(tmp.path(), "big.toml", text);
    // The estimate the message must state: 10⁸ elements × 288 B (module header of
    // run::estimate) = 26.8 GiB, above half of this machine's available memory (and of any
    // machine with less than 53 GiB available).
    let plan = expand(&SweepFile::parse("big.toml".as_ref(), text).unwrap()).unwrap();
    let est = plan.runs[0].config.estimate(1);
    assert!(
        (est.state_bytes / 2f64.powi(30) - 26.82).abs() < 0.01,
        "{est:?}"
    );
    let t0 = Instant::now();
    let o = cli(
        tmp.path(),
        &["run", "big.toml", "--run-timeout", "5", "--out", "o"],
    );
    assert!(t0.elapsed() < Duration::from_secs(2), "{:?}", t0.elapsed());
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    for needle in [
        "fixed.elements",
        "26.8 GiB",
        "--max-run-memory",
        "lower `elements`",
    ] {
        assert!(err.contains(needle), "`{needle}` not in {err}");
    }
    assert!(!tmp.path().join("o").exists(), "nothing written");
    // An explicit budget refuses smaller runs too, naming h when h was given.
    write(
        tmp.path(),
        "mid.toml",
        "name = \"mid\"\nscene = \"bar1d\"\nseries_every = 0\n[fixed]\nh = 1e-6\ndt = 0.01\n",
    );
    let o = cli(
        tmp.path(),
        &["plan", "mid.toml", "--max-run-memory", "100M"],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("fixed.h") && err.contains("274.7 MiB"),
        "{err}"
    );
    let o = cli(tmp.path(), &["plan", "mid.toml", "--max-run-memory", "1G"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn kept_series_count_against_the_budget_and_name_series_every() {
    let tmp = tempfile::tempdir().unwrap();
    // 10⁸ steps kept whole: about 10⁸ × (size of a series row + its id) bytes, the elements
    // themselves negligible.
    write(
        tmp.path(),
        "long.toml",
        "name = \"long\"\nscene = \"bar1d\"\n[fixed]\nh = 0.25\ndt = 1e-7\nT = 10.0\n",
    );
    let o = cli(tmp.path(), &["plan", "long.toml", "--max-run-memory", "1G"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("key `series_every`") && err.contains("100000000 steps"),
        "{err}"
    );
    // Keeping every 1000th step fits.
    let o = cli(
        tmp.path(),
        &[
            "run",
            "long.toml",
            "--max-run-memory",
            "1G",
            "--series-every",
            "1000",
            "--run-timeout",
            "0.5",
            "--out",
            "o",
            "--no-summary",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn the_run_timeout_covers_the_setup() {
    // A bar1d run of 10⁶ elements spends about 0.2 s building its operators (measured 0.9 s
    // for 10 steps on this machine class); a budget of 1 ms is over at the first setup
    // checkpoint, before the first step.
    let text = "name = \"s\"\nscene = \"bar1d\"\n[fixed]\nelements = 1000000\ndt = 0.01\n";
    let plan = expand(&SweepFile::parse("s.toml".as_ref(), text).unwrap()).unwrap();
    let RunConfig::Bar1d(_) = &plan.runs[0].config else {
        panic!("a bar1d run")
    };
    let t0 = Instant::now();
    let out = simulate(
        &plan.runs[0].config,
        &RunOptions {
            series_every: 0,
            timeout: Some(Duration::from_millis(1)),
            cancel: None,
        },
    );
    assert_eq!(out.status, Status::Timeout);
    let msg = out.message.unwrap();
    assert!(msg.contains("during setup"), "{msg}");
    assert_eq!(out.metrics.steps, 0);
    // Stopped after the operators: well before the 1200 steps (≈ 100 s at this size).
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
}

#[test]
fn an_interruption_stops_a_run_in_its_setup() {
    // The scheduler's SIGTERM raises the cancel flag; a run still building its operators stops
    // at the next setup checkpoint (before its first step) and is dropped, not written.
    static CANCEL: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(true);
    for text in [
        "name = \"s\"\nscene = \"bar1d\"\n[fixed]\nelements = 1000000\ndt = 0.01\n",
        "name = \"s\"\nscene = \"bar2d\"\n[fixed]\nh = 0.025\ndt = 0.0125\n",
    ] {
        let plan = expand(&SweepFile::parse("s.toml".as_ref(), text).unwrap()).unwrap();
        let out = simulate(
            &plan.runs[0].config,
            &RunOptions {
                series_every: 1,
                timeout: None,
                cancel: Some(&CANCEL),
            },
        );
        assert_eq!(out.status, Status::Cancelled, "{text}");
        assert_eq!(out.metrics.steps, 0);
        assert!(out.series.is_empty());
    }
}
