//! Damaged output folders: a part truncated by hand is moved aside with a warning naming it and
//! its runs are computed again (each run present exactly once); `summarize` skips it with the
//! same warning; a missing or corrupt manifest is rebuilt from the sweep file. And `status DIR`:
//! what is done, failed and missing, per shard, and the command that completes it.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_complete, cli, write};
use contact_sweep::sink::parquet_parts;

/// 24 runs of a few ms: 3 meshes × 2 methods × 4 amplitudes.
const SWEEP: &str = r#"
name = "rec"
scene = "bar1d"
series_every = 10
[fixed]
T = 3.0
courant = 1.0
[grid]
h = [0.0625, 0.03125, 0.015625]
method = [
  { space = "mixed", mass = "mod3", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hybrid" },
]
amplitude = [0.25, 0.5, 0.75, 1.0]
"#;

fn run(cwd: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "run",
        "s.toml",
        "--out",
        "o",
        "--no-summary",
        "--threads",
        "1",
    ];
    args.extend_from_slice(extra);
    cli(cwd, &args)
}

/// Cut a file to half its length (as a full disk or a careless copy would).
fn truncate_half(p: &Path) {
    let len = std::fs::metadata(p).unwrap().len();
    let f = std::fs::OpenOptions::new().write(true).open(p).unwrap();
    f.set_len(len / 2).unwrap();
}

fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// runs/ and series/ hold nothing but committed `*.parquet` parts (no dot-file of any kind).
fn assert_only_parts(out: &Path) {
    for sub in ["runs", "series"] {
        for e in std::fs::read_dir(out.join(sub)).unwrap() {
            let name = e.unwrap().file_name().into_string().unwrap();
            assert!(
                !name.starts_with('.') && name.ends_with(".parquet"),
                "{sub}/{name} is not a committed part"
            );
        }
    }
}

fn folder_with_parts() -> (tempfile::TempDir, PathBuf, Vec<PathBuf>) {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "s.toml", SWEEP);
    // Batches of 4 runs: 6 runs parts, each with its series part.
    let o = run(tmp.path(), &["--batch", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = tmp.path().join("o");
    let parts = parquet_parts(&out.join("runs")).unwrap();
    assert_eq!(parts.len(), 6);
    (tmp, out, parts)
}

#[test]
fn a_truncated_runs_part_is_moved_aside_and_its_runs_computed_again() {
    let (tmp, out, parts) = folder_with_parts();
    let victim = &parts[2];
    let name = victim.file_name().unwrap().to_str().unwrap().to_string();
    truncate_half(victim);

    // summarize: skips the part with a warning naming it, and still writes the tables (of the
    // 20 readable runs).
    let o = cli(tmp.path(), &["summarize", "o"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains(&name) && err.contains("cannot be read"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains("20 runs"));
    assert!(out.join("summary/convergence.parquet").exists());

    // resume: the part goes aside with its series partner, its 4 runs are computed again.
    let o = run(tmp.path(), &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains(&name) && err.contains("moved aside"),
        "{err}"
    );
    assert!(err.contains("20 of 24 runs already done"), "{err}");
    // Out of the parts' folders: every reader's glob of runs/ and series/ sees complete parts
    // only (current polars expands `*.parquet` to dot-files too).
    assert!(out.join("damaged/runs").join(&name).exists());
    assert!(out.join("damaged/series").join(&name).exists());
    assert_only_parts(&out);
    assert_complete(&out, 24);

    // A second resume finds nothing damaged and nothing to do.
    let o = run(tmp.path(), &[]);
    let err = stderr(&o);
    assert!(o.status.success() && !err.contains("warning"), "{err}");
    assert!(err.contains("24 of 24 runs already done"), "{err}");
}

#[test]
fn a_truncated_series_part_takes_its_batch_with_it() {
    let (tmp, out, parts) = folder_with_parts();
    let name = parts[4].file_name().unwrap().to_owned();
    truncate_half(&out.join("series").join(&name));
    let o = run(tmp.path(), &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("20 of 24 runs already done"), "{err}");
    assert_complete(&out, 24);
}

#[test]
fn a_corrupt_or_missing_manifest_is_rebuilt_with_a_warning() {
    let (tmp, out, _) = folder_with_parts();
    std::fs::write(out.join("manifest.json"), "{\"sweep\": \"rec\", \"sess").unwrap();
    let o = run(tmp.path(), &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("manifest.json is damaged") && err.contains("rebuilt from s.toml"),
        "{err}"
    );
    assert!(out.join("damaged/manifest.json").exists());
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["sweep"], "rec");
    assert_eq!(m["sessions"][0]["sweep_text"], SWEEP);

    std::fs::remove_file(out.join("manifest.json")).unwrap();
    let o = run(tmp.path(), &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("has no manifest.json: rebuilt from s.toml"),
        "{err}"
    );
    assert!(out.join("manifest.json").exists());
    assert_complete(&out, 24);

    // summarize with a corrupt manifest: a warning, the default columns, the tables.
    std::fs::write(out.join("manifest.json"), "not json").unwrap();
    let o = cli(tmp.path(), &["summarize", "o"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("warning:") && err.contains("manifest"),
        "{err}"
    );
}

#[test]
fn status_counts_done_failed_and_missing_per_shard_and_prints_what_completes_it() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "s.toml", SWEEP);
    // Shards 0 and 2 of 3 ran; shard 1 never did. A run timeout of 1 µs in shard 2 makes
    // its runs `timeout` rows: done (a result), and counted as failed.
    assert!(run(tmp.path(), &["--shard", "0/3"]).status.success());
    assert!(
        run(tmp.path(), &["--shard", "2/3", "--run-timeout", "0.000001"])
            .status
            .success()
    );
    let o = cli(tmp.path(), &["status", "o"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "{}", stderr(&o));
    // The shards as `run --shard k/3` cuts them (balanced by work: 5, 8 and 11 runs here).
    let st = contact_sweep::exec::status::status(&tmp.path().join("o"), None).unwrap();
    assert_eq!(st.shards, 3);
    assert_eq!(st.planned, 24);
    let counts: Vec<(usize, usize, usize, usize)> = st
        .per_shard
        .iter()
        .map(|c| (c.planned, c.done, c.failed, c.missing))
        .collect();
    assert_eq!(counts, [(5, 5, 0, 0), (8, 0, 0, 8), (11, 11, 11, 0)]);
    assert_eq!(st.by_status.get("ok"), Some(&5));
    assert_eq!(st.by_status.get("timeout"), Some(&11));
    assert_eq!(st.missing_shards(), [1]);
    assert_eq!(st.sessions.len(), 2);
    for needle in [
        "done 16 (ok 5, timeout 11), failed 11, missing 8",
        "1/3       8     0       0        8",
        "damaged files: none",
        "sessions: 2 (2 finished",
        "contact-sweep run s.toml --out o",
        "contact-sweep slurm s.toml --out o --only-shards 1/3 --submit",
    ] {
        assert!(text.contains(needle), "`{needle}` not in\n{text}");
    }
    // A damaged part shows, and the local command completes exactly what is missing.
    let parts = parquet_parts(&tmp.path().join("o/runs")).unwrap();
    truncate_half(&parts[0]);
    let o = cli(tmp.path(), &["status", "o"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let name = parts[0].file_name().unwrap().to_str().unwrap();
    assert!(
        text.contains(name) && text.contains("cannot be read"),
        "{text}"
    );
    let o = cli(tmp.path(), &["run", "s.toml", "--out", "o", "--no-summary"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Every run once (the timeout rows have no series: assert_complete does not apply).
    let runs = contact_sweep::sink::read_runs(&tmp.path().join("o")).unwrap();
    let ids = runs.column("run_id").unwrap().str().unwrap().clone();
    let distinct: std::collections::HashSet<_> = ids.iter().flatten().collect();
    assert_eq!((runs.height(), distinct.len()), (24, 24));
    let o = cli(tmp.path(), &["status", "o"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        text.contains("missing 0") && text.contains("complete: nothing to resubmit"),
        "{text}"
    );
    assert!(
        text.contains("(moved aside; its runs count as missing)"),
        "{text}"
    );
    // Without a manifest and without --sweep, status says what it needs (exit 2).
    std::fs::remove_file(tmp.path().join("o/manifest.json")).unwrap();
    let o = cli(tmp.path(), &["status", "o"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--sweep FILE"), "{}", stderr(&o));
    let o = cli(tmp.path(), &["status", "o", "--sweep", "s.toml"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Regression (issue 23): current polars expands `runs/*.parquet` to dot-files, so the
/// temporaries (`runs/.tmp-NAME`) and damaged parts (`runs/.damaged-NAME`) that older versions
/// kept beside the parts broke every polars read of the folder. A folder of that layout is
/// mended by the next `run`: temporaries removed, damaged parts moved to `damaged/` — and its
/// runs stay done, each once.
#[test]
fn regression_dot_files_beside_the_parts_leave_on_the_next_run() {
    let (tmp, out, parts) = folder_with_parts();
    let name = parts[1].file_name().unwrap().to_str().unwrap().to_string();
    // The old layout: a damaged pair moved aside as dot-files, and a temporary of a killed write.
    for sub in ["runs", "series"] {
        std::fs::rename(
            out.join(sub).join(&name),
            out.join(sub).join(format!(".damaged-{name}")),
        )
        .unwrap();
    }
    std::fs::write(out.join("runs/.tmp-part-x.parquet"), b"partial").unwrap();
    let o = run(tmp.path(), &[]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("20 of 24 runs already done"), "{err}");
    assert_only_parts(&out);
    assert!(out.join("damaged/runs").join(&name).exists());
    assert!(out.join("damaged/series").join(&name).exists());
    assert_complete(&out, 24);
    // status lists the moved pair among the files moved aside.
    let o = cli(tmp.path(), &["status", "o"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(text.contains(&format!("damaged/runs/{name}")), "{text}");
}
