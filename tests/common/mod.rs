//! Shared helpers of the integration tests.
#![allow(dead_code)]

pub mod getfem;
pub mod getfem_blocks;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use contact_sweep::run::bar1d::Bar1dConfig;
use contact_sweep::run::{Grid1d, Outcome, RunConfig, RunContext, RunOptions, Status, simulate};
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactInit, ContactMethod};

pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_contact-sweep")
}

/// Run the binary with `args` in `cwd`.
pub fn cli(cwd: &Path, args: &[&str]) -> Output {
    Command::new(bin())
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("the binary starts")
}

pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Simulate a bar1d run on `grid`, its contact node started consistently, keeping every
/// `series_every`-th step.
pub fn bar1d(bar: BarParams, grid: Grid1d, series_every: usize) -> Outcome {
    simulate_with(Bar1dConfig::new(bar, grid), series_every)
}

/// As [`bar1d`], with the massless contact node started by `init` (contract §2.2
/// `contact_init`).
pub fn bar1d_start(
    init: ContactInit,
    bar: BarParams,
    grid: Grid1d,
    series_every: usize,
) -> Outcome {
    simulate_with(
        Bar1dConfig::new(bar, grid).with_contact_init(init),
        series_every,
    )
}

fn simulate_with(cfg: Bar1dConfig, series_every: usize) -> Outcome {
    simulate(
        &RunConfig::Bar1d(cfg),
        &RunOptions {
            series_every,
            timeout: None,
            cancel: None,
        },
    )
}

pub fn ok(o: Outcome) -> Outcome {
    assert_eq!(o.status, Status::Ok, "run did not end ok: {:?}", o.message);
    o
}

pub fn nitsche(theta: f64, gamma0: f64) -> ContactMethod {
    ContactMethod::Nitsche { theta, gamma0 }
}

/// E(T)/E⁰.
pub fn energy_ratio(o: &Outcome) -> f64 {
    o.metrics.energy_final.unwrap() / o.metrics.energy_initial.unwrap()
}

/// Assert that `x` rounds to the figure printed in contract §6. The figures come from two
/// independent implementations that agree to 1e-11, so the only uncertainty is the rounding of
/// the printed digits: half a unit in the last printed place.
pub fn assert_printed(what: &str, x: f64, printed: &str) {
    assert_printed_within(what, x, printed, 0.5)
}

/// As [`assert_printed`] with a tolerance of `units` in the last printed place.
pub fn assert_printed_within(what: &str, x: f64, printed: &str, units: f64) {
    let target: f64 = printed.parse().unwrap();
    let digits_after_point = printed.split('.').nth(1).map_or(0, |d| d.len());
    let half_ulp = units * 10f64.powi(-(digits_after_point as i32));
    assert!(
        (x - target).abs() <= half_ulp * (1.0 + 1e-9),
        "{what}: computed {x:.6e}, contract §6 prints {printed} (tolerance ±{half_ulp:e})"
    );
}

/// Assert that DIR holds exactly `n` runs, each once, and that the time series has one row per
/// (run, step) and belongs to exactly those runs. Returns the run ids.
pub fn assert_complete(dir: &Path, n: usize) -> std::collections::HashSet<String> {
    use polars::prelude::UniqueKeepStrategy;
    let ids_of = |df: &polars::prelude::DataFrame| -> std::collections::HashSet<String> {
        df.column("run_id")
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .flatten()
            .map(String::from)
            .collect()
    };
    let runs = contact_sweep::sink::read_runs(dir).unwrap();
    assert_eq!(runs.height(), n, "rows in {}", dir.display());
    let ids = ids_of(&runs);
    assert_eq!(ids.len(), n, "duplicate run rows in {}", dir.display());
    let series = contact_sweep::sink::read_series(dir).unwrap();
    let uniq = series
        .select(["run_id", "step"])
        .unwrap()
        .unique_stable(None, UniqueKeepStrategy::First, None)
        .unwrap();
    assert_eq!(uniq.height(), series.height(), "duplicate series rows");
    if series.height() > 0 {
        assert_eq!(
            ids_of(&series),
            ids,
            "series of other runs than the rows, or missing"
        );
    }
    ids
}

/// Plan and run a sweep given as text through the library (references computed into a
/// temporary folder), on two threads; the records in plan order.
pub fn run_sweep_text(text: &str) -> Vec<contact_sweep::run::RunRecord> {
    run_sweep_text_at(Path::new("test.toml"), text)
}

/// [`run_sweep_text`] as if the sweep were the file `path` (mesh files are relative to it).
pub fn run_sweep_text_at(path: &Path, text: &str) -> Vec<contact_sweep::run::RunRecord> {
    use contact_sweep::exec::{self, ExecOptions};
    use contact_sweep::sweep::{SweepFile, expand};
    let sweep = SweepFile::parse(path, text).expect("valid sweep");
    let plan = expand(&sweep).expect("plan");
    let dir = tempfile::tempdir().unwrap();
    let runs: Vec<_> = plan.runs.iter().collect();
    let opts = RunOptions {
        series_every: 0,
        timeout: None,
        cancel: None,
    };
    let refs = exec::references::ensure(dir.path(), &plan, &runs, &opts).expect("references");
    let mut out = Vec::new();
    exec::execute::<()>(
        &plan.sweep.name,
        &runs,
        &refs,
        &ExecOptions {
            threads: 2,
            lockstep: ExecOptions::LOCKSTEP_DEFAULT,
            run: opts,
        },
        |r| {
            out.push(r.record);
            Ok(())
        },
    )
    .unwrap();
    let order: Vec<&str> = plan.runs.iter().map(|r| r.run_id.as_str()).collect();
    out.sort_by_key(|r| order.iter().position(|id| *id == r.run_id));
    out
}

/// The energy a contact potential's schemes keep, per step: E_Θ for Nitsche (the run's label
/// names its space) and E^h for the others (with the penalty, E^h holds the penalty potential
/// Φ: contract §3.2's E^h + Φ).
pub fn kept_energy(label: &str, o: &Outcome) -> Vec<f64> {
    if label.contains("nitsche") {
        o.series
            .rows()
            .map(|r| r.energy_theta.expect("Nitsche has E_Θ"))
            .collect()
    } else {
        o.series.energy.clone()
    }
}

/// Every run of a sweep given as text, simulated with its full time series (one row a step),
/// with its label; `path` is where the sweep would be (mesh files are relative to it).
pub fn outcomes_at(path: &Path, text: &str) -> Vec<(String, Outcome)> {
    outcomes_edited(path, text, |_| {}, &RunContext::default())
}

/// [`outcomes_at`] with each planned configuration changed by `edit` first (a setting the
/// sweep keys do not reach) and simulated in the context `ctx` (e.g. recording the solution).
pub fn outcomes_edited(
    path: &Path,
    text: &str,
    edit: impl Fn(&mut RunConfig),
    ctx: &RunContext,
) -> Vec<(String, Outcome)> {
    let plan = contact_sweep::sweep::expand(
        &contact_sweep::sweep::SweepFile::parse(path, text).expect("valid sweep"),
    )
    .expect("plan");
    assert!(!plan.runs.is_empty(), "no run planned: {text}");
    plan.runs
        .iter()
        .map(|spec| {
            let mut cfg = spec.config.clone();
            edit(&mut cfg);
            let o = contact_sweep::run::simulate_with(
                &cfg,
                &RunOptions {
                    series_every: 1,
                    ..RunOptions::default()
                },
                ctx,
            );
            assert_eq!(o.status.as_str(), "ok", "{}: {:?}", spec.label, o.message);
            (spec.label.clone(), o)
        })
        .collect()
}

/// [`outcomes_at`] for a sweep without mesh files.
pub fn outcomes(text: &str) -> Vec<(String, Outcome)> {
    outcomes_at(Path::new("t.toml"), text)
}

/// The contact patch test's sweep (contract §1.10) on `scene` with mesh size `h`: B's base
/// clamped, gap 0, at rest, λ = λ_b = 0, μ = 1, μ_b = 2, p = 1e-2, one backward-Euler step of
/// τ = 1e6; `method` is the contact treatment's lines (keys of [fixed], then optionally a
/// [grid] table).
pub fn patch_sweep(scene: &str, h: f64, method: &str) -> String {
    format!(
        "name = \"patch\"\nscene = \"{scene}\"\n[fixed]\nT = 1e6\nh = {h}\ndt = 1e6\nscheme = \"backward-euler\"\nfar_end = \"clamped\"\ngap = 0.0\nvelocity = 0.0\nlame_lambda = 0.0\nlame_lambda_b = 0.0\nlame_mu = 1.0\nlame_mu_b = 2.0\npressure = 1e-2\n{method}\n"
    )
}

/// Asserts every patch-test run ended ok with `patch_stress_error` and `patch_pressure_error`
/// ≤ 1e-8 (issue 44 done-when 5), printing them.
pub fn assert_patch(what: &str, runs: &[(String, Outcome)]) {
    for (label, o) in runs {
        assert_eq!(o.status.as_str(), "ok", "{label}: {:?}", o.message);
        let (s, p) = (
            o.metrics.patch_stress_error.expect("a pressure run"),
            o.metrics.patch_pressure_error.expect("a pressure run"),
        );
        eprintln!("patch {what} {label}: stress {s:e}, pressure {p:e}");
        assert!(
            s <= 1e-8 && p <= 1e-8,
            "{label}: stress {s:e}, pressure {p:e}"
        );
    }
}

/// Asserts every two-body run ended ok, touched (a contact phase), and kept its momentum to
/// `tol` (contract §2.6's invariant, `momentum_drift`); returns the worst drift.
pub fn assert_momentum(runs: &[(String, Outcome)], tol: f64) -> f64 {
    let mut worst = 0.0f64;
    for (label, o) in runs {
        assert_eq!(o.status, Status::Ok, "{label}: {:?}", o.message);
        assert!(
            o.metrics.contact_phases.unwrap_or(0) >= 1,
            "{label}: the blocks never touched"
        );
        let drift = o.metrics.momentum_drift.expect("free blocks have a drift");
        assert!(drift <= tol, "{label}: momentum_drift {drift:e}");
        worst = worst.max(drift);
        // Every scheme writes the two-body series at every kept step (the §3.2 methods'
        // driver did not, before).
        for r in o.series.rows() {
            assert!(
                r.momentum.is_some_and(f64::is_finite) && r.u_contact_b.is_some_and(f64::is_finite),
                "{label}: step {} has no momentum or u_contact_b in its series",
                r.step
            );
        }
    }
    worst
}
