//! Benchmarks of the finite-element engine (contract §1.2, §4), reusing the bars of `scene::bar`.
//!
//! - `bar3d-20k/…`: the 3D bar at h = 0.0125 (9 × 9 × 81 nodes, 19 440 free dofs), mod3 mass,
//!   Crank–Nicolson with τ = h/2: the numeric factorisation of A = M + τ²/4 K, one solve with it
//!   (the two triangular solves alone), and one time step of the engine (solve, condensed contact,
//!   the product with M, energy) — measured on the engine's own clock over 64 steps of a run,
//!   set-up excluded. The step ÷ solve ratio is what the engine adds to the bare solves.
//! - `bar2d-82k/…`: the same for the h/32 reference of 000 Table 1 (65 × 641 nodes, 83 200
//!   dofs, τ = h/2/32).
//!
//! - `disc2d-q2-h4/…`, `sphere3d-q2-h8/…`: the paper's disc (Q2, h = 4: 1346 dofs) and ball
//!   (Q2, h = 8: 4503 dofs) of 003 §4.2 with the engine's choices for them (AMD; simplicial in
//!   2D, supernodal in 3D — `run::fe`'s `build_ball`): assembly of the pattern, K and M, the
//!   symbolic analysis, the numeric factorisation of A = M + τ²/4 K (τ = 0.1, consistent mass:
//!   mixed + CN; Nitsche's Θ-term adds rank-one updates inside the same pattern, so its factor
//!   costs the same), the condensation Z = A⁻¹C onto the contact unknowns (one solve per
//!   column: the Γ_C nodes for `mixed`, the Γ_C quadrature points for `nitsche`), and one solve.
//!   A whole step (the solve, the contact Newton/LCP, the energy) is measured per run over the
//!   paper's T = 40 by `sweeps/003_fig11_disc.toml` / `003_fig12_sphere.toml`
//!   (`stepping_time_s / steps` of the runs table).
//!
//! - `bar2d-methods/…` (issue 20, done-when 4): one step of each contract §3.2 method against
//!   Crank–Nicolson on bar2d at h = 0.00625 (17 × 161 nodes, 5 440 dofs, 17 contact dofs),
//!   consistent mass, τ = h/2, T = 1 (free flight, the impact at t = 0.4 and the contact
//!   phase): the engine's stepping time per step over the run, factor cached (as in a sweep),
//!   contact solves (CSN's predictor LCP included) and the energy observation in it. Kinematic
//!   central difference (lumped) at half its CFL step is listed for its own cost per step.
//!   `disc2d-methods/…`: the discrete gradient against CN with the same Nitsche (Θ = 1,
//!   γ0 = 1e-3) and the penalty on the paper's disc (P2, h = 4, τ = 0.1, T = 15: the impact at
//!   t ≈ 10).
//!
//! - `bar2d-friction/…` (issue 33, done-when 5): one step of mixed + Crank–Nicolson on bar2d at
//!   21 120 dofs (h = 0.1/32: 33 × 321 nodes, 33 contact nodes), consistent mass, τ = h/2,
//!   T = 1 (the impact at t = 0.4, then contact to the end), frictionless against Coulomb
//!   (μ_f = 0.3: the frictional contact solve over 66 unknowns and twice Z's columns) and
//!   Tresca; the engine's stepping time per step, factor cached. The target: frictional ÷
//!   frictionless ≤ 1.5.
//!
//! - `block3d-friction/…` (issue 43, done-when 3): one step of Nitsche (Θ = 1, γ0 = 1e-3), of
//!   the penalty (γ0 = 100) and of mixed + Crank–Nicolson on the 3D sliding block at 5 187 dofs
//!   (sweeps/meshes/block3d_5k.msh: 12 × 6 × 18 Q1 hexahedra, 648 contact quadrature points,
//!   91 Γ_C nodes), resting on the plane under gravity and thrown at V = 0.5, τ = 0.05, 10 steps
//!   (every point sliding; the block's bottom lifts off and lands again in steps 5–9),
//!   frictionless against Coulomb μ_f = 0.2: the engine's stepping time per step, factor
//!   cached, the contact iterations printed. The frictional Nitsche/penalty Newton has 3 × 648
//!   unknowns; its steps are made in the space of the m = 546 contact dofs (run/fe/schur.rs:
//!   S = R A⁻¹ Rᵀ once per run, GMRES preconditioned by a reused LU of the m × m Newton matrix,
//!   W Λ as P S C Λ). The targets: Nitsche/penalty frictional ÷ frictionless ≤ 1.5, mixed
//!   ≤ 1.3. Measured (session 29, two cores shared with builds, load ~7; medians): Nitsche
//!   76.8 ms frictionless, 73.7 ms Coulomb (57 Newton iterations over the 10 steps, at most 11):
//!   0.96×; penalty 70.3 ms, 87.96 ms (75 iterations, at most 16): 1.25× — both met (session 28,
//!   with a full-space sparse LU per Newton iteration: 25×). Mixed 6.68 ms, 13.57 ms (the
//!   Alart–Curnier Newton on 273 unknowns, 20 iterations, a dense LU each): 2.03×, not met.
//!   With chord steps on the kept LU while the node kinds repeat (`contact::coulomb`'s
//!   header; session 29, before/after binaries run alternately, load ~1.3): before 3.85 ms,
//!   9.35 ms (2.43×); after 3.89 ms, 6.86 ms (1.77×; 31 iterations, at most 4) — better, still
//!   not met: the rest is the fresh factors the chord steps do not avoid and Z's 273 columns.
//!   Session 30: a slipping node's two Newton rows in the frame (t, s), one tangential force
//!   eliminated (182 unknowns, not 273), on faer's blocked LU (`contact::coulomb`'s header):
//!   12.62 ms frictionless, 19.06 ms Coulomb (33 iterations, at most 4): 1.51× by the clock
//!   at load ~11; by perf's CPU samples in the stepping loop (150 steps each, same load) 647
//!   against 700, 1.08×: the frictional contact solve now costs what the LCP does (89 and 92
//!   samples), the rest is Z's 273 columns against 91 (72 and 178 samples), streamed from
//!   memory, which the load slows most. The clock's ratio wants a quiet machine: at load ~1
//!   (same session, after the builds), ten criterion runs of the two, alternating, gave
//!   per-run ratios 1.02–1.68 (the frictionless step alone ranges 2.8–4.8 ms between runs) with
//!   median 1.27×; the medians of the last six runs' medians, 4.17 ms and 5.39 ms, 1.29×.
//!
//! - `two-bodies-cost/…` (issue 44, done-when 7): one step of mixed + Crank–Nicolson, consistent
//!   mass, on two bodies against one body of the same size: `blocks2d` with W = 0.1 and
//!   H_a = H_b = ½ (the bar cut in two, 17 × 81 nodes each at h = 0.1/16: 5 508 dofs, 17
//!   node-to-node rows) against `bar2d` (0.1 × 1, 17 × 161 nodes less its clamped top: 5 440
//!   dofs, 17 obstacle rows), both falling at ½ over a gap of 0.2 (the impact at t = 0.4), T =
//!   0.6, τ = h/2: the engine's stepping time per step, factor cached. The target: two bodies ÷
//!   one ≤ 1.2.
//!
//! `cargo bench --bench fe`; compare medians within one run (`cargo bench --bench fe -- disc2d`
//! for one group).

use std::time::Duration;

mod common;

use criterion::{Criterion, criterion_group, criterion_main};

use common::{config, step_matrix};
use contact_sweep::run::fe::FeConfig;
use contact_sweep::run::{RunOptions, simulate};
use contact_sweep::scene::{Physics, Scene, SceneSetup};
use contact_sweep::space::cg::{CgOptions, CgWork, jacobi, pcg_into};
use contact_sweep::space::fe::nitsche::contact_points;
use contact_sweep::space::fe::{BallMesh, DofMap, ElementOp, SymMatrix, assemble, fe_pattern};
use contact_sweep::space::linalg::{
    Cholesky, CholeskyOptions, FactorKind, Ordering, SymbolicCholesky,
};
use contact_sweep::space::step_solver::Solver;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{NewmarkParams, Scheme};

fn bench_bar(c: &mut Criterion, name: &str, dim: usize, h: f64) {
    let mut g = c.benchmark_group(name);
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    let cfg = config(dim, h, 64);
    let (a, n, opts) = step_matrix(&cfg);
    let sym = SymbolicCholesky::with_options(&a.pattern, &opts).unwrap();
    g.bench_function("factorization", |b| {
        b.iter(|| Cholesky::new(&sym, &a).unwrap())
    });
    let chol = Cholesky::new(&sym, &a).unwrap();
    let mut work = chol.work();
    let mut x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
    g.bench_function("solve", |b| {
        b.iter(|| chol.solve_in_place(&mut x, &mut work))
    });
    // `solver = "cg"`: one product with A, by the engine's kernel (a row gather over the full
    // symmetric storage) and by faer's sparse × dense product on the same storage; and one
    // whole CG solve from a zero guess to 1e-12 (no warm start: an upper bound of a step's).
    let mut y = vec![0.0; n];
    g.bench_function("matvec", |b| b.iter(|| a.matvec_into(&x, &mut y)));
    let view = faer::sparse::SparseColMatRef::new(
        faer::sparse::SymbolicSparseColMatRef::new_checked(
            n,
            n,
            &a.pattern.col_ptr,
            None,
            &a.pattern.row_idx,
        ),
        &a.values,
    );
    g.bench_function("matvec-faer", |b| {
        b.iter(|| {
            faer::sparse::linalg::matmul::sparse_dense_matmul(
                faer::MatMut::from_column_major_slice_mut(&mut y, n, 1),
                faer::Accum::Replace,
                view,
                faer::MatRef::from_column_major_slice(&x, n, 1),
                1.0,
                faer::Par::Seq,
            )
        })
    });
    let inv = jacobi(&a).unwrap();
    let mut cg_work = CgWork::new(n);
    let rhs = x.clone();
    g.bench_function("cg-solve", |b| {
        b.iter(|| {
            y.fill(0.0);
            pcg_into(&a, &inv, &rhs, &mut y, CgOptions::new(1e-12), &mut cg_work).unwrap()
        })
    });
    // One step on the engine's own clock: the run's stepping time over its 64 steps.
    g.bench_function("step", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let out = simulate(
                    &contact_sweep::run::RunConfig::Fe(cfg.clone()),
                    &RunOptions {
                        series_every: 0,
                        ..RunOptions::default()
                    },
                );
                let per_step = out.metrics.stepping_time_s.unwrap() / cfg.steps as f64;
                total += Duration::from_secs_f64(per_step);
            }
            total
        })
    });
    g.finish();
}

/// The disc (dim 2) or ball (dim 3) of 003 §4.2 at degree 2 and nominal size h, as the engine
/// builds it for a run (contract §1.3: R = 20, λ = μ = 20, ρ = 1, centre R + 5 above the plane).
fn ball_operators(dim: usize, h: f64) -> (BallMesh, DofMap, SymMatrix, SymMatrix) {
    let (radius, lame) = (20.0, 20.0);
    let mut centre = [0.0; 3];
    centre[dim - 1] = radius + 5.0;
    let mesh = BallMesh::with_size(dim, 2, radius, centre, h).unwrap();
    let dofs = DofMap::all(mesh.coords.len() * dim);
    let p = fe_pattern(&mesh, &dofs);
    let k = assemble(
        &mesh,
        &dofs,
        &p,
        ElementOp::Stiffness {
            lambda: lame,
            mu: lame,
        },
        &|_| 1.0,
    );
    let m = assemble(&mesh, &dofs, &p, ElementOp::Mass { rho: 1.0 }, &|_| 1.0);
    (mesh, dofs, k, m)
}

fn bench_ball(c: &mut Criterion, name: &str, dim: usize, h: f64) {
    let mut g = c.benchmark_group(name);
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    g.bench_function("assembly", |b| b.iter(|| ball_operators(dim, h)));
    let (mesh, dofs, k, m) = ball_operators(dim, h);
    let tau = 0.1;
    let a = SymMatrix::lin_comb(1.0, &m, tau * tau / 4.0, &k);
    let n = dofs.n_free();
    // The engine's choice for the mapped meshes (`run::fe::build_ball`): no lattice to dissect.
    let opts = CholeskyOptions {
        ordering: Ordering::Amd,
        kind: if dim == 2 {
            FactorKind::Simplicial
        } else {
            FactorKind::Supernodal
        },
    };
    g.bench_function("symbolic", |b| {
        b.iter(|| SymbolicCholesky::with_options(&a.pattern, &opts).unwrap())
    });
    let sym = SymbolicCholesky::with_options(&a.pattern, &opts).unwrap();
    g.bench_function("factorization", |b| {
        b.iter(|| Cholesky::new(&sym, &a).unwrap())
    });
    let chol = Cholesky::new(&sym, &a).unwrap();
    // Condensation: one column per contact unknown (mixed: the vertical dofs of the Γ_C nodes;
    // nitsche: the Γ_C quadrature points), solved together as the engine does.
    let mixed = mesh.contact_nodes.len();
    let nitsche = contact_points(&mesh, 20.0, 20.0, 1.0).len();
    for (what, nc) in [("condense-mixed", mixed), ("condense-nitsche", nitsche)] {
        let z0: Vec<f64> = (0..n * nc).map(|i| ((i % 97) as f64).sin()).collect();
        let mut z = z0.clone();
        let mut work = chol.work_for(nc);
        g.bench_function(format!("{what}-{nc}"), |b| {
            b.iter(|| {
                z.copy_from_slice(&z0);
                chol.solve_many_in_place(&mut z, nc, &mut work)
            })
        });
    }
    let mut work = chol.work();
    let mut x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
    g.bench_function("solve", |b| {
        b.iter(|| chol.solve_in_place(&mut x, &mut work))
    });
    println!(
        "{name}: {n} dofs, nnz(A) {}, nnz(L) {}, contact unknowns mixed {mixed} / nitsche {nitsche}",
        a.pattern.nnz(),
        sym.factor_nnz()
    );
    g.finish();
}

/// The engine's stepping time per step of one run (set-up excluded, factors cached).
fn bench_steps(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    what: &str,
    cfg: &FeConfig,
) {
    let run = contact_sweep::run::RunConfig::Fe(cfg.clone());
    let opts = RunOptions {
        series_every: 0,
        ..RunOptions::default()
    };
    let warm = simulate(&run, &opts);
    assert_eq!(warm.status.as_str(), "ok", "{what}: {:?}", warm.message);
    // The contact solver's work, to read beside the time.
    eprintln!(
        "{what}: {} contact iterations over {} steps (at most {:?} in one step)",
        warm.metrics.iterations, warm.metrics.steps, warm.metrics.iterations_max_step
    );
    g.bench_function(what, |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let out = simulate(&run, &opts);
                let per_step = out.metrics.stepping_time_s.unwrap() / out.metrics.steps as f64;
                total += Duration::from_secs_f64(per_step);
            }
            total
        })
    });
}

fn bench_methods(c: &mut Criterion) {
    use contact_sweep::time::{GeneralizedAlphaParams, MoreauJeanParams};
    let mut g = c.benchmark_group("bar2d-methods");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    let h: f64 = 0.05 / 8.0;
    let dt = h / 2.0;
    let steps = (1.0 / dt).round() as usize;
    let mut base = config(2, h, steps);
    base.mass = MassVariant::Consistent;
    for (what, scheme) in [
        (
            "crank-nicolson",
            Scheme::Newmark(NewmarkParams::crank_nicolson()),
        ),
        ("kane", Scheme::Kane),
        (
            "contact-stabilized-newmark",
            Scheme::ContactStabilizedNewmark,
        ),
        (
            "generalized-alpha-0.5",
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::from_rho_inf(0.5)),
        ),
        (
            "hht-0.1",
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::hht(0.1)),
        ),
        (
            "moreau-jean",
            Scheme::MoreauJean(MoreauJeanParams::midpoint()),
        ),
    ] {
        let cfg = FeConfig {
            scheme,
            ..base.clone()
        };
        bench_steps(&mut g, what, &cfg);
    }
    let mut cd = FeConfig {
        mass: MassVariant::Lumped,
        scheme: Scheme::Newmark(NewmarkParams::central_difference()),
        ..base.clone()
    };
    let limit = cd.explicit_dt_limit().unwrap().unwrap();
    cd.dt = 0.5 * limit;
    cd.steps = (1.0 / cd.dt).round() as usize;
    bench_steps(&mut g, "central-difference-kinematic", &cd);
    g.finish();

    let mut g = c.benchmark_group("disc2d-methods");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    let scene = contact_sweep::scene::BallScene { dim: 2 };
    let physics = Physics(
        scene
            .physics()
            .iter()
            .map(|k| (k.name, k.default))
            .collect(),
    );
    let SceneSetup::Fe(setup) = scene.setup(&physics, scene.mesh_from_h(&physics, 4.0).unwrap())
    else {
        unreachable!("the disc is an FE scene")
    };
    for (space, method) in [
        (
            "nitsche",
            ContactMethod::Nitsche {
                theta: 1.0,
                gamma0: 1e-3,
            },
        ),
        ("penalty", ContactMethod::Penalty { gamma0: 20.0 }),
    ] {
        for (what, scheme) in [
            (
                "crank-nicolson",
                Scheme::Newmark(NewmarkParams::crank_nicolson()),
            ),
            ("discrete-gradient", Scheme::DiscreteGradient),
        ] {
            let cfg = FeConfig {
                setup: setup.clone(),
                method,
                mass: MassVariant::Consistent,
                scheme,
                dt: 0.1,
                steps: 150,
                perturbation: None,
                solver: Solver::Direct,
                friction: contact_sweep::contact::friction::FrictionLaw::None,
                contact_init: contact_sweep::space::ContactInit::Consistent,
            };
            bench_steps(&mut g, &format!("{space}-{what}"), &cfg);
        }
    }
    g.finish();
}

/// Issue 33's cost of friction per step (module header, `bar2d-friction`).
fn bench_friction(c: &mut Criterion) {
    use contact_sweep::contact::friction::FrictionLaw;
    let mut g = c.benchmark_group("bar2d-friction");
    g.sample_size(10).warm_up_time(Duration::from_millis(500));
    let h: f64 = 0.1 / 32.0;
    let dt = h / 2.0;
    let steps = (1.0 / dt).round() as usize;
    let mut base = config(2, h, steps);
    base.mass = MassVariant::Consistent;
    base.scheme = Scheme::Newmark(NewmarkParams::crank_nicolson());
    for (what, friction) in [
        ("none", FrictionLaw::None),
        ("coulomb-0.3", FrictionLaw::Coulomb { coefficient: 0.3 }),
        ("tresca-0.05", FrictionLaw::Tresca { threshold: 0.05 }),
    ] {
        let cfg = FeConfig {
            friction,
            ..base.clone()
        };
        bench_steps(&mut g, what, &cfg);
    }
    g.finish();
}

/// Issue 44's cost of a second body per step (module header, `two-bodies-cost`).
fn bench_two_bodies(c: &mut Criterion) {
    let mut g = c.benchmark_group("two-bodies-cost");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    let h = 0.1 / 16.0;
    let common = format!(
        "[fixed]\nT = 0.6\nh = {h:?}\ndt = {:?}\nspace = \"mixed\"\nmass = \"consistent\"\nscheme = \"crank-nicolson\"\ngap = 0.2\n",
        h / 2.0
    );
    for (what, scene, extra) in [
        ("one-body-bar2d", "bar2d", ""),
        (
            "two-bodies-blocks2d",
            "blocks2d",
            "width = 0.1\nheight = 0.5\nheight_b = 0.5\nlame_lambda = 0.25\nlame_mu = 0.5\nvelocity = -0.5\n",
        ),
    ] {
        let text = format!("name = \"{what}\"\nscene = \"{scene}\"\n{common}{extra}");
        let sweep =
            contact_sweep::sweep::SweepFile::parse(std::path::Path::new("cost.toml"), &text)
                .expect("valid sweep");
        let plan = contact_sweep::sweep::expand(&sweep).expect("plan");
        let contact_sweep::run::RunConfig::Fe(cfg) = &plan.runs[0].config else {
            unreachable!("an FE scene")
        };
        eprintln!("{what}: {} dofs", cfg.unknowns());
        bench_steps(&mut g, what, cfg);
    }
    g.finish();
}

/// Issue 43's cost of Nitsche/penalty friction per step in 3D (module header, `block3d-friction`).
fn bench_friction_3d(c: &mut Criterion) {
    let mut g = c.benchmark_group("block3d-friction");
    // The fewest samples criterion takes (55 runs of 10 steps each): mixed's 5-ms steps would
    // otherwise be repeated for its default 5 s of measured (stepping) time.
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(1));
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let text = r#"
name = "block3d-friction"
scene = "mesh3d"
[fixed]
mesh = "meshes/block3d_5k.msh"
density = 1.0
lame_lambda = 10.0
lame_mu = 10.0
gravity = 0.1
gap = 0.0
velocity_tangential = 0.5
T = 0.5
dt = 0.05
scheme = "crank-nicolson"
[grid]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3 },
  { space = "penalty", penalty_gamma0 = 100.0 },
  { space = "mixed" },
]
friction = [
  { friction = "none" },
  { friction = "coulomb", friction_coefficient = 0.2 },
]
"#;
    let path = root.join("sweeps/block3d-friction.toml");
    let sweep = contact_sweep::sweep::SweepFile::parse(&path, text).expect("valid sweep");
    let plan = contact_sweep::sweep::expand(&sweep).expect("plan");
    for spec in &plan.runs {
        let contact_sweep::run::RunConfig::Fe(cfg) = &spec.config else {
            unreachable!("the block is an FE scene")
        };
        let law = match cfg.friction {
            contact_sweep::contact::friction::FrictionLaw::None => "none",
            _ => "coulomb-0.2",
        };
        let what = format!("{}-{law}", cfg.method.name());
        bench_steps(&mut g, &what, cfg);
    }
    g.finish();
}

fn fe(c: &mut Criterion) {
    bench_two_bodies(c);
    bench_friction_3d(c);
    bench_friction(c);
    bench_methods(c);
    bench_ball(c, "disc2d-q2-h4", 2, 4.0);
    bench_ball(c, "sphere3d-q2-h8", 3, 8.0);
    bench_bar(c, "bar3d-20k", 3, 0.0125);
    bench_bar(c, "bar2d-82k", 2, 0.05 / 32.0);
}

criterion_group!(benches, fe);
criterion_main!(benches);
