//! End to end: the binary on sweep files, the Parquet it writes, determinism across thread
//! counts, crash safety (SIGKILL mid-sweep and while workers encode, then resume), timeouts,
//! foreign output folders.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{assert_complete, bin, cli, write};
use contact_sweep::sink::{committed_run_ids, parquet_parts, part_problem, read_runs, read_series};
use polars::prelude::*;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn quickstart_runs_and_prints_errors_against_the_exact_solution() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("qs");
    let o = cli(
        repo(),
        &[
            "run",
            "sweeps/quickstart.toml",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("l2(τ;L2)") && stdout.contains("l2(τ;H1)"),
        "{stdout}"
    );
    // The terminal output fits one screen: 60 runs > 30, so one line per method group with its
    // rates, a legend line for every abbreviated column, and what to look at.
    let all = format!("{}{stdout}", String::from_utf8_lossy(&o.stderr));
    let lines = all.lines().count();
    assert!(lines <= 50, "{lines} lines:\n{all}");
    let groups = [
        "mixed · consistent · crank-nicolson",
        "mixed · mod3 · crank-nicolson",
        "mixed · mod3 · hybrid",
        "mixed · zero-contact · crank-nicolson",
        "nitsche(Θ=1, γ0=1e-6) · consistent · crank-nicolson",
        "nitsche(Θ=1, γ0=1e-6) · consistent · hybrid",
    ];
    for (k, g) in groups.iter().enumerate() {
        // the group's line: its number, title and path, then its rates
        let line = stdout
            .lines()
            .find(|l| {
                l.trim_start()
                    .strip_prefix(&(k + 1).to_string())
                    .is_some_and(|rest| rest.trim_start().starts_with(&format!("{g} ")))
            })
            .unwrap_or_else(|| panic!("no line for group {g}:\n{stdout}"));
        assert!(line.contains("ν=0.5, h↓") && line.contains("5/5"), "{line}");
    }
    for legend in [
        "l2(τ;L2): displacement error in l2(0,T;L2)",
        "l2(τ;H1): displacement error in l2(0,T;H1)",
        "σ½ l2(τ): contact pressure error at the midpoints",
        "E l2(τ): energy error",
        "E(T)/E⁰: final over initial discrete energy",
        "rate letters: p pre-asymptotic",
        "path: the value held fixed",
    ] {
        assert!(stdout.contains(legend), "no legend `{legend}`:\n{stdout}");
    }
    assert!(stdout.contains("look at:"), "{stdout}");
    // zero-contact + CN converges fastest in l2(τ;H1) (docs/methods.md: rate ≈ 0.4 at ν = 0.5)
    assert!(
        stdout.contains("highest l2(τ;H1) rate: 0.42 (group 4"),
        "{stdout}"
    );
    // One engineering format: no `e0` exponents, no five-digit mantissas.
    assert!(
        !stdout.contains("e0 ") && !stdout.contains("1.0025"),
        "{stdout}"
    );
    let df = read_runs(&out).unwrap();
    assert!(df.height() >= 50, "quickstart has {} runs", df.height());
    // Every run has its errors against the closed form, and its derived columns filled.
    for c in [
        "err_u_l2l2",
        "err_u_l2h1",
        "err_sigma_l2",
        "h",
        "dt",
        "courant",
        "T",
    ] {
        assert_eq!(df.column(c).unwrap().null_count(), 0, "{c} has nulls");
    }
    let status = df.column("status").unwrap().str().unwrap().clone();
    assert!(status.iter().all(|s| s == Some("ok")));
    let series = read_series(&out).unwrap();
    assert!(series.height() > 1000);
    assert!(out.join("manifest.json").exists());
}

/// Rows sorted by run_id, without the timing columns (wall_time_*, setup/stepping/observe
/// `*_time_s`).
fn rows_without_timing(dir: &Path, series: bool) -> DataFrame {
    let df = if series {
        read_series(dir)
    } else {
        read_runs(dir)
    }
    .unwrap();
    let keep: Vec<String> = df
        .get_column_names()
        .into_iter()
        .map(|s| s.to_string())
        .filter(|c| !c.starts_with("wall_time") && !c.ends_with("_time_s"))
        .collect();
    let by: Vec<&str> = if series {
        vec!["run_id", "step"]
    } else {
        vec!["run_id"]
    };
    df.select(keep)
        .unwrap()
        .sort(by, SortMultipleOptions::default())
        .unwrap()
}

#[test]
fn one_and_two_threads_give_identical_rows() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = repo().join("sweeps/quickstart.toml");
    let (a, b) = (tmp.path().join("t1"), tmp.path().join("t2"));
    for (dir, threads) in [(&a, "1"), (&b, "2")] {
        let o = cli(
            tmp.path(),
            &[
                "run",
                sweep.to_str().unwrap(),
                "--out",
                dir.to_str().unwrap(),
                "--threads",
                threads,
                "--no-summary",
            ],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for series in [false, true] {
        let (x, y) = (
            rows_without_timing(&a, series),
            rows_without_timing(&b, series),
        );
        assert_eq!(x.height(), y.height());
        assert!(
            x.equals_missing(&y),
            "serial and parallel rows differ (series = {series})"
        );
    }
}

/// A sweep long enough to be killed in the middle: 240 runs of a few tens of ms.
const LONG: &str = r#"
name = "long"
scene = "bar1d"
series_every = 50
[fixed]
T = 12.0
courant = 1.0
[grid]
h = [0.005, 0.0025, 0.004, 0.002]
method = [
  { space = "mixed", mass = "mod3", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hybrid" },
  { space = "mixed", mass = "zero-contact", scheme = "backward-euler" },
]
amplitude = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 1.9, 2.0]
"#;

/// Start `contact-sweep run` on the LONG sweep in the background (stderr piped).
fn spawn_long(sweep: &Path, out: &Path, extra: &[&str]) -> std::process::Child {
    Command::new(bin())
        .args([
            "run",
            sweep.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--no-summary",
        ])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn sigkill_mid_sweep_then_resume_loses_nothing_and_duplicates_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = write(tmp.path(), "long.toml", LONG);
    let out = tmp.path().join("out");
    let mut child = spawn_long(&sweep, &out, &["--threads", "2", "--batch", "1"]);
    // Wait until a few batches are committed, then kill without warning.
    let start = Instant::now();
    loop {
        let parts = parquet_parts(&out.join("runs"))
            .map(|p| p.len())
            .unwrap_or(0);
        if parts >= 5 {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        child.try_wait().unwrap().is_none(),
        "the sweep finished before it could be killed"
    );
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    // Whatever is on disk is readable.
    let partial = read_runs(&out).unwrap();
    assert!(
        partial.height() >= 5 && partial.height() < 240,
        "{} rows",
        partial.height()
    );
    // Resume (automatic: same sweep) completes the sweep.
    let o = cli(
        tmp.path(),
        &["run", "long.toml", "--out", "out", "--no-summary"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("resuming"), "{err}");
    // Every run once, every (run, step) of the series once, no orphan series.
    assert_complete(&out, 240);
    // A third invocation has nothing left to do.
    let o = cli(
        tmp.path(),
        &["run", "long.toml", "--out", "out", "--no-summary"],
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("240 of 240 runs already done"));
    assert_eq!(read_runs(&out).unwrap().height(), 240);
}

/// Batches of `.tmp/` (encoded or being encoded, not yet committed): their names, without the
/// `.series`/`.runs` suffix of each file.
fn batches_in_flight(out: &Path) -> std::collections::HashSet<String> {
    std::fs::read_dir(out.join(".tmp"))
        .map(|entries| {
            entries
                .flatten()
                .filter_map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    name.rsplit_once('.').map(|(batch, _)| batch.to_string())
                })
                .collect()
        })
        .unwrap_or_default()
}

/// Issue 35: each worker encodes its batch into `.tmp/`, one thread commits. A SIGKILL while
/// several batches are in `.tmp/` (workers encoding, or waiting for the committer) leaves only
/// complete parts in `runs/` and `series/`; the resume keeps every committed run, computes
/// exactly the others again (its "already done" count is the committed rows at the kill), and
/// no row is there twice.
#[test]
fn sigkill_while_workers_encode_loses_only_runs_in_flight() {
    let tmp = tempfile::tempdir().unwrap();
    // Every step stored, so that encoding a batch takes a while; 4 workers on batches of 2.
    let sweep = write(
        tmp.path(),
        "long.toml",
        &LONG.replace("series_every = 50", "series_every = 1"),
    );
    let out = tmp.path().join("out");
    let mut child = spawn_long(&sweep, &out, &["--threads", "4", "--batch", "2"]);
    let start = Instant::now();
    loop {
        let committed = parquet_parts(&out.join("runs"))
            .map(|p| p.len())
            .unwrap_or(0);
        if committed >= 3 && batches_in_flight(&out).len() >= 2 {
            break;
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "the sweep finished before two batches were seen in flight"
        );
        assert!(start.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(1));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    // Only complete parts are visible: every one reads (runs whole, series by their footer).
    let runs_parts = parquet_parts(&out.join("runs")).unwrap();
    for (sub, whole) in [("runs", true), ("series", false)] {
        for part in parquet_parts(&out.join(sub)).unwrap() {
            assert_eq!(part_problem(&part, whole), None, "{}", part.display());
        }
    }
    let committed = committed_run_ids(&out.join("runs")).unwrap();
    assert_eq!(
        read_runs(&out).unwrap().height(),
        committed.len(),
        "a run committed twice before the kill"
    );
    assert!(committed.len() < 240);
    // The resume recomputes the uncommitted runs, and only them.
    let o = cli(
        tmp.path(),
        &["run", "long.toml", "--out", "out", "--no-summary"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(&format!("{} of 240 runs already done", committed.len())),
        "{err}"
    );
    // The parts committed before the kill are still there, untouched; every run once.
    let after = parquet_parts(&out.join("runs")).unwrap();
    assert!(runs_parts.iter().all(|p| after.contains(p)));
    let ids = assert_complete(&out, 240);
    assert!(committed.is_subset(&ids));
    assert_eq!(
        batches_in_flight(&out).len(),
        0,
        "temporaries left in .tmp/"
    );
}

#[test]
fn timeouts_and_failures_are_rows_not_aborts() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"t\"\nscene = \"bar1d\"\n[fixed]\ncourant = 1.0\nspace = \"nitsche\"\n[grid]\nnitsche_gamma0 = [1e-6, 3.0]\nh = [0.25, 0.0002]\n",
    );
    let o = cli(
        tmp.path(),
        &[
            "run",
            "s.toml",
            "--out",
            "o",
            "--run-timeout",
            "0.05",
            "--no-summary",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let df = read_runs(&tmp.path().join("o")).unwrap();
    let status: Vec<String> = df
        .column("status")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .flatten()
        .map(String::from)
        .collect();
    assert_eq!(df.height(), 4);
    // h = 2e-4 at ν = 1: 60 000 steps of 5 000 nodes, far beyond 50 ms.
    assert!(status.iter().any(|s| s == "timeout"), "{status:?}");
    // γ0 = 3 with Θ = 1 at ν = 1 violates the well-posedness condition of 003 §2.2.3 at the
    // first step: the condensed contact equation has two solutions, reported, not guessed.
    assert_eq!(
        status.iter().filter(|s| *s == "solver-failed").count(),
        2,
        "{status:?}"
    );
    let msgs = df.column("message").unwrap().str().unwrap().clone();
    assert!(msgs.iter().flatten().any(|m| m.contains("timeout")));
    assert!(msgs.iter().flatten().any(|m| m.contains("well-posedness")));
}

#[test]
fn a_folder_of_another_sweep_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "a.toml",
        "name = \"a\"\nscene = \"bar1d\"\n[fixed]\nh = 0.5\ndt = 0.5\nT = 1.0\n",
    );
    write(
        tmp.path(),
        "b.toml",
        "name = \"b\"\nscene = \"bar1d\"\n[fixed]\nh = 0.25\ndt = 0.5\nT = 1.0\n",
    );
    assert!(
        cli(tmp.path(), &["run", "a.toml", "--out", "d", "--no-summary"])
            .status
            .success()
    );
    let o = cli(tmp.path(), &["run", "b.toml", "--out", "d", "--no-summary"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("holds results of sweep `a`"));
    assert_eq!(
        read_runs(&tmp.path().join("d")).unwrap().height(),
        1,
        "nothing of b written"
    );
    // With --resume the runs of b are added.
    assert!(
        cli(
            tmp.path(),
            &["run", "b.toml", "--out", "d", "--resume", "--no-summary"]
        )
        .status
        .success()
    );
    assert_eq!(read_runs(&tmp.path().join("d")).unwrap().height(), 2);
}

#[test]
fn concurrent_shards_share_one_folder_without_losing_or_duplicating_rows() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = write(tmp.path(), "long.toml", LONG);
    let out = tmp.path().join("out");
    // Three shards started together, as a job array would; batches of one run so that the
    // shards' commits interleave.
    let children: Vec<_> = (0..3)
        .map(|k| {
            spawn_long(
                &sweep,
                &out,
                &[
                    "--threads",
                    "1",
                    "--batch",
                    "1",
                    "--shard",
                    &format!("{k}/3"),
                ],
            )
        })
        .collect();
    for c in children {
        let o = c.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_complete(&out, 240);
    // One manifest entry per shard, each closed.
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    let sessions = manifest["sessions"].as_array().unwrap();
    assert_eq!(sessions.len(), 3);
    let mut shards: Vec<&str> = sessions
        .iter()
        .map(|s| s["shard"].as_str().unwrap())
        .collect();
    shards.sort();
    assert_eq!(shards, ["0/3", "1/3", "2/3"]);
    assert!(
        sessions
            .iter()
            .all(|s| s["finished"].is_string() && s["runs_written"] == 80)
    );
    // The summary of the whole folder, once all shards are done.
    let o = cli(tmp.path(), &["summarize", "out"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("summary/convergence.parquet").exists());
}

#[test]
fn bad_shard_specs_are_usage_errors() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"x\"\nscene = \"bar1d\"\n[fixed]\nh = 0.5\ndt = 0.5\nT = 1.0\n",
    );
    for bad in ["3/3", "1", "a/b", "0/0"] {
        let o = cli(tmp.path(), &["run", "s.toml", "--shard", bad]);
        assert_eq!(o.status.code(), Some(2), "--shard {bad}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("--shard must be K/N"));
    }
}

#[test]
fn sigterm_commits_every_finished_run_and_exits_130() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = write(tmp.path(), "long.toml", LONG);
    let out = tmp.path().join("out");
    // Large batches: without the handler, a signal would lose every uncommitted finished run.
    let child = spawn_long(&sweep, &out, &["--threads", "2", "--batch", "1000"]);
    // Let some runs finish (the first batch commits only after 2 s), then SIGTERM, as Slurm
    // does at a time limit.
    std::thread::sleep(Duration::from_millis(700));
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let t0 = Instant::now();
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(
        t0.elapsed() < Duration::from_secs(10),
        "the interrupt took {:?}",
        t0.elapsed()
    );
    assert!(err.contains("interrupted"), "{err}");
    let saved = read_runs(&out).map(|df| df.height()).unwrap_or(0);
    assert!(saved > 0 && saved < 240, "{saved} rows saved");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["sessions"][0]["interrupted"], true);
    assert_eq!(manifest["sessions"][0]["runs_written"], saved);
    // Resume completes the sweep, with every row once.
    let o = cli(
        tmp.path(),
        &["run", "long.toml", "--out", "out", "--no-summary"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_complete(&out, 240);
}

#[test]
fn plan_prints_counts_reasons_and_the_varying_parameters() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"p\"\nscene = \"bar1d\"\n[fixed]\nh = 0.1\ndt = 0.1\nT = 1.0\n[grid]\nspace = [\"mixed\", \"nitsche\"]\nnitsche_gamma0 = [1e-6, 0.1]\n",
    );
    let o = cli(tmp.path(), &["plan", "s.toml"]);
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("4 combinations → 3 runs"), "{out}");
    assert!(
        out.contains(
            "1 collapsed into identical runs: nitsche_gamma0 applies to space = nitsche only"
        ),
        "{out}"
    );
    // the varying parameters are columns; the work column totals 3 runs × 10 steps × 10 nodes
    assert!(
        out.contains("nitsche_gamma0") && out.contains("space"),
        "{out}"
    );
    assert!(
        out.lines().last().unwrap().trim_end().ends_with("3.00e2"),
        "{out}"
    );
    assert!(!tmp.path().join("out").exists(), "plan writes nothing");
}

#[test]
fn run_prints_the_columns_of_the_sweeps_summary_table() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"x\"\nscene = \"bar1d\"\nseries_every = 0\n[fixed]\nT = 1.0\ncourant = 1.0\n\
         [grid]\nelements = [4, 8, 16]\n[summary]\nerrors = [\"err_energy_l2\", \"err_u_l2h1\"]\nflags = false\n",
    );
    let o = cli(tmp.path(), &["run", "s.toml", "--out", "out"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(tmp.path().join("out/summary/convergence.md")).unwrap();
    assert!(
        md.contains("| level | h | dt | status | err_energy_l2 | rate | err_u_l2h1 | rate |\n"),
        "{md}"
    );
    assert!(md.contains("| LSQ slope, finest 3 |") && !md.contains("| flags |"));
    // `summarize` alone finds the same choice in the manifest; --errors overrides the columns.
    let o = cli(tmp.path(), &["summarize", "out"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let again = std::fs::read_to_string(tmp.path().join("out/summary/convergence.md")).unwrap();
    assert_eq!(again, md);
    let o = cli(tmp.path(), &["summarize", "out", "--errors", "err_u_l2l2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(tmp.path().join("out/summary/convergence.md")).unwrap();
    assert!(
        md.contains("| level | h | dt | status | err_u_l2l2 | rate |\n")
            && !md.contains("| flags |"),
        "{md}"
    );
}

#[test]
fn table_flag_chooses_runs_or_groups() {
    let tmp = tempfile::tempdir().unwrap();
    write(
        tmp.path(),
        "s.toml",
        "name = \"t\"\nscene = \"bar1d\"\n[fixed]\nT = 1.0\ncourant = 1.0\n[grid]\nh = [0.25, 0.125, 0.0625]\nmass = [\"consistent\", \"mod3\"]\n",
    );
    // 6 runs ≤ 30: every run by default, with the legend of its columns.
    let o = cli(tmp.path(), &["run", "s.toml", "--out", "a"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let run_lines = out.lines().filter(|l| l.contains("  ok  ")).count();
    assert_eq!(run_lines, 6, "{out}");
    assert!(out.contains("σ½ l2(τ): contact pressure error"), "{out}");
    // --table groups: no per-run line, one line per group.
    let o = cli(
        tmp.path(),
        &["run", "s.toml", "--out", "b", "--table", "groups"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        out.lines().filter(|l| l.contains("  ok  ")).count(),
        0,
        "{out}"
    );
    assert!(
        out.contains("1  mixed · consistent · crank-nicolson"),
        "{out}"
    );
    assert!(out.contains("2  mixed · mod3 · crank-nicolson"), "{out}");
    // A bad mode is a usage error (clap: exit 2) naming the accepted values.
    let o = cli(tmp.path(), &["run", "s.toml", "--table", "all"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("runs"));
}

#[test]
fn every_subcommand_help_ends_with_examples() {
    for sub in [
        "plan",
        "run",
        "summarize",
        "schema",
        "slurm",
        "report",
        "status",
    ] {
        let o = cli(repo(), &[sub, "--help"]);
        assert!(o.status.success(), "{sub}");
        let help = String::from_utf8_lossy(&o.stdout);
        let tail = help.trim_end();
        let at = tail
            .rfind("Examples:")
            .unwrap_or_else(|| panic!("{sub}: {help}"));
        // the examples are the last block, each line a command
        assert!(
            tail[at..]
                .lines()
                .skip(1)
                .all(|l| l.trim_start().starts_with("contact-sweep ")),
            "{sub}: {help}"
        );
    }
}

/// Regression (`contact-sweep plan … | head` panicked on the broken pipe): a reader that goes
/// away ends `plan` quietly, and `run` still writes its summary and report after the runs (its
/// results are committed before anything is printed).
#[test]
fn a_reader_that_goes_away_neither_panics_nor_loses_the_summary() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("qs");
    for args in [
        vec!["plan", "sweeps/quickstart.toml"],
        vec![
            "run",
            "sweeps/quickstart.toml",
            "--out",
            out.to_str().unwrap(),
        ],
    ] {
        let mut child = Command::new(bin())
            .args(&args)
            .current_dir(repo())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The read end is closed before the child prints anything (its output would fit in the
        // pipe's buffer, so a reader that read one line first would never break the pipe).
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        if args[0] == "run" {
            assert!(o.status.success(), "{stderr}");
            assert!(out.join("summary/energy.parquet").exists());
            assert!(out.join("report.html").exists());
        }
    }
}
