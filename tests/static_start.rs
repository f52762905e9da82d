//! `start = "static"` (contract §1.8, issue 43): a mesh scene's body starts from its static
//! state under gravity with its contact (the Γ_C nodes on the plane pinned normally, stuck
//! tangentially with the run's friction), so a block resting on the plane — flat or inclined —
//! has no bounce: the unstressed start at gap 0 sets it bouncing under gravity (a Γ_C node whose
//! normal force passes through 0 slips whatever μ_f). What is tested: the resting block stays at
//! rest to round-off with every mass variant and several schemes while its rest-started twin
//! bounces; the refusals where a static state does not exist or is not the stuck one; the ids of
//! runs that do not give the key are unchanged. The campaign's resting blocks
//! (tests/friction_campaign.rs) check the stick of every treatment × scheme × mass from it.

use std::path::{Path, PathBuf};

use contact_sweep::run::{Outcome, RunContext, RunOptions, Status, simulate_with};
use contact_sweep::sweep::{Key, SweepFile, expand};
use rayon::prelude::*;

fn sweeps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps")
}

/// The 2D block of sweeps/sliding_block.toml's material (ρ = 1, λ = μ = 10, g = 0.1) resting on
/// the plane at gap 0, with `extra` keys under [fixed] and `grid` under [grid].
fn block(extra: &str, grid: &str) -> String {
    format!(
        "name = \"static\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"meshes/block2d.msh\"\ndensity = 1.0\nlame_lambda = 10.0\nlame_mu = 10.0\ngravity = 0.1\ngap = 0.0\nT = 1.0\ndt = 0.05\n{extra}\n[grid]\n{grid}"
    )
}

/// Plan `text` (as if at sweeps/) and run every run with its series: (label, id, outcome).
fn runs(text: &str) -> Vec<(String, String, Outcome)> {
    let path = sweeps_dir().join("static.toml");
    let plan = expand(&SweepFile::parse(&path, text).expect("valid sweep")).expect("plan");
    plan.runs
        .par_iter()
        .map(|spec| {
            let o = simulate_with(
                &spec.config,
                &RunOptions {
                    series_every: 1,
                    ..RunOptions::default()
                },
                &RunContext::default(),
            );
            let label = match spec.params.get(&Key::Start) {
                Some(start) => format!("{} · start {start}", spec.label),
                None => spec.label.clone(),
            };
            (label, spec.run_id.clone(), o)
        })
        .collect()
}

/// The largest kinetic energy over the run, over the energy scale m·g·H.
fn largest_kinetic(o: &Outcome) -> f64 {
    let scale = o.metrics.energy_scale.unwrap();
    o.series
        .rows()
        .map(|r| r.energy_kinetic.unwrap() / scale)
        .fold(0.0, f64::max)
}

/// A block resting on the plane, flat and on an 18° incline (μ_f = 0.5 > tan 18° = 0.325),
/// mixed, with every mass variant and three schemes: from `start = "static"` it never moves —
/// its kinetic energy stays ≤ 1e-24 of m·g·H (velocities of 1e-12 of √(gH); measured 2e-32,
/// round-off of the step solves) — while from rest (the default) it bounces, the unstressed
/// block falling onto its elastic support: ≥ 1e-5 of m·g·H (measured ≥ 9.5e-5, backward Euler
/// damping it most).
#[test]
fn a_resting_block_starts_at_its_static_state() {
    let grid = "incline = [0.0, 18.0]\nmass = [\"consistent\", \"lumped\", \"mod3\"]\nscheme = [{ scheme = \"crank-nicolson\" }, { scheme = \"backward-euler\" }, { scheme = \"generalized-alpha\", rho_inf = 0.5 }]\nstart = [\"rest\", \"static\"]\n";
    let out = runs(&block(
        "space = \"mixed\"\nfriction = \"coulomb\"\nfriction_coefficient = 0.5",
        grid,
    ));
    // 2 × 3 × 3 × 2 combinations, less those a mass variant does not take (the planner's).
    assert_eq!(out.len(), 32);
    let (mut still, mut bounced) = (0.0f64, f64::INFINITY);
    for (label, _, o) in &out {
        assert_eq!(o.status, Status::Ok, "{label}: {:?}", o.message);
        let v = largest_kinetic(o);
        if label.ends_with("start static") {
            still = still.max(v);
        } else {
            bounced = bounced.min(v);
        }
    }
    eprintln!(
        "largest kinetic energy / m·g·H: static start {still:e}; rest start at least {bounced:e}"
    );
    assert!(still <= 1e-24, "{still:e}");
    assert!(bounced >= 1e-5, "{bounced:e}");
}

/// The static start's E⁰ is the static state's −½Fᵀu⁰ < 0 (the gravity potential zero at the
/// unstressed position), and the run's energy stays there: backward Euler at rest keeps E to
/// 1e-12 of the energy scale m·g·H (a step's round-off).
#[test]
fn the_static_start_energy_is_the_static_states() {
    let out = runs(&block(
        "space = \"mixed\"\nfriction = \"coulomb\"\nfriction_coefficient = 1.0\nscheme = \"backward-euler\"\nstart = \"static\"\nincline = 18.0",
        "mass = [\"consistent\"]\n",
    ));
    let o = &out[0].2;
    assert_eq!(o.status, Status::Ok, "{:?}", o.message);
    let e0 = o.metrics.energy_initial.unwrap();
    let scale = o.metrics.energy_scale.unwrap();
    assert!(e0 < 0.0, "{e0}");
    let worst = o
        .series
        .rows()
        .map(|r| (r.energy - e0).abs() / scale)
        .fold(0.0, f64::max);
    assert!(worst <= 1e-12, "{worst:e}");
}

/// The error of planning `text`, rendered.
fn refusal(text: &str) -> String {
    let path = sweeps_dir().join("static.toml");
    let sweep = match SweepFile::parse(&path, text) {
        Err(e) => return e.to_string(),
        Ok(s) => s,
    };
    match expand(&sweep) {
        Err(e) => e.to_string(),
        Ok(p) => panic!("planned {} runs: {text}", p.runs.len()),
    }
}

/// Where no static state exists, or it is not unique, the key is refused before anything runs,
/// naming the file, the key and why; on a scene that does not take it, as an unknown key.
#[test]
fn the_static_start_is_refused_where_meaningless() {
    let frictionless = refusal(&block("start = \"static\"", "mass = [\"consistent\"]\n"));
    assert!(
        frictionless.contains("static.toml")
            && frictionless.contains("start")
            && frictionless.contains("no friction"),
        "{frictionless}"
    );
    let weightless = refusal(&block(
        "start = \"static\"\nfriction = \"coulomb\"\nfriction_coefficient = 1.0",
        "gravity = [0.0]\n",
    ));
    assert!(weightless.contains("without gravity"), "{weightless}");
    let falling = refusal(&block(
        "start = \"static\"\nfriction = \"coulomb\"\nfriction_coefficient = 1.0",
        "gap = [0.5]\n",
    ));
    assert!(falling.contains("it falls"), "{falling}");
    let word = refusal(&block(
        "start = \"settled\"\nfriction = \"coulomb\"\nfriction_coefficient = 1.0",
        "mass = [\"consistent\"]\n",
    ));
    assert!(
        word.contains("unknown start `settled`") && word.contains("rest or static"),
        "{word}"
    );
    let bar = refusal(
        "name = \"s\"\nscene = \"bar2d\"\n[fixed]\nh = 0.1\nT = 0.1\ndt = 0.01\nstart = \"static\"\n",
    );
    assert!(bar.contains("start"), "{bar}");
}

/// Where the stuck static state lies outside the friction cone (μ_f = 0.1 < tan 18°: the block
/// would slide down), the run ends `invalid` at its start, saying so.
#[test]
fn a_stuck_state_outside_the_cone_is_invalid() {
    let out = runs(&block(
        "space = \"mixed\"\nfriction = \"coulomb\"\nfriction_coefficient = 0.1\nstart = \"static\"\nincline = 18.0\nscheme = \"backward-euler\"",
        "mass = [\"consistent\"]\n",
    ));
    let o = &out[0].2;
    assert_eq!(o.status, Status::Invalid);
    let m = o.message.as_deref().unwrap();
    assert!(m.contains("outside the friction cone"), "{m}");
}

/// A run that does not give `start`, or gives its default `rest`, keeps its id; `static` is
/// another run.
#[test]
fn ids_are_unchanged_without_the_key() {
    let path = sweeps_dir().join("static.toml");
    let id = |extra: &str| {
        let text = block(
            &format!("friction = \"coulomb\"\nfriction_coefficient = 1.0\n{extra}"),
            "mass = [\"consistent\"]\n",
        );
        let plan = expand(&SweepFile::parse(&path, &text).unwrap()).unwrap();
        plan.runs[0].run_id.clone()
    };
    assert_eq!(id(""), id("start = \"rest\""));
    assert_ne!(id(""), id("start = \"static\""));
}
