//! The analysis contract (contract §8) with the readers users install today (issue 23): polars,
//! pandas, pyarrow and DuckDB, each at its newest release (`analysis/requirements.txt` has no
//! upper pins; this test installs it), read a results folder
//! (a) again and again while a sweep writes it — current polars expands `runs/*.parquet` to
//!     dot-files, so before issue 23 the sink's `.tmp-*.parquet` temporaries failed 2 reads in
//!     96 —,
//! (b) after a part was damaged and moved aside,
//! (c) after a sweep was killed and resumed,
//! (d) written by the engine before issue 23 (polars' encoder, `tests/data/legacy/old`) and
//!     resumed by this one: the old run ids are recognised as done, the old runs parts are
//!     given the columns added since, and every column reads with one type in polars and
//!     pandas across old and new parts,
//!
//! with 0 errors and every committed run present exactly once. The README's and docs/guide.md's analysis snippets
//! runs exactly as printed, on the quickstart's folder.
//!
//! The readers are driven by `analysis/readers_check.py` (one JSON line per call).

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Once;
use std::time::{Duration, Instant};

use common::{bin, cli};

/// Install the newest readers once per test binary.
fn readers() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let req = concat!(env!("CARGO_MANIFEST_DIR"), "/analysis/requirements.txt");
        let o = Command::new("python3")
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
            ])
            .args(["--upgrade", "-r", req])
            .output()
            .expect("python3 runs");
        assert!(
            o.status.success(),
            "pip install -r analysis/requirements.txt failed (run the tests with scripts/test.sh: \
             Debian's and Ubuntu's python3 refuse pip outside a virtual environment):\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    });
}

fn check_script() -> &'static str {
    concat!(env!("CARGO_MANIFEST_DIR"), "/analysis/readers_check.py")
}

/// `readers_check.py check DIR --runs N`: panics with the readers' findings unless clean.
fn check(dir: &Path, runs: usize, same_types: bool) -> serde_json::Value {
    readers();
    let mut cmd = Command::new("python3");
    cmd.arg(check_script()).arg("check").arg(dir);
    cmd.args(["--runs", &runs.to_string()]);
    if same_types {
        cmd.arg("--same-types");
    }
    let o = cmd.output().expect("python3 runs");
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{out}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_str(out.trim()).expect("one JSON line")
}

/// The 400-run 1D sweep of the overhead benchmark, three times longer (T = 36) with every
/// fourth step kept and batches of 4 runs: ≈ 10 s of writing, 100 commits, so readers meet
/// the folder in every state a sweep passes through.
fn sweep_args(out: &Path) -> Vec<String> {
    let sweep = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/sweeps/overhead_1d.toml"
    );
    [
        "run",
        sweep,
        "--out",
        out.to_str().unwrap(),
        "--set",
        "T=36.0",
        "--series-every",
        "4",
        "--batch",
        "4",
        "--no-summary",
        "--threads",
        "2",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

const RUNS: usize = 400;

fn committed_parts(dir: &Path) -> Vec<std::path::PathBuf> {
    contact_sweep::sink::parquet_parts(&dir.join("runs")).unwrap()
}

#[test]
fn every_reader_reads_the_folder_while_written_after_damage_and_after_a_resume() {
    readers();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let stop = tmp.path().join("stop");

    // (a) While the sweep writes.
    let watcher = Command::new("python3")
        .arg(check_script())
        .arg("watch")
        .arg(&out)
        .args(["--stop", stop.to_str().unwrap()])
        .args(["--runs", &RUNS.to_string()])
        .stdout(Stdio::piped())
        .spawn()
        .expect("python3 runs");
    let o = Command::new(bin()).args(sweep_args(&out)).output().unwrap();
    std::fs::write(&stop, b"").unwrap();
    let w = watcher.wait_with_output().unwrap();
    let report = String::from_utf8_lossy(&w.stdout).to_string();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        w.status.success(),
        "readers failed while the sweep wrote: {report}"
    );
    let r: serde_json::Value = serde_json::from_str(report.trim()).unwrap();
    eprintln!("readers while the sweep wrote: {report}");
    // At least one read in flight besides the final one (each round reads the whole folder
    // with five readers: a few a second at most).
    assert!(r["reads"].as_u64().unwrap() >= 2, "{report}");

    // (b) A runs part damaged by hand: moved aside by the next run, its runs computed again.
    let parts = committed_parts(&out);
    let victim = &parts[parts.len() / 2];
    let len = std::fs::metadata(victim).unwrap().len();
    std::fs::OpenOptions::new()
        .write(true)
        .open(victim)
        .unwrap()
        .set_len(len / 2)
        .unwrap();
    let o = Command::new(bin()).args(sweep_args(&out)).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success() && err.contains("moved aside"), "{err}");
    check(&out, RUNS, false);

    // (c) Killed in the middle of a sweep, then resumed.
    let killed = tmp.path().join("k");
    let mut child = Command::new(bin())
        .args(sweep_args(&killed))
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while committed_parts(&killed).len() < 10 && start.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let done = committed_parts(&killed).len();
    assert!(
        (10..RUNS / 4).contains(&done),
        "{done} parts before the kill"
    );
    let o = Command::new(bin())
        .args(sweep_args(&killed))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    check(&killed, RUNS, false);
}

/// (d) A folder written before issue 23 — polars' encoder, strings as views, lists as large
/// lists in its embedded schema — resumed by this engine with two more amplitudes.
#[test]
fn a_folder_written_before_reads_alike_and_resumes() {
    readers();
    let tmp = tempfile::tempdir().unwrap();
    let data = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/legacy"));
    let out = tmp.path().join("old");
    std::fs::create_dir_all(&out).unwrap();
    for sub in ["runs", "series"] {
        std::fs::create_dir_all(out.join(sub)).unwrap();
        for e in std::fs::read_dir(data.join("old").join(sub)).unwrap() {
            let p = e.unwrap().path();
            std::fs::copy(&p, out.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    std::fs::copy(data.join("old/manifest.json"), out.join("manifest.json")).unwrap();
    std::fs::copy(data.join("legacy.toml"), tmp.path().join("legacy.toml")).unwrap();
    // The old parts alone, as the old engine left them.
    check(&out, 4, true);
    let o = cli(
        tmp.path(),
        &["run", "legacy.toml", "--out", "old", "--threads", "1"],
    );
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(o.status.success(), "{err}");
    // Run ids unchanged: the 4 runs of the old folder are done.
    assert!(err.contains("4 of 8 runs already done"), "{err}");
    // The old parts lack the columns added since (rho_inf, pressure_oscillation, …): polars'
    // glob refused the mixed folder ("extra column in file outside of expected schema") until
    // the old runs parts were given the current columns.
    assert!(
        err.contains("2 runs part(s) written by an older version"),
        "{err}"
    );
    assert!(out.join("summary/convergence.parquet").exists());
    check(&out, 8, true);
}

/// Every ```python block of a Markdown text.
fn python_blocks(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(k) = rest.find("```python\n") {
        let body = &rest[k + "```python\n".len()..];
        let end = body.find("```").expect("a closed python block");
        out.push(body[..end].to_string());
        rest = &body[end..];
    }
    out
}

/// The analysis snippets as printed — the README's, and the guide's (the ```python block of
/// docs/guide.md "## Outputs") — run exactly as printed in a folder holding `out/quickstart`.
#[test]
fn the_readme_analysis_snippet_runs_as_printed() {
    readers();
    let root = env!("CARGO_MANIFEST_DIR");
    let readme = std::fs::read_to_string(format!("{root}/README.md")).unwrap();
    let guide = std::fs::read_to_string(format!("{root}/docs/guide.md")).unwrap();
    let outputs = &guide[guide.find("\n## Outputs").expect("an Outputs section")..];
    let guide_snippet = python_blocks(outputs)
        .into_iter()
        .next()
        .expect("a python snippet in the guide's Outputs");
    let readme_snippets = python_blocks(&readme);
    assert!(
        !readme_snippets.is_empty(),
        "the README shows how to read the output"
    );
    let tmp = tempfile::tempdir().unwrap();
    let sweep = concat!(env!("CARGO_MANIFEST_DIR"), "/sweeps/quickstart.toml");
    let o = cli(tmp.path(), &["run", sweep, "--no-summary"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Each snippet, then a line that proves it read what the folder holds (60 runs).
    let checks = std::iter::once((
        guide_snippet,
        "assert runs.height == 60 and len(runs_pd) == 60, (runs.height, len(runs_pd))",
    ))
    .chain(
        readme_snippets
            .into_iter()
            .map(|s| (s, "assert runs.height == 60, runs.height")),
    );
    for (snippet, check) in checks {
        assert!(
            snippet.contains("out/quickstart/runs/*.parquet"),
            "{snippet}"
        );
        let program = format!("{snippet}\n{check}\n");
        let o = Command::new("python3")
            .args(["-c", &program])
            .current_dir(tmp.path())
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "the snippet failed:\n{snippet}\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}
