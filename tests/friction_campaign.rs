//! The seeded frictional campaign of issue 43: blocks sliding and sticking, flat and on
//! inclines (2D and 3D Gmsh meshes of sweeps/meshes), the P2 disc thrown onto an incline, bar2d
//! and bar3d; every contact treatment × mass variant × implicit scheme with a frictional
//! version (contract §2.5); Coulomb μ_f up to 5 and Tresca thresholds up to the block's weight;
//! small and large γ0 for Nitsche and penalty. Table-driven: each [`Case`] is one run, its
//! treatment a field, so the cases of every treatment sit in one list.
//!
//! What it asserts (issue 43, "done when" 1):
//! - no run ends `solver-failed`;
//! - no run ends `diverged` (or `invalid`) where its frictionless twin — the same run with
//!   `friction = "none"` — ends ok;
//! - a block with μ_f ≥ 1 sticks: after the transient the time mean of the Γ_C mean tangential
//!   velocity is ≤ 1e-8·V (V the throw speed) — asserted for every method on the blocks
//!   resting on the 18° incline from their static state, the regularised sticks (Nitsche,
//!   penalty) at their predicted creep and Moreau–Jean within its index set's bounce; on the
//!   thrown blocks for backward Euler, printed for the rest ([`ASSERT_STICK`] says why).
//!
//! The named cases of the issue are regression tests of their own below, and so are the
//! campaign's steps that once ended `solver-failed` ([`rescued_case`]). Nitsche and penalty
//! cases are asserted as mixed ones ([`ASSERT_POTENTIALS`]). The campaign prints where its
//! time goes ([`profile`]: each case's CPU time, per scene and the slowest), never asserting it.

use std::path::{Path, PathBuf};

use contact_sweep::run::{Outcome, RunContext, RunOptions, Status, simulate_with};
use contact_sweep::sweep::{SweepFile, expand};
use rayon::prelude::*;

/// A contact treatment (contract §2.2's `space`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Treatment {
    Mixed,
    Nitsche,
    Penalty,
}

/// A friction law of a case.
#[derive(Debug, Clone, Copy)]
enum Law {
    Coulomb(f64),
    Tresca(f64),
}

impl Law {
    fn toml(self) -> String {
        match self {
            Law::Coulomb(mu) => {
                format!("friction = \"coulomb\"\nfriction_coefficient = {mu}\n")
            }
            Law::Tresca(s) => format!("friction = \"tresca\"\ntresca_threshold = {s}\n"),
        }
    }
}

/// A block that must stick (μ_f ≥ 1) and how it starts.
#[derive(Debug, Clone, Copy)]
enum Stick {
    /// Thrown at V (its speed scale) from rest at gap 0.
    Thrown(f64),
    /// At rest from its static state on the 18° incline (`start = "static"`), its Γ_C elements'
    /// diameter h_K (the regularised sticks' creep, [`creep`]).
    Resting { h_k: f64 },
}

impl Stick {
    /// The speed the drift is measured in: the throw speed; a resting block's thrown twin's.
    fn speed(self) -> f64 {
        match self {
            Stick::Thrown(v) => v,
            Stick::Resting { .. } => 0.05,
        }
    }
}

/// One run of the campaign.
#[derive(Debug, Clone)]
struct Case {
    /// The scene's name in the campaign (block2d-flat, disc-p2-incline, …).
    scene: &'static str,
    /// The scene's [fixed] keys (scene, mesh, physics, T, dt), without friction or method.
    body: String,
    treatment: Treatment,
    /// The method's keys: mass, scheme and their parameters, γ0.
    method: String,
    law: Law,
    /// A block that must stick (μ_f ≥ 1): the stick criterion applies.
    sticks: Option<Stick>,
}

impl Case {
    fn text(&self, law: Option<Law>) -> String {
        let space = match self.treatment {
            Treatment::Mixed => "mixed",
            Treatment::Nitsche => "nitsche",
            Treatment::Penalty => "penalty",
        };
        format!(
            "name = \"campaign\"\n{}\nspace = \"{space}\"\n{}\n{}",
            self.body,
            self.method,
            law.map_or("friction = \"none\"\n".to_string(), Law::toml)
        )
    }

    fn label(&self) -> String {
        format!(
            "{} · {:?} · {} · {:?}",
            self.scene,
            self.treatment,
            self.method.replace('\n', " "),
            self.law
        )
    }
}

fn sweeps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps")
}

/// Plan and run the one run of `text` (mesh paths relative to sweeps/), with its series.
fn run(text: &str) -> Result<Outcome, String> {
    let path = sweeps_dir().join("campaign.toml");
    let sweep = SweepFile::parse(&path, text).map_err(|e| format!("{e}"))?;
    let plan = expand(&sweep).map_err(|e| format!("{e:?}"))?;
    assert_eq!(plan.runs.len(), 1, "one run per case: {text}");
    Ok(simulate_with(
        &plan.runs[0].config,
        &RunOptions {
            series_every: 1,
            ..RunOptions::default()
        },
        &RunContext::default(),
    ))
}

/// The block's body (sweeps/sliding_block.toml's material and load: ρ = 1, λ = μ = 10, g = 0.1;
/// weight per unit of Γ_C ρgH = 0.05) thrown at `v` along an `incline` in degrees.
fn block(dim: usize, incline: f64, v: f64, t: f64, dt: f64) -> String {
    format!(
        "scene = \"mesh{dim}d\"\n[fixed]\nmesh = \"meshes/block{dim}d.msh\"\ndensity = 1.0\nlame_lambda = 10.0\nlame_mu = 10.0\ngravity = 0.1\ngap = 0.0\nvelocity_tangential = {v}\nincline = {incline}\nT = {t}\ndt = {dt}"
    )
}

/// The P2 disc of sweeps/meshes/disc_p2.msh (R = 20, λ = μ = 20, g = 0.1) dropped from gap 1
/// onto an `incline`, thrown at 0.5 along it.
/// `body` starting from its static state under gravity (`start = "static"`, contract §1.8).
fn static_start(body: String) -> String {
    format!("{body}\nstart = \"static\"")
}

fn disc_p2(incline: f64, t: f64, dt: f64) -> String {
    format!(
        "scene = \"mesh2d\"\n[fixed]\nmesh = \"meshes/disc_p2.msh\"\ndensity = 1.0\nlame_lambda = 20.0\nlame_mu = 20.0\ngravity = 0.1\ngap = 1.0\nvelocity_tangential = 0.5\nincline = {incline}\nT = {t}\ndt = {dt}"
    )
}

fn bar(scene: &str, h: f64, t: f64, dt: f64) -> String {
    format!("scene = \"{scene}\"\n[fixed]\nh = {h}\nT = {t}\ndt = {dt}")
}

/// The mixed treatment's (mass, scheme) pairs: every mass variant with every implicit scheme
/// that has a frictional version (contract §2.5; central difference is explicit).
fn mixed_methods() -> Vec<String> {
    let schemes = [
        "scheme = \"crank-nicolson\"",
        "scheme = \"backward-euler\"",
        "scheme = \"kane\"",
        "scheme = \"contact-stabilized-newmark\"",
        "scheme = \"generalized-alpha\"\nrho_inf = 0.5",
        "scheme = \"hht\"\nhht_alpha = 0.1",
        "scheme = \"moreau-jean\"\nrestitution = 0.0",
    ];
    let mut out = Vec::new();
    for mass in ["consistent", "lumped", "mod3"] {
        for s in schemes {
            out.push(format!("mass = \"{mass}\"\n{s}"));
        }
    }
    out
}

/// Nitsche's and the penalty's (mass, scheme, γ0): small and large γ0.
fn potential_methods(t: Treatment) -> Vec<String> {
    let schemes = [
        "scheme = \"crank-nicolson\"",
        "scheme = \"backward-euler\"",
        "scheme = \"generalized-alpha\"\nrho_inf = 0.5",
        "scheme = \"hht\"\nhht_alpha = 0.1",
    ];
    let gammas: [&str; 2] = match t {
        Treatment::Nitsche => [
            "nitsche_theta = 1.0\nnitsche_gamma0 = 1e-4",
            "nitsche_theta = 1.0\nnitsche_gamma0 = 1e-2",
        ],
        _ => ["penalty_gamma0 = 10.0", "penalty_gamma0 = 1000.0"],
    };
    let mut out = Vec::new();
    for mass in ["consistent", "mod3"] {
        for s in schemes {
            for g in gammas {
                out.push(format!("mass = \"{mass}\"\n{s}\n{g}"));
            }
        }
    }
    out
}

/// Whether the Nitsche and penalty cases are asserted too: they are. Measured (campaign()
/// prints each failure as "FAIL …"; seed 43, 55 runs each): at the start of robust43 (issue 43,
/// session 30), Nitsche 11 and penalty 8 runs `solver-failed` — 15 of them in the quasi-static
/// start of mod3's massless layer (μ_f 2.3–5), rescued by its frictionless fallback
/// ([`sticking_block_mod3_start_with_mu_5`]). The last 6 were steps that neither the
/// continuation in the bound nor the block Gauss–Seidel fallback solved (Nitsche γ0 = 1e-4 on
/// the 18° incline with backward Euler, generalized-α and HHT at μ_f 3.4–4.2, flat with mod3
/// and backward Euler at 4.59, Tresca s = 0.048 with HHT; the penalty γ0 = 1e3 with backward
/// Euler at 3.91): each step's LCP has a solution — Lemke's pivoting finds it where the
/// continuation's path folds — and the solve's last stage is now Lemke
/// (`crate::contact::lemke`); each case is a regression test below
/// ([`rescued_case`]). Nitsche's and the penalty's stick drift is printed, not asserted
/// (their stick is regularised). None diverged. Mixed: 0 of its 77.
const ASSERT_POTENTIALS: bool = true;

/// Whether the stick criterion is asserted for every method: it is, on the blocks resting on
/// the 18° incline from their static state (`start = "static"`, contract §1.8; scenes
/// `block2d-incline18-rest` with every treatment × scheme × mass, `block3d-incline18-rest` a
/// sample; [`stick_holds`]). "After the transient" is precise there: a static start has none
/// but the regularised laws' first step, so the window t ≥ T/2 of [`REST_T`] holds 20 steps of
/// the steady state. Mixed sticks to round-off with every scheme and mass (measured ≤ 1.4e-15·V)
/// but Moreau–Jean θ = ½ (≤ 1.4e-2·V, its index set's round-off decisions, [`stick_holds`]);
/// the penalty and Nitsche creep at their regularisation's predicted rate.
///
/// The thrown blocks (V = 0.05 from rest at gap 0, T = 10, window t ≥ 5) are asserted with
/// backward Euler only, as before: it sticks with every mass (drift ≤ 1.5e-16·V); every other
/// implicit scheme drifts, 6e-4·V (generalized-α, lumped) to 0.67·V (CN, lumped). Measured from
/// the static start too (session 32): no better — CN up to 0.83·V, kane 7.7e-5–6e-3·V,
/// Moreau–Jean 3.5e-4–4.9e-2·V, generalized-α/HHT/CSN 3e-6–7e-3·V, and one backward Euler run
/// (18°, lumped, μ_f 2.34) 6.6e-8·V, its bounce not yet damped at t = 5. It is the throw, not
/// the start: the stick at the stop is sudden (the block decelerates at g(μ_f cos α − sin α)
/// and its Γ_C halts within a step), it releases a shear wave whose traction is of the order
/// of μ_f f_n itself, and a scheme that neither damps it (CN and kane keep it; generalized-α
/// ρ∞ = ½, HHT α = 0.1, CSN barely damp it; Moreau–Jean θ = ½ feeds it at lift-off, contract
/// §2.5) breaks the stick again wherever the wave takes a node's traction out of the cone.
/// Every such step meets the §4 tolerance: not a solver failure, the undamped elastic model.
const ASSERT_STICK: bool = true;

/// The sticking blocks' end time (their stick window is t ≥ T/2). T = 5 would halve the
/// campaign's largest share (the 2D sticking blocks' 82 runs are 30 of its 51 CPU seconds,
/// measured), but the shorter window is not past the transient: measured at T = 5, a mixed
/// backward Euler run on the 18° incline (lumped, μ_f 2.34) drifts 2.0e-7·V, over the
/// criterion's 1e-8·V.
const STICK_T: f64 = 10.0;

/// The block's weight per unit of Γ_C: ρ·g·H = 1 · 0.1 · 0.5.
const BLOCK_WEIGHT: f64 = 0.05;

/// Every case of the campaign, drawn from the seed: the blocks with every method, the disc
/// and the bars with a seeded sample of them.
fn cases(seed: u64) -> Vec<Case> {
    let mut rng = fastrand::Rng::with_seed(seed);
    let mut methods: Vec<(Treatment, String)> = Vec::new();
    for m in mixed_methods() {
        methods.push((Treatment::Mixed, m));
    }
    for t in [Treatment::Nitsche, Treatment::Penalty] {
        for m in potential_methods(t) {
            methods.push((t, m));
        }
    }
    // (scene, body, law drawn, throw speed if it must stick, every method or a sample).
    type Draw = fn(&mut fastrand::Rng) -> Law;
    let stick: Draw = |r| Law::Coulomb(1.0 + 4.0 * r.f64());
    let slide: Draw = |r| Law::Coulomb(0.1 + 0.5 * r.f64());
    let tresca: Draw = |r| Law::Tresca(BLOCK_WEIGHT * (0.1 + 0.9 * r.f64()));
    let moderate: Draw = |r| Law::Coulomb(0.3 + 0.7 * r.f64());
    let scenes: Vec<(&str, String, Draw, Option<Stick>, bool)> = vec![
        (
            "block2d-flat-stick",
            block(2, 0.0, 0.05, STICK_T, 0.05),
            stick,
            Some(Stick::Thrown(0.05)),
            true,
        ),
        (
            "block2d-incline18-stick",
            block(2, 18.0, 0.05, STICK_T, 0.05),
            stick,
            Some(Stick::Thrown(0.05)),
            true,
        ),
        (
            "block2d-incline5-slide",
            block(2, 5.0, 0.5, 3.0, 0.05),
            slide,
            None,
            true,
        ),
        (
            "block2d-tresca",
            block(2, 0.0, 0.5, 3.0, 0.05),
            tresca,
            None,
            true,
        ),
        (
            "block3d-flat-stick",
            block(3, 0.0, 0.05, STICK_T, 0.05),
            stick,
            Some(Stick::Thrown(0.05)),
            false,
        ),
        (
            "block3d-incline5-tresca",
            block(3, 5.0, 0.5, 2.0, 0.05),
            tresca,
            None,
            false,
        ),
        (
            "disc-p2-incline26",
            disc_p2(26.0, 8.0, 0.1),
            moderate,
            None,
            false,
        ),
        ("bar2d", bar("bar2d", 0.1, 1.0, 0.02), moderate, None, false),
        ("bar3d", bar("bar3d", 0.1, 1.0, 0.05), moderate, None, false),
        // Last, so the scenes above keep their draws of the seed.
        (
            "block2d-incline18-rest",
            static_start(block(2, 18.0, 0.0, REST_T, 0.05)),
            stick,
            Some(Stick::Resting {
                // sweeps/meshes/block2d.msh: 8 × 4 squares of side 1/8.
                h_k: (2.0f64 / 64.0).sqrt(),
            }),
            true,
        ),
        (
            "block3d-incline18-rest",
            static_start(block(3, 18.0, 0.0, REST_T, 0.05)),
            stick,
            Some(Stick::Resting {
                // sweeps/meshes/block3d.msh: 4 × 2 × 2 cubes of side 1/4.
                h_k: (3.0f64 / 16.0).sqrt(),
            }),
            false,
        ),
    ];
    let mut out = Vec::new();
    for (scene, body, draw, sticks, every) in scenes {
        let chosen: Vec<&(Treatment, String)> = if every {
            methods.iter().collect()
        } else {
            // Two of each treatment's methods.
            let mut pick = Vec::new();
            for t in [Treatment::Mixed, Treatment::Nitsche, Treatment::Penalty] {
                let of: Vec<_> = methods.iter().filter(|m| m.0 == t).collect();
                for _ in 0..2 {
                    pick.push(of[rng.usize(..of.len())]);
                }
            }
            pick
        };
        for (t, m) in chosen {
            out.push(Case {
                scene,
                body: body.clone(),
                treatment: *t,
                method: m.clone(),
                law: draw(&mut rng),
                sticks,
            });
        }
    }
    out
}

/// What one case gave.
struct Report {
    status: Status,
    message: Option<String>,
    /// The time mean over t ≥ T/2 of the Γ_C mean tangential velocity, over V (sticking
    /// blocks only).
    drift: Option<f64>,
    iterations: i64,
    iterations_max_step: i64,
    /// The run record's stage columns: primary Newton, continuation, fallback.
    stages: [Option<i64>; 3],
    /// The frictionless twin's status where the run did not end ok.
    twin: Option<Status>,
    /// CPU time of the case's thread (its twin included), for the campaign's profile.
    secs: f64,
}

/// The case's report, or None where the planner finds the combination meaningless (a mass
/// variant a scheme does not take: the product below lists them all, the planner decides — as
/// one combination left out of an axis, or, the case's methods being fixed keys, refused at
/// them as making no method).
fn evaluate(c: &Case) -> Option<Report> {
    let start = thread_cpu_seconds();
    let o = match run(&c.text(Some(c.law))) {
        Ok(o) => o,
        Err(e) if e.contains("inapplicable") || e.contains("together make no method") => {
            return None;
        }
        Err(e) => panic!("{}: the planner refused the case: {e}", c.label()),
    };
    let drift = c.sticks.map(Stick::speed).and_then(|v| {
        let rows: Vec<_> = o.series.rows().collect();
        let t_end = rows.last()?.t;
        let late: Vec<f64> = rows
            .iter()
            .filter(|r| r.t >= 0.5 * t_end)
            .filter_map(|r| r.v_t_contact)
            .collect();
        (!late.is_empty()).then(|| (late.iter().sum::<f64>() / late.len() as f64).abs() / v)
    });
    let twin = (o.status != Status::Ok).then(|| run(&c.text(None)).expect("planned").status);
    Some(Report {
        status: o.status,
        message: o.message.clone(),
        drift,
        iterations: o.metrics.iterations,
        iterations_max_step: o.metrics.iterations_max_step.unwrap_or(0),
        stages: [
            o.metrics.friction_newton_iterations,
            o.metrics.friction_continuation_iterations,
            o.metrics.friction_fallback_iterations,
        ],
        twin,
        secs: thread_cpu_seconds() - start,
    })
}

/// The campaign (module header): seeded, every case once, in parallel.
#[test]
fn campaign() {
    let all = cases(43);
    let start = std::time::Instant::now();
    let reports: Vec<Option<Report>> = all.par_iter().map(evaluate).collect();
    let ran = reports.iter().flatten().count();
    eprintln!(
        "{ran} runs ({} inapplicable) in {:.1} s",
        all.len() - ran,
        start.elapsed().as_secs_f64()
    );
    profile(&all, &reports);
    let mut failures = Vec::new();
    let mut counts = std::collections::BTreeMap::<String, [usize; 4]>::new();
    // Mixed steps the primary Newton did not solve (it returns within 100 steps, Tresca's
    // closure within 300): on main these runs ended `solver-failed`.
    let rescued = all
        .iter()
        .zip(&reports)
        .filter(|(c, r)| {
            let limit = if matches!(c.law, Law::Tresca(_)) {
                300
            } else {
                100
            };
            c.treatment == Treatment::Mixed
                && r.as_ref().is_some_and(|r| r.iterations_max_step >= limit)
        })
        .count();
    let drifts: Vec<f64> = reports.iter().flatten().filter_map(|r| r.drift).collect();
    eprintln!(
        "mixed runs rescued (solver-failed on main): {rescued}; stick drift/V over {} runs: min {:e} max {:e}",
        drifts.len(),
        drifts.iter().cloned().fold(f64::INFINITY, f64::min),
        drifts.iter().cloned().fold(0.0, f64::max)
    );
    for (c, r) in all.iter().zip(&reports) {
        let Some(r) = r else { continue };
        check_stage_columns(c, r);
        let solver_failed = r.status == Status::SolverFailed;
        let lost = r.status != Status::Ok && !solver_failed && r.twin == Some(Status::Ok);
        // Stick (issue 43): the resting blocks by every method ([`stick_holds`]); the thrown
        // blocks by backward Euler, 1e-8·V — a stuck node's slip is the solver's residual,
        // 1e-12 relative, and the mean over the window averages the elastic vibration out
        // ([`ASSERT_STICK`]: the other schemes' drift is printed, and why).
        if let (Some(Stick::Resting { .. }), Some(d)) = (c.sticks, r.drift) {
            eprintln!("rest {}: drift/V {d:e}", c.label());
        }
        let slid = match (c.sticks, r.drift) {
            (Some(Stick::Resting { h_k }), Some(d)) => !stick_holds(c, h_k, d),
            (Some(Stick::Thrown(_)), Some(d)) => d > 1e-8 && c.method.contains("backward-euler"),
            _ => false,
        };
        // Nitsche's and the penalty's thrown blocks slide on too: printed, not asserted.
        let slid_asserted = slid
            && (c.treatment == Treatment::Mixed
                || ASSERT_STICK && matches!(c.sticks, Some(Stick::Resting { .. })));
        let e = counts.entry(format!("{:?}", c.treatment)).or_default();
        e[0] += 1;
        e[1] += usize::from(solver_failed);
        e[2] += usize::from(lost);
        e[3] += usize::from(slid);
        if solver_failed || lost || slid {
            let line = format!(
                "{}: {} (twin {:?}) drift {:?} its {} max {}: {:?}",
                c.label(),
                r.status.as_str(),
                r.twin,
                r.drift,
                r.iterations,
                r.iterations_max_step,
                r.message
            );
            eprintln!("FAIL {line}");
            if (c.treatment == Treatment::Mixed || ASSERT_POTENTIALS)
                && (solver_failed || lost || slid_asserted)
            {
                failures.push(line);
            }
        }
    }
    let max_its = reports
        .iter()
        .flatten()
        .map(|r| r.iterations_max_step)
        .max();
    eprintln!("runs / solver-failed / diverged with an ok twin / slid, per treatment: {counts:?}");
    eprintln!("most iterations in one step: {max_its:?}");
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The resting blocks' end time: they start static, so there is no transient but the
/// regularised laws' own first steps (the penalty's contact settles by f_n/κ, its tangential
/// force builds in one step), and the window t ≥ T/2 holds 20 steps of the steady creep.
const REST_T: f64 = 2.0;

/// Whether a resting block (μ_f ≥ 1 on the 18° incline, from its static state; elements of
/// diameter `h_k`) sticks as its treatment can: `drift` is the window's mean Γ_C tangential
/// velocity over V = 0.05. The tangential traction that friction holds is t_t = ρgH sin 18°.
/// - `mixed`: the nodes stick exactly, drift ≤ 1e-8 (the criterion).
/// - `penalty`: f_t = −κ(u_t^{n+1} − u_t^n) (contract §2.5) holds t_t only while the point
///   slips by t_t/κ per step: a creep t_t/(κτ), κ = E·γ0/h_K (E = 25 from λ = μ = 10) —
///   4.37e-5·V at γ0 = 1e3, 4.37e-3·V at γ0 = 10 on the 2D block, 1.07e-2·V at γ0 = 10 on the
///   3D one. Measured within 5 % of it (2D: 4.16e-5–4.37e-5 and 4.23e-3–4.47e-3 over the
///   schemes, masses and μ_f; 3D 1.08e-2): asserted to 10 %, twice that.
/// - `nitsche`: the slip per step is γ_h τ (σ_t(u_h) − f_t) (contract §2.5), γ_h = γ0·h_K: a
///   creep γ_h (σ_t − f_t), bounded by γ_h·t_t while the points' stress σ_t(u_h) errs by less
///   than the traction it carries. Measured 3.6 % of the bound at γ0 = 1e-4 and 8 % at 1e-2 in
///   2D (1.9e-7·V and 4.5e-5·V), 14 % at 1e-4 in 3D (1.9e-6·V). Asserted: ≤ γ_h·t_t.
fn stick_holds(c: &Case, h_k: f64, drift: f64) -> bool {
    let v = 0.05;
    let t_t = BLOCK_WEIGHT * 18f64.to_radians().sin();
    let gamma0 = |key: &str| -> f64 {
        let line = c.method.lines().find(|l| l.starts_with(key)).unwrap();
        line.split('=').nth(1).unwrap().trim().parse().unwrap()
    };
    match c.treatment {
        // Moreau–Jean θ = ½ (contract §2.5): a resting node's place in the index set
        // y + ½τẏ ≤ 0 is decided by round-off (y, ẏ ~ 1e-19 at the static state), a node left
        // out drops and is caught by an impulse that can add energy, so the block starts
        // rocking (|v_n| up to 1e-2 from the static start, measured) and a node whose impulse
        // passes through 0 slips: drifts 8e-5 to 1.4e-2 of V measured (flat and 18°, μ_f 1–5,
        // consistent and lumped). Siconos 4.4 does the same on this block
        // ([`moreau_jean_resting_block_against_siconos`]): the method. Asserted: ≤ 0.05, the
        // block creeping at most a twentieth of the thrown twin's speed.
        Treatment::Mixed if c.method.contains("moreau-jean") => drift <= 0.05,
        Treatment::Mixed => drift <= 1e-8,
        Treatment::Penalty => {
            let kappa = 25.0 * gamma0("penalty_gamma0") / h_k;
            let predicted = t_t / (kappa * 0.05) / v;
            (drift / predicted - 1.0).abs() <= 0.1
        }
        Treatment::Nitsche => drift <= gamma0("nitsche_gamma0") * h_k * t_t / v,
    }
}

/// This thread's CPU time in seconds (user + system, /proc/thread-self/stat's utime and stime
/// at the usual 100 ticks a second): each case runs on one rayon thread, so under a loaded
/// machine this is its cost, where wall time is mostly waiting. 0 where /proc has no answer.
fn thread_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/thread-self/stat") else {
        return 0.0;
    };
    // The fields after the command's closing parenthesis: state is field 3, utime 14, stime 15.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

/// Print where the campaign's time goes: per scene, and the slowest cases (timings are
/// printed, never asserted).
fn profile(all: &[Case], reports: &[Option<Report>]) {
    let mut per_scene = std::collections::BTreeMap::<&str, (usize, f64)>::new();
    let mut timed: Vec<(f64, String)> = Vec::new();
    for (c, r) in all.iter().zip(reports) {
        let Some(r) = r else { continue };
        let e = per_scene.entry(c.scene).or_default();
        e.0 += 1;
        e.1 += r.secs;
        timed.push((
            r.secs,
            format!(
                "{} (iterations {}, stages {:?})",
                c.label(),
                r.iterations,
                r.stages
            ),
        ));
    }
    eprintln!("CPU seconds per scene (runs, total): {per_scene:?}");
    timed.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (secs, label) in timed.iter().take(12) {
        eprintln!("slow {secs:.2} s: {label}");
    }
}

/// The stage columns of a frictional run (issue 43: iterations of each stage reported): set
/// on every run that stepped, and on a run that ended ok where every contact solve is the frictional one (Nitsche, penalty: the steps' and the
/// stages' counts are the same integers) they add up to `iterations`; a mixed run whose step
/// needed more than the primary Newton's budget (the rescue) shows it in the rescue's columns.
fn check_stage_columns(c: &Case, r: &Report) {
    let [Some(newton), Some(cont), Some(fallback)] = r.stages else {
        // A run stopped in its set-up (the quasi-static start) has no step and no tally.
        assert_ne!(r.status, Status::Ok, "{}: no stage columns", c.label());
        return;
    };
    // A failed step's stages are counted, its iterations not: ok runs only.
    if c.treatment != Treatment::Mixed && r.status == Status::Ok {
        assert_eq!(newton + cont + fallback, r.iterations, "{}", c.label());
    } else if r.status == Status::Ok {
        assert!(newton + cont + fallback <= r.iterations, "{}", c.label());
    }
    let limit = if matches!(c.law, Law::Tresca(_)) {
        300
    } else {
        100
    };
    if c.treatment == Treatment::Mixed && r.iterations_max_step >= limit {
        assert!(
            cont + fallback > 0,
            "{}: rescued, no rescue stage",
            c.label()
        );
    }
}

/// sweeps/sliding_block.toml's text with `friction = "tresca"` and the thresholds of issue 43
/// (0.1 to 1 × the weight per unit of Γ_C, 0.05) on an axis: 50 runs.
fn sliding_block_tresca_text() -> String {
    let text = std::fs::read_to_string(sweeps_dir().join("sliding_block.toml")).unwrap();
    let text = text
        .replace("friction = \"coulomb\"", "friction = \"tresca\"")
        .replace("friction_coefficient = 0.2\n", "")
        .replace(
            "incline = [0.0, 5.0]",
            "incline = [0.0, 5.0]\ntresca_threshold = [0.005, 0.01, 0.02, 0.03, 0.05]",
        )
        .replace("series_every = 1", "series_every = 0");
    assert!(
        text.contains("tresca_threshold = ["),
        "the sweep file changed"
    );
    text
}

/// The statuses of every run of a sweep text (as if at sweeps/), with labels.
fn statuses(text: &str) -> Vec<(String, Status, Option<String>, i64)> {
    let path = sweeps_dir().join("named.toml");
    let plan = expand(&SweepFile::parse(&path, text).expect("valid sweep")).expect("plan");
    plan.runs
        .par_iter()
        .map(|spec| {
            let o = simulate_with(&spec.config, &RunOptions::default(), &RunContext::default());
            (
                spec.label.clone(),
                o.status,
                o.message,
                o.metrics.iterations_max_step.unwrap_or(0),
            )
        })
        .collect()
}

/// Assert every run of `runs` whose label passes `keep` ended ok; returns how many did.
fn all_ok(runs: &[(String, Status, Option<String>, i64)], keep: impl Fn(&str) -> bool) -> usize {
    let mut n = 0;
    for (label, status, message, its) in runs.iter().filter(|r| keep(&r.0)) {
        eprintln!(
            "{label}: {} (most iterations in a step {its})",
            status.as_str()
        );
        assert_eq!(*status, Status::Ok, "{label}: {message:?}");
        n += 1;
    }
    n
}

/// Issue 43: sweeps/sliding_block.toml with Tresca failed 30 of its 50 runs — 8 of them mixed
/// (kane and Moreau–Jean from s = 0.02, 0.4 × the weight; "did not converge in 300
/// iterations"). Every mixed run now ends ok (measured: rescued steps cost up to 2 626
/// iterations, primary Newton, closure, continuation and Gauss–Seidel together).
#[test]
fn sliding_block_toml_with_tresca() {
    let runs = statuses(&sliding_block_tresca_text());
    assert_eq!(runs.len(), 50);
    assert_eq!(all_ok(&runs, |l| l.starts_with("mixed")), 30);
}

/// The Nitsche and penalty runs of [`sliding_block_toml_with_tresca`] (20, all failing on main).
#[test]
fn sliding_block_toml_with_tresca_nitsche_and_penalty() {
    let runs = statuses(&sliding_block_tresca_text());
    assert_eq!(all_ok(&runs, |l| !l.starts_with("mixed")), 20);
}

/// The block of sweeps/sliding_block.toml's material thrown slowly (V = 0.05) on the flat plane
/// and an 18° incline with μ_f from `mus`, mixed with every mass and implicit scheme: a sweep.
fn sticking_block_text(mus: &str) -> String {
    format!(
        r#"name = "stick"
scene = "mesh2d"
[fixed]
mesh = "meshes/block2d.msh"
density = 1.0
lame_lambda = 10.0
lame_mu = 10.0
gravity = 0.1
gap = 0.0
velocity_tangential = 0.05
friction = "coulomb"
T = 3.0
dt = 0.05
space = "mixed"
[grid]
incline = [0.0, 18.0]
friction_coefficient = {mus}
mass = ["consistent", "lumped", "mod3"]
scheme = [
  {{ scheme = "crank-nicolson" }},
  {{ scheme = "backward-euler" }},
  {{ scheme = "kane" }},
  {{ scheme = "contact-stabilized-newmark" }},
  {{ scheme = "generalized-alpha", rho_inf = 0.5 }},
  {{ scheme = "hht", hht_alpha = 0.1 }},
  {{ scheme = "moreau-jean", restitution = 0.0 }},
]
"#
    )
}

/// Issue 43: a block with μ_f = 1–2 at low speed (on main: 5 of the 102 mixed runs here ended
/// `solver-failed`, mod3 with kane, Newmark/CN and backward Euler) — every run ends ok.
#[test]
fn block_with_mu_1_to_2_at_low_speed() {
    let runs = statuses(&sticking_block_text("[1.0, 1.5, 2.0]"));
    assert_eq!(all_ok(&runs, |_| true), 102);
}

/// Issue 43: at μ_f = 5 every method failed, most in their first step (on main: 29 of the 34
/// runs here `solver-failed`, 13 at step 1) — every run ends ok.
#[test]
fn block_with_mu_5() {
    let runs = statuses(&sticking_block_text("[5.0]"));
    assert_eq!(all_ok(&runs, |_| true), 34);
}

/// The scene and [fixed] keys of sweeps/sliding_block.toml's block resting on the plane, up to
/// its throw speed.
const BLOCK2D_KEYS: &str = "scene = \"mesh2d\"\n[fixed]\nmesh = \"meshes/block2d.msh\"\ndensity = 1.0\nlame_lambda = 10.0\nlame_mu = 10.0\ngravity = 0.1\ngap = 0.0\n";

/// The block of sweeps/sliding_block.toml thrown at V = 0.5 on the flat plane with Nitsche,
/// mod3 and backward Euler, μ_f = 0.9174 (rigid stop near t = 5.45): on main its frictional
/// Newton fails as the block stops (measured: step 116, t = 5.8, "did not converge in 100
/// iterations"). The mixed twin runs too.
#[test]
fn sliding_block_nitsche_mod3_backward_euler_at_its_stop() {
    let text = format!(
        r#"name = "stop"
{}velocity_tangential = 0.5
friction = "coulomb"
friction_coefficient = 0.9174
mass = "mod3"
scheme = "backward-euler"
T = 8.0
dt = 0.05
[grid]
space = [{{ space = "mixed" }}, {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3 }}]
"#,
        BLOCK2D_KEYS
    );
    assert_eq!(all_ok(&statuses(&text), |_| true), 2);
}

/// Issue 43's campaign: the quasi-static start of the massless Γ_C layer (mod3) failed for
/// Nitsche and penalty with μ_f 2.3–5 on the sticking blocks (15 of the campaign's runs: "the
/// quasi-static start: semismooth Newton did not converge in 100 iterations"; the sliding
/// points' −μ_f v̂ fold makes the start's W no P-matrix). The start now falls back to the
/// frictionless quasi-static state, as mixed's does: no run fails in its start, and every run
/// ends ok — the last one that did not (Nitsche γ0 = 1e-2, backward Euler, failing at step 2
/// in the time loop, neither the continuation nor Gauss–Seidel solving it) since the solve's
/// Lemke stage (robust43).
#[test]
fn sticking_block_mod3_start_with_mu_5() {
    let text = format!(
        r#"name = "start5"
{}velocity_tangential = 0.05
friction = "coulomb"
friction_coefficient = 5.0
mass = "mod3"
T = 0.5
dt = 0.05
[grid]
incline = [0.0, 18.0]
scheme = [{{ scheme = "crank-nicolson" }}, {{ scheme = "backward-euler" }}]
space = [
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-4 }},
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-2 }},
  {{ space = "penalty", penalty_gamma0 = 10.0 }},
  {{ space = "penalty", penalty_gamma0 = 1000.0 }},
]
"#,
        BLOCK2D_KEYS
    );
    let runs = statuses(&text);
    assert_eq!(runs.len(), 16);
    for (label, _, message, _) in &runs {
        let m = message.as_deref().unwrap_or("");
        assert!(!m.contains("quasi-static start"), "{label}: {m}");
    }
    let failed: Vec<&str> = runs
        .iter()
        .filter(|r| r.1 != Status::Ok)
        .map(|r| r.0.as_str())
        .collect();
    assert_eq!(failed, Vec::<&str>::new());
}

/// The P2 disc (sweeps/meshes/disc_p2.msh) thrown at 0.5 onto a 26° incline from gap 5,
/// Nitsche (Θ = 1, γ0 = 1e-3) + CN, μ_f = 0.86 (issue 43: failed at step 96 in the issue's
/// campaign; this reconstruction of its settings ran ok on main too — a guard), and mixed.
#[test]
fn p2_disc_on_a_26_degree_incline() {
    let text = r#"name = "disc26"
scene = "mesh2d"
[fixed]
mesh = "meshes/disc_p2.msh"
density = 1.0
lame_lambda = 20.0
lame_mu = 20.0
gravity = 0.1
gap = 5.0
velocity_tangential = 0.5
incline = 26.0
friction = "coulomb"
friction_coefficient = 0.86
scheme = "crank-nicolson"
T = 20.0
dt = 0.1
[grid]
space = [{ space = "mixed" }, { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3 }]
"#;
    assert_eq!(all_ok(&statuses(text), |_| true), 2);
}

/// A slow block (V = 0.01) on an 18° incline, penalty (γ0 = 10, 100, 1000) + HHT (α = 0.1),
/// μ_f = 0.61 (issue 43: failed at step 8 in the issue's campaign; these reconstructions of its
/// settings ran ok on main — a guard), and the mixed twin.
#[test]
fn slow_block_on_an_18_degree_incline_penalty_hht() {
    let text = r#"name = "slow18"
scene = "mesh2d"
[fixed]
mesh = "meshes/block2d.msh"
density = 1.0
lame_lambda = 10.0
lame_mu = 10.0
gravity = 0.1
gap = 0.0
velocity_tangential = 0.01
incline = 18.0
friction = "coulomb"
friction_coefficient = 0.61
scheme = "hht"
hht_alpha = 0.1
T = 2.0
dt = 0.05
[grid]
space = [
  { space = "mixed" },
  { space = "penalty", penalty_gamma0 = 10.0 },
  { space = "penalty", penalty_gamma0 = 100.0 },
  { space = "penalty", penalty_gamma0 = 1000.0 },
]
"#;
    assert_eq!(all_ok(&statuses(text), |_| true), 4);
}

/// Issue 43: Moreau–Jean θ = ½, e = 0 raises E + W_f on a block resting on the plane (thrown at
/// V = 0.05, μ_f = 0.3, consistent mass, τ = 0.2, T = 5). Siconos 4.4 (MoreauJeanOSI θ = ½,
/// NewtonImpactFrictionNSL e = 0, the 2D frictional contact problem by Lemke) on the same mesh
/// and setting (tests/siconos/block_moreau_jean.py, its own Q1 assembly) does the same: its
/// first step equals the engine's (E + W_f to 7e-15 energy scales measured; 1e-12 allows for
/// two assemblies' round-off), both first raise E + W_f at step 4, and Siconos' largest
/// one-step rise is 0.100 energy scales against the engine's 0.095. It is the method (the
/// index set's prediction y + ½τẏ ≤ 0 keeps a lifting node and its impulse adds energy; which
/// resting node is kept is decided by round-off in y, ẏ ~ 1e-19 — so the two trajectories part
/// at step 2 here; the same block landed from a gap of 0.003, where no decision hangs on
/// round-off, equals Siconos to 3.4e-12 at every step: tests/moreau_jean_siconos.rs).
#[test]
fn moreau_jean_resting_block_against_siconos() {
    let install = std::process::Command::new("bash")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/install_siconos.sh"))
        .status()
        .expect("bash");
    assert!(install.success(), "tests/install_siconos.sh failed");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("siconos.json");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/siconos/block_moreau_jean.py");
    let o = std::process::Command::new("/usr/bin/python3")
        .arg(&script)
        .args(["0.3", "0.05", "0.2", "5.0"])
        .arg(&out)
        .output()
        .expect("python3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let siconos: Vec<f64> = json["e_plus_wf"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let text = format!(
        "name = \"siconos\"\n{}\nspace = \"mixed\"\nmass = \"consistent\"\nscheme = \"moreau-jean\"\nrestitution = 0.0\n{}",
        block(2, 0.0, 0.05, 5.0, 0.2),
        Law::Coulomb(0.3).toml()
    );
    let o = run(&text).unwrap();
    assert_eq!(o.status, Status::Ok);
    let engine: Vec<f64> = o
        .series
        .rows()
        .map(|r| r.energy + r.friction_work.unwrap())
        .collect();
    assert_eq!(engine.len(), siconos.len());
    let scale = o.metrics.energy_scale.unwrap();
    assert!((engine[1] - siconos[1]).abs() <= 1e-12 * scale);
    let rise = |e: &[f64]| {
        e.windows(2)
            .map(|w| (w[1] - w[0]) / scale)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let first = |e: &[f64]| e.windows(2).position(|w| w[1] - w[0] > 1e-12 * scale);
    eprintln!(
        "largest rise: engine {:.4}, Siconos {:.4}",
        rise(&engine),
        rise(&siconos)
    );
    assert_eq!(first(&engine), Some(3));
    assert_eq!(first(&siconos), Some(3));
    // Both raise E + W_f in one step by about a fortieth of the block's weight work m·g·H (the
    // energy scale since issue 42 made it continuous, m·g·H + ½m|v⁰|²; measured 0.0023 and
    // 0.0024 of it — 0.0948 and 0.1004 of the former ½m·V_t²). The trajectories part at step 2,
    // so the figures agree in size, not in digits: both above 1e-3, against the frictionless
    // twin's 1e-14.
    assert!(rise(&engine) > 1e-3 && rise(&siconos) > 1e-3);
}

/// One of the campaign's cases (seed 43) that ended `solver-failed` before the solve's Lemke
/// stage (issue 43; [`ASSERT_POTENTIALS`]' note), run to `t_end` — a few steps past the one
/// that failed, at t_fail: it ends ok, and the fallback stages did work (the step that
/// failed needed them; the stage that solved it met the primary Newton's tolerance, which
/// `run/fe/nitsche.rs`' `lemke_stage_solves_the_campaign_steps` checks row by row on two of
/// these steps).
fn rescued_case(incline: f64, v: f64, t_end: f64, treatment: Treatment, method: &str, law: Law) {
    let case = Case {
        scene: "rescued",
        body: block(2, incline, v, t_end, 0.05),
        treatment,
        method: method.to_string(),
        law,
        sticks: None,
    };
    let o = run(&case.text(Some(law))).expect("planned");
    assert_eq!(o.status, Status::Ok, "{}: {:?}", case.label(), o.message);
    let fallback = o.metrics.friction_fallback_iterations.unwrap();
    eprintln!(
        "{}: iterations {} (most in a step {:?}), fallback {fallback}",
        case.label(),
        o.metrics.iterations,
        o.metrics.iterations_max_step
    );
    assert!(fallback > 0, "{}: no fallback", case.label());
}

/// block2d-flat-stick · Nitsche γ0 = 1e-4 · mod3 · backward Euler · μ_f = 4.5855 (failed at
/// step 13, t = 0.65).
#[test]
fn block2d_flat_stick_nitsche_mod3_backward_euler_mu_4_59() {
    rescued_case(
        0.0,
        0.05,
        0.85,
        Treatment::Nitsche,
        "mass = \"mod3\"\nscheme = \"backward-euler\"\nnitsche_theta = 1.0\nnitsche_gamma0 = 1e-4",
        Law::Coulomb(4.585503583845901),
    );
}

/// block2d-flat-stick · penalty γ0 = 1e3 · consistent · backward Euler · μ_f = 3.909 (failed at
/// step 10, t = 0.5).
#[test]
fn block2d_flat_stick_penalty_backward_euler_mu_3_91() {
    rescued_case(
        0.0,
        0.05,
        0.7,
        Treatment::Penalty,
        "mass = \"consistent\"\nscheme = \"backward-euler\"\npenalty_gamma0 = 1000.0",
        Law::Coulomb(3.90930989399961),
    );
}

/// block2d-incline18-stick · Nitsche γ0 = 1e-4 · consistent · backward Euler · μ_f = 4.153
/// (failed at step 35, t = 1.75).
#[test]
fn block2d_incline18_stick_nitsche_backward_euler_mu_4_15() {
    rescued_case(
        18.0,
        0.05,
        1.95,
        Treatment::Nitsche,
        "mass = \"consistent\"\nscheme = \"backward-euler\"\nnitsche_theta = 1.0\nnitsche_gamma0 = 1e-4",
        Law::Coulomb(4.153319265203933),
    );
}

/// block2d-incline18-stick · Nitsche γ0 = 1e-4 · consistent · generalized-α ρ∞ = ½ ·
/// μ_f = 3.417 (failed at step 72, t = 3.6).
#[test]
fn block2d_incline18_stick_nitsche_generalized_alpha_mu_3_42() {
    rescued_case(
        18.0,
        0.05,
        3.8,
        Treatment::Nitsche,
        "mass = \"consistent\"\nscheme = \"generalized-alpha\"\nrho_inf = 0.5\nnitsche_theta = 1.0\nnitsche_gamma0 = 1e-4",
        Law::Coulomb(3.4168924387253923),
    );
}

/// block2d-incline18-stick · Nitsche γ0 = 1e-4 · consistent · HHT α = 0.1 · μ_f = 4.181
/// (failed at step 60, t = 3.0).
#[test]
fn block2d_incline18_stick_nitsche_hht_mu_4_18() {
    rescued_case(
        18.0,
        0.05,
        3.2,
        Treatment::Nitsche,
        "mass = \"consistent\"\nscheme = \"hht\"\nhht_alpha = 0.1\nnitsche_theta = 1.0\nnitsche_gamma0 = 1e-4",
        Law::Coulomb(4.1808499399163646),
    );
}

/// block2d-tresca · Nitsche γ0 = 1e-4 · consistent · HHT α = 0.1 · Tresca s = 0.0479 (0.96 ×
/// the weight; failed at step 10, t = 0.5).
#[test]
fn block2d_tresca_nitsche_hht_s_0_048() {
    rescued_case(
        0.0,
        0.5,
        0.7,
        Treatment::Nitsche,
        "mass = \"consistent\"\nscheme = \"hht\"\nhht_alpha = 0.1\nnitsche_theta = 1.0\nnitsche_gamma0 = 1e-4",
        Law::Tresca(0.04791726831388534),
    );
}
