//! The analysis/ scripts on a real sweep: every figure is drawn and none is blank.
//!
//! Needs python3 with analysis/requirements.txt installed: the README's test command,
//! `scripts/test.sh`, puts a virtual environment holding them first on PATH; a missing
//! interpreter or package fails the test with that instruction.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::cli;

/// The quickstart run into `dir/qs` (no summary), its path.
fn quickstart(repo: &Path, dir: &Path) -> PathBuf {
    let out = dir.join("qs");
    let o = cli(
        repo,
        &[
            "run",
            "sweeps/quickstart.toml",
            "--out",
            out.to_str().unwrap(),
            "--no-summary",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    out
}

#[test]
fn analysis_scripts_draw_every_figure_of_a_small_sweep() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = quickstart(repo, tmp.path());
    // The stability maps are drawn from the summary's table.
    let o = cli(repo, &["summarize", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let figs = out.join("figures");
    for script in [
        "plot_series.py",
        "plot_convergence.py",
        "plot_work_precision.py",
        "plot_stability_map.py",
    ] {
        let o = Command::new("python3")
            .arg(repo.join("analysis").join(script))
            .arg(&out)
            .arg("--out")
            .arg(&figs)
            .output()
            .expect("python3 runs (scripts/test.sh: a venv with analysis/requirements.txt)");
        assert!(
            o.status.success(),
            "{script} failed — is analysis/requirements.txt installed (scripts/test.sh)?\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = Command::new("python3")
        .arg(repo.join("analysis/check_figures.py"))
        .arg(&figs)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // series (12 parts for 60 runs), convergence, work-precision
    let last = stdout.lines().last().unwrap_or("");
    let passed: usize = last
        .split_whitespace()
        .next()
        .unwrap_or("0")
        .parse()
        .unwrap_or(0);
    assert!(passed >= 3 && last.ends_with("0 failed"), "{last}");
    for f in [
        "convergence_quickstart.png",
        "convergence_quickstart.pdf",
        "work_precision_quickstart_err_u_l2h1.png",
        "stability_map_qs_mixed_mod3_crank-nicolson.png",
    ] {
        assert!(figs.join(f).exists(), "{f} missing");
    }
}

/// 003 Figs 11/12: `plot_energy_impacts.py` on the disc sweep cut to T = 12 (the free fall and
/// the first two time units of the impact: 120 steps of the 1346-dof Q2 disc, well under a
/// second): the four methods are named as the paper names them (the runs joined to the series
/// on run_id), the figure is drawn and not blank, and the deviation the script prints for each
/// method is the engine's own `energy_max_dev` — both are max_n |E^n − E⁰|/energy_scale, so
/// they agree to the script's printing (4 significant digits: relative 5e-4; bound 1e-3).
#[test]
fn energy_impacts_figure_of_a_short_disc_sweep() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("disc");
    let o = cli(
        repo,
        &[
            "run",
            "sweeps/003_fig11_disc.toml",
            "--set",
            "T=12",
            "--out",
            out.to_str().unwrap(),
            "--no-summary",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let figs = tmp.path().join("figures");
    let o = Command::new("python3")
        .arg(repo.join("analysis/plot_energy_impacts.py"))
        .arg(&out)
        .arg("--out")
        .arg(&figs)
        .arg("--stem")
        .arg("disc_energy")
        .output()
        .expect("python3 runs (scripts/test.sh: a venv with analysis/requirements.txt)");
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "plot_energy_impacts.py failed — is analysis/requirements.txt installed (scripts/test.sh)?\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let runs = contact_sweep::sink::read_runs(&out).unwrap();
    assert_eq!(runs.height(), 4);
    let col = |name: &str| -> Vec<String> {
        runs.column(name)
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .map(|s| s.unwrap_or("").to_string())
            .collect()
    };
    let (space, mass, scheme) = (col("space"), col("mass"), col("scheme_label"));
    let dev = runs.column("energy_max_dev").unwrap().f64().unwrap();
    for i in 0..4 {
        let name = match (space[i].as_str(), mass[i].as_str(), scheme[i].as_str()) {
            ("mixed", "consistent", "crank-nicolson") => "mixed + CN:",
            ("nitsche", "consistent", "crank-nicolson") => "Nitsche + CN (",
            ("nitsche", "consistent", "hybrid") => "Nitsche-Hybrid (",
            ("mixed", "zero-contact", "crank-nicolson") => "modified mass + CN:",
            other => panic!("unexpected method {other:?} in sweeps/003_fig11_disc.toml"),
        };
        let line = stdout
            .lines()
            .find(|l| l.starts_with(&format!("003-fig11-disc {name}")))
            .unwrap_or_else(|| panic!("no line for {name} in\n{stdout}"));
        let printed: f64 = line
            .split("max |E−E⁰| = ")
            .nth(1)
            .and_then(|r| r.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("no deviation in {line}"));
        let engine = dev.get(i).unwrap();
        assert!(
            (printed - engine).abs() <= 1e-3 * engine,
            "{name} printed {printed:e}, runs table {engine:e}"
        );
        assert!(line.contains("(× energy_scale)"), "{line}");
    }
    let png = figs.join("disc_energy.png");
    let size = std::fs::metadata(&png).expect("figure written").len();
    // Measured 143 kB (two panels, four curves, two E_Θ curves, the legend); the same two
    // panels with empty axes save to 30 kB: bound 60 kB.
    assert!(size > 60_000, "{} is only {size} bytes", png.display());
    let o = Command::new("python3")
        .arg(repo.join("analysis/check_figures.py"))
        .arg(&figs)
        .args(["--expect", "disc_energy.png"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}");
    assert!(
        stdout.trim_end().ends_with("1 passed, 0 failed"),
        "{stdout}"
    );
}

/// `analysis/sweepdata.py` mirrors the output schema in Python (it reads every part with one
/// schema and casts what differs, so a renamed or retyped column would silently read as nulls
/// there): every column it declares for the runs and series tables is in the engine's Parquet
/// with the declared type, and its `ERROR_COLUMNS` are the engine's (`model::ERROR_COLUMNS`,
/// in order).
#[test]
fn sweepdata_py_mirrors_the_engine_schema() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = quickstart(repo, tmp.path());
    let check = r#"
import sys, polars as pl
sys.path.insert(0, sys.argv[1])
import sweepdata as sd
out, engine_errors = sys.argv[2], sys.argv[3].split(",")
problems = []
for table, declared in (("runs", sd.RUN_COLUMNS), ("series", sd.SERIES_COLUMNS)):
    schema = pl.read_parquet_schema(sd.parquet_files(f"{out}/{table}")[0])
    for name, dtype in declared.items():
        if name not in schema:
            problems.append(f"{table}.{name}: declared, not written")
        elif schema[name] != dtype:
            problems.append(f"{table}.{name}: declared {dtype}, written {schema[name]}")
if sd.ERROR_COLUMNS != engine_errors:
    problems.append(f"ERROR_COLUMNS {sd.ERROR_COLUMNS} != engine {engine_errors}")
print("\n".join(problems))
sys.exit(1 if problems else 0)
"#;
    let o = Command::new("python3")
        .arg("-c")
        .arg(check)
        .arg(repo.join("analysis"))
        .arg(&out)
        .arg(contact_sweep::model::ERROR_COLUMNS.join(","))
        .output()
        .expect("python3 runs (scripts/test.sh: a venv with analysis/requirements.txt)");
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}
