//! No heap allocation inside a time loop (issue 12, target 3) — a count, not a time.
//!
//! A counting global allocator (global only in this test binary) counts the allocations the
//! current thread makes. A run with N steps and the same run with 2N steps (series off) do the
//! same setup and the same finishing work; only the time loop runs N more steps. Equal counts
//! mean the loop allocated nothing — not "little": a single allocation every 10⁴ steps shows
//! as a difference. Each case is run once before it is measured, so that the FE engine's
//! caches (geometry, factorisation) are filled and both measured runs take the same path.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

use contact_sweep::run::{RunOptions, Status, simulate};
use contact_sweep::sweep::{self, SweepFile};

struct Counting;

thread_local! {
    /// Allocations made by this thread (a thread-local, so tests running in parallel in this
    /// binary do not count each other's).
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    // try_with: the thread-local may already be gone while the thread is exiting.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to the system allocator; counting has no effect
// on the memory returned.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}

/// The plan of a sweep text with `T` substituted.
fn plan(text: &str, t_final: f64) -> sweep::Plan {
    let text = text.replace("T_FINAL", &format!("{t_final:?}"));
    let sf = SweepFile::parse(Path::new("alloc.toml"), &text).expect("a valid sweep");
    sweep::expand(&sf).expect("a valid plan")
}

/// For every run of the sweep: allocations of the run with T and with 2T must be equal.
fn assert_loop_allocates_nothing(text: &str, t_final: f64) {
    assert_loop_allocates_nothing_with(text, t_final, 2);
}

/// As [`assert_loop_allocates_nothing`], with the number of contact switches the short run
/// must show (1: it enters contact and stays — the disc under gravity).
fn assert_loop_allocates_nothing_with(text: &str, t_final: f64, min_switches: i64) {
    let (short, long) = (plan(text, t_final), plan(text, 2.0 * t_final));
    assert_eq!(short.runs.len(), long.runs.len());
    assert!(!short.runs.is_empty());
    let opts = RunOptions {
        series_every: 0,
        ..RunOptions::default()
    };
    for (a, b) in short.runs.iter().zip(&long.runs) {
        let out = simulate(&a.config, &opts); // warm the caches
        assert_eq!(out.status, Status::Ok, "{}: {:?}", a.label, out.message);
        let mut counts = [0u64; 2];
        let mut steps = [0i64; 2];
        // The FE caches (geometry, factors) are process-wide and this binary's other tests run
        // in parallel: one of them may evict this run's entries between the two measured runs,
        // and the second then rebuilds them (set-up allocations, seen once under load). Up to
        // five attempts; an allocation in the time loop differs at every one.
        for _attempt in 0..5 {
            for (k, spec) in [a, b].into_iter().enumerate() {
                let before = allocations();
                let out = simulate(&spec.config, &opts);
                counts[k] = allocations() - before;
                assert_eq!(out.status, Status::Ok, "{}: {:?}", spec.label, out.message);
                steps[k] = out.metrics.steps;
                drop(out);
            }
            if counts[0] == counts[1] {
                break;
            }
        }
        assert_eq!(steps[1], 2 * steps[0], "{}: steps {steps:?}", a.label);
        // The contact solve must have run in both states: the short run already switches
        // between contact and release, so its loop took every branch the long one takes.
        assert!(
            out.metrics.contact_switches >= min_switches,
            "{}: {} contact switches — the loop never left or entered contact",
            a.label,
            out.metrics.contact_switches
        );
        assert!(steps[0] >= 100, "{}: too few steps to show", a.label);
        // Control: the counter sees this thread's allocations (a run's setup allocates).
        assert!(counts[0] > 0, "{}: no allocation counted at all", a.label);
        assert_eq!(
            counts[0], counts[1],
            "{}: {} allocations for {} steps, {} for {} steps — the time loop allocates",
            a.label, counts[0], steps[0], counts[1], steps[1]
        );
    }
}

/// Every 1D scheme family with every contact treatment it runs with (and the massless
/// quasi-static contact node, whose rows take their own path), the methods of contract §3.2
/// included (kane, contact-stabilized Newmark's two solves, generalized-α/hht, Moreau–Jean, the
/// discrete gradient's Newton iteration, kinematic central difference with the lumped mass).
#[test]
fn bar1d_time_loops_allocate_nothing() {
    assert_loop_allocates_nothing(
        r#"
name = "alloc-1d"
scene = "bar1d"
[fixed]
T = T_FINAL
elements = 40
courant = 0.5
[grid]
method = [
  { space = "mixed", mass = "mod3", scheme = "crank-nicolson" },
  { space = "mixed", mass = "consistent", scheme = "crank-nicolson" },
  { space = "mixed", mass = "zero-contact", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 1e-3, scheme = "crank-nicolson" },
  { space = "mixed", mass = "mod3", scheme = "newmark", newmark_beta = 0.3, newmark_gamma = 0.6 },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "newmark-dissipative" },
  { space = "mixed", mass = "lumped", scheme = "central-difference" },
  { space = "mixed", mass = "mod3", scheme = "backward-euler" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "theta", theta_scheme = 0.7 },
  { space = "penalty", penalty_gamma0 = 1e-3, scheme = "backward-euler" },
  { space = "mixed", mass = "mod3", scheme = "paoli-schatzman" },
  { space = "mixed", mass = "mod3", scheme = "hybrid" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hybrid" },
  { space = "penalty", penalty_gamma0 = 1e-3, scheme = "hybrid" },
  { space = "mixed", scheme = "kane" },
  { space = "mixed", mass = "mod3", scheme = "kane" },
  { space = "mixed", scheme = "generalized-alpha", rho_inf = 0.5 },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "hht", hht_alpha = 0.1 },
  { space = "mixed", scheme = "moreau-jean", restitution = 0.5 },
  { space = "penalty", penalty_gamma0 = 1.0, scheme = "discrete-gradient" },
  { space = "nitsche", nitsche_gamma0 = 1e-6, scheme = "discrete-gradient" },
]
"#,
        3.0,
    );
}

/// The finite-element sweeps' text: `name`, `scene`, the [fixed] lines (T = T_FINAL first) and
/// the grid's `method` list.
fn fe_sweep(name: &str, scene: &str, fixed: &str, methods: &[&str]) -> String {
    let methods: String = methods.iter().map(|m| format!("  {m},\n")).collect();
    format!(
        "name = \"{name}\"\nscene = \"{scene}\"\n[fixed]\nT = T_FINAL\n{fixed}\n[grid]\nmethod = [\n{methods}]\n"
    )
}

/// The bars' set-up (bar2d: 3 × 21 nodes; bar3d: a 3 × 3 × 21-node box whose contact face has 9
/// nodes, so the contact problem has several unknowns and switches).
const BAR: &str = "h = 0.1\ndt = 0.01";
/// The disc under gravity (Q1, h = 8): inactive before the impact at t ≈ 2, then in contact
/// for good — one switch is all the short run can show.
const DISC: &str = "h = 8.0\ndt = 0.1\ngap = 0.05\ndegree = 1";

/// The FE engine on bar2d and bar3d: the modified masses with Crank–Nicolson and backward
/// Euler, the consistent mass with both.
#[test]
fn fe_time_loops_allocate_nothing() {
    for (scene, methods) in [
        (
            "bar2d",
            &[
                r#"{ mass = "mod3", scheme = "crank-nicolson" }"#,
                r#"{ mass = "consistent", scheme = "backward-euler" }"#,
            ][..],
        ),
        (
            "bar3d",
            &[
                r#"{ mass = "mod3", scheme = "crank-nicolson" }"#,
                r#"{ mass = "consistent", scheme = "crank-nicolson" }"#,
                r#"{ mass = "mod1", scheme = "backward-euler" }"#,
            ][..],
        ),
    ] {
        assert_loop_allocates_nothing(&fe_sweep("alloc-fe", scene, BAR, methods), 1.0);
    }
}

/// Friction on the FE scenes (contract §2.5, issue 33): mixed + Crank–Nicolson and backward Euler
/// with Coulomb and Tresca on bar2d and bar3d (3D: the disc's linearised projection) — the
/// frictional contact solve (semismooth Newton, its dense LU) and the friction tally, nothing
/// allocated.
#[test]
fn fe_frictional_time_loops_allocate_nothing() {
    for (scene, fixed) in [("bar2d", "h = 0.05\ndt = 0.01"), ("bar3d", BAR)] {
        let methods = [
            r#"{ mass = "consistent", scheme = "crank-nicolson", friction = "coulomb", friction_coefficient = 0.05 }"#,
            r#"{ mass = "mod3", scheme = "backward-euler", friction = "coulomb", friction_coefficient = 0.3 }"#,
            r#"{ mass = "consistent", scheme = "crank-nicolson", friction = "tresca", tresca_threshold = 0.05 }"#,
        ];
        assert_loop_allocates_nothing(&fe_sweep("alloc-fe-friction", scene, fixed, &methods), 1.0);
    }
}

/// `solver = "cg"` (issue 24): the step solves by conjugate gradient, warm-started from the
/// previous step's solution kept in the solver's work — bar3d with the LCP contact and the disc
/// with Nitsche's Newton (its step matrix with the Θ-term).
#[test]
fn cg_time_loops_allocate_nothing() {
    let bar = [
        r#"{ mass = "mod3", scheme = "crank-nicolson" }"#,
        r#"{ mass = "consistent", scheme = "backward-euler" }"#,
    ];
    let fixed = format!("{BAR}\nsolver = \"cg\"");
    assert_loop_allocates_nothing(&fe_sweep("alloc-cg-3d", "bar3d", &fixed, &bar), 1.0);
    let disc = [
        r#"{ space = "mixed", scheme = "crank-nicolson" }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.001, scheme = "hybrid" }"#,
    ];
    let fixed = format!("{DISC}\nsolver = \"cg\"");
    assert_loop_allocates_nothing_with(
        &fe_sweep("alloc-cg-disc", "disc2d", &fixed, &disc),
        15.0,
        1,
    );
}

/// The FE engine on the disc under gravity (issue 8): mixed + CN (chatters; also with the
/// zero-contact mass), Nitsche + CN, Nitsche + hybrid and penalty + hybrid (semismooth Newton).
#[test]
fn disc2d_time_loops_allocate_nothing() {
    let methods = [
        r#"{ space = "mixed", scheme = "crank-nicolson" }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.001, scheme = "crank-nicolson" }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.001, scheme = "hybrid" }"#,
        r#"{ space = "penalty", penalty_gamma0 = 20.0, scheme = "hybrid" }"#,
        r#"{ space = "mixed", mass = "zero-contact", scheme = "crank-nicolson" }"#,
    ];
    assert_loop_allocates_nothing_with(&fe_sweep("alloc-disc", "disc2d", DISC, &methods), 15.0, 1);
}

/// Two bodies (contract §1.10, issue 44): blocks2d and blocks3d with node-to-node rows —
/// mixed and penalty + Crank–Nicolson, mixed + backward Euler with a massless contact on B
/// alone (the quasi-static dofs), kane — and the two-body Gmsh file's copy of blocks2d's mesh
/// through the same engine data: the momentum tally, the rows' products and the refinement
/// allocate nothing per step.
#[test]
fn two_body_time_loops_allocate_nothing() {
    let methods = [
        r#"{ space = "mixed", scheme = "crank-nicolson" }"#,
        r#"{ space = "penalty", penalty_gamma0 = 10.0, scheme = "crank-nicolson" }"#,
        r#"{ space = "mixed", mass = "zero-contact", mass_side = "b", scheme = "backward-euler" }"#,
        r#"{ space = "mixed", scheme = "kane" }"#,
    ];
    let fixed = "h = 0.25\ndt = 0.01\nvelocity = -1.0\nvelocity_b = 0.5\ngap = 0.05";
    // Backward Euler's impact is plastic: the blocks touch and stay (one switch).
    for scene in ["blocks2d", "blocks3d"] {
        let text = fe_sweep("alloc-blocks", scene, fixed, &methods);
        assert_loop_allocates_nothing_with(&text, 1.0, 1);
    }
}

/// Non-matching blocks (issue 45, `mesh_ratio` 4/3: B round(16/3) = 5 elements across under A's 4): the
/// projecting pairings' rows — node-to-segment, mortar with the standard and the dual basis on
/// the segmentation, mortar with the `element` quadrature — with mixed and penalty +
/// Crank–Nicolson, mixed + backward Euler, on blocks2d and blocks3d: rows with more entries
/// than a node-to-node pair's go through the same products, nothing allocated per step.
#[test]
fn non_matching_time_loops_allocate_nothing() {
    let methods = [
        r#"{ space = "mixed", pairing = "node-to-segment", scheme = "crank-nicolson" }"#,
        r#"{ space = "mixed", pairing = "mortar", scheme = "crank-nicolson" }"#,
        r#"{ space = "mixed", pairing = "mortar", mortar_basis = "dual", scheme = "backward-euler" }"#,
        r#"{ space = "mixed", pairing = "mortar", interface_quadrature = "element", scheme = "crank-nicolson" }"#,
        r#"{ space = "penalty", penalty_gamma0 = 10.0, pairing = "mortar", scheme = "crank-nicolson" }"#,
        r#"{ space = "penalty", penalty_gamma0 = 10.0, pairing = "node-to-segment", scheme = "crank-nicolson" }"#,
    ];
    let fixed = "h = 0.25\nmesh_ratio = 1.3333333333333333\ndt = 0.01\nvelocity = -1.0\nvelocity_b = 0.5\ngap = 0.05";
    // Backward Euler's impact is plastic: the blocks touch and stay (one switch).
    for scene in ["blocks2d", "blocks3d"] {
        let text = fe_sweep("alloc-blocks-nonmatching", scene, fixed, &methods);
        assert_loop_allocates_nothing_with(&text, 1.0, 1);
    }
}

/// Friction with two-body Nitsche (issue 44): the pair points' slip rows through the one-body
/// frictional Newton and tally — unbiased with Crank–Nicolson (Coulomb), one-sided with
/// backward Euler (Tresca), generalized-α — on blocks2d and blocks3d, nothing allocated per
/// step.
#[test]
fn two_body_nitsche_friction_loops_allocate_nothing() {
    let methods = [
        r#"{ space = "nitsche", nitsche_gamma0 = 0.05, scheme = "crank-nicolson", friction = "coulomb", friction_coefficient = 0.3 }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.05, nitsche_sides = "a", nitsche_theta = -1.0, scheme = "backward-euler", friction = "tresca", tresca_threshold = 0.2 }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.05, scheme = "generalized-alpha", rho_inf = 0.5, friction = "coulomb", friction_coefficient = 2.0 }"#,
    ];
    let fixed = "h = 0.25\ndt = 0.01\nvelocity = -1.0\nvelocity_tangential = 0.5\nvelocity_b = 0.5\ngap = 0.05";
    for scene in ["blocks2d", "blocks3d"] {
        let text = fe_sweep("alloc-blocks-nitsche-friction", scene, fixed, &methods);
        assert_loop_allocates_nothing_with(&text, 1.0, 1);
    }
}

/// The FE engine's contract §3.2 methods (run::fe's methods module) on bar2d: kane with the
/// consistent and a massless contact mass, contact-stabilized Newmark's two LCPs (M⁻¹Bᵀ built
/// at setup), generalized-α/hht, Moreau–Jean's masked LCP, kinematic central difference.
#[test]
fn bar2d_comparison_methods_allocate_nothing() {
    let methods = [
        r#"{ mass = "consistent", scheme = "kane" }"#,
        r#"{ mass = "mod3", scheme = "kane" }"#,
        r#"{ mass = "consistent", scheme = "contact-stabilized-newmark" }"#,
        r#"{ mass = "lumped", scheme = "generalized-alpha", rho_inf = 0.5 }"#,
        r#"{ mass = "consistent", scheme = "hht", hht_alpha = 0.1 }"#,
        r#"{ mass = "consistent", scheme = "moreau-jean", restitution = 0.5 }"#,
        r#"{ mass = "lumped", scheme = "central-difference", dt = 0.002 }"#,
    ];
    assert_loop_allocates_nothing(&fe_sweep("alloc-fe-methods", "bar2d", BAR, &methods), 1.0);
}

/// Friction in the same methods (issue 33): the frictional condensation and the solver's
/// workspace are made at setup, the semismooth Newton reuses its buffers, the tally its
/// vectors; kane (Coulomb, the LU kept while the node states repeat), Moreau–Jean (Tresca,
/// the active mask), generalized-α (f_tⁿ in the right-hand side), kinematic central
/// difference's local projection — bar2d (d = 2) and bar3d (the disc's linearised
/// projection); and generalized-α/HHT with Nitsche (Θ = 0, 1) and the penalty, whose
/// frictional Newton and state (run/fe/nitsche.rs) are made at setup.
#[test]
fn frictional_comparison_methods_allocate_nothing() {
    let methods = [
        r#"{ mass = "consistent", scheme = "kane", friction = "coulomb", friction_coefficient = 0.05 }"#,
        r#"{ mass = "mod3", scheme = "kane", friction = "coulomb", friction_coefficient = 0.05 }"#,
        r#"{ mass = "consistent", scheme = "moreau-jean", friction = "tresca", tresca_threshold = 0.02 }"#,
        r#"{ mass = "lumped", scheme = "generalized-alpha", rho_inf = 0.5, friction = "coulomb", friction_coefficient = 0.05 }"#,
        r#"{ mass = "lumped", scheme = "central-difference", dt = 0.002, friction = "coulomb", friction_coefficient = 0.05 }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.001, scheme = "hht", hht_alpha = 0.1, friction = "coulomb", friction_coefficient = 0.3 }"#,
        r#"{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "generalized-alpha", rho_inf = 0.5, friction = "tresca", tresca_threshold = 0.02 }"#,
        r#"{ space = "penalty", penalty_gamma0 = 100.0, scheme = "generalized-alpha", rho_inf = 0.5, friction = "coulomb", friction_coefficient = 0.05 }"#,
    ];
    for (scene, fixed) in [("bar2d", "h = 0.05\ndt = 0.01"), ("bar3d", BAR)] {
        assert_loop_allocates_nothing(&fe_sweep("alloc-fe-friction", scene, fixed, &methods), 1.0);
    }
}

/// Nitsche and penalty friction in 3D with the Newmark family (issue 43): bar3d at h = 0.1
/// (36 contact points: the Newton's dense active block) and at h = 0.025 (144 points, 432
/// unknowns: from 384 active unknowns on, the Newton's step is made in the contact dofs' space,
/// run/fe/schur.rs — GMRES and K's dense LU in buffers sized at setup) — nothing allocated in
/// the time loop.
#[test]
fn nitsche_3d_frictional_time_loops_allocate_nothing() {
    let methods = [
        r#"{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "crank-nicolson", friction = "coulomb", friction_coefficient = 0.3 }"#,
        r#"{ space = "penalty", penalty_gamma0 = 100.0, scheme = "backward-euler", friction = "tresca", tresca_threshold = 0.02 }"#,
    ];
    for fixed in [BAR, "h = 0.025\ndt = 0.01"] {
        assert_loop_allocates_nothing(
            &fe_sweep("alloc-fe-friction", "bar3d", fixed, &methods),
            1.0,
        );
    }
}

/// The discrete gradient's condensed Newton on the disc (penalty, Nitsche Θ = 1), and
/// generalized-α/hht with Nitsche and the penalty (the engine's Newton, f_cⁿ carried).
#[test]
fn disc2d_comparison_methods_allocate_nothing() {
    let methods = [
        r#"{ space = "penalty", penalty_gamma0 = 20.0, scheme = "discrete-gradient" }"#,
        r#"{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "discrete-gradient" }"#,
        r#"{ space = "nitsche", nitsche_gamma0 = 0.001, scheme = "hht", hht_alpha = 0.1 }"#,
        r#"{ space = "penalty", penalty_gamma0 = 20.0, scheme = "generalized-alpha", rho_inf = 0.5 }"#,
    ];
    assert_loop_allocates_nothing_with(
        &fe_sweep("alloc-disc-dg", "disc2d", DISC, &methods),
        15.0,
        1,
    );
}

/// The oscillator (contract §1.5): every scheme family it runs, with both contact treatments —
/// the exact solution is built at setup and the contact starts go to a buffer sized there.
#[test]
fn oscillator_time_loops_allocate_nothing() {
    assert_loop_allocates_nothing(
        r#"
name = "alloc-osc"
scene = "oscillator"
[fixed]
T = T_FINAL
courant = 0.02
impact_law = 0.5
[grid]
method = [
  { space = "mixed", scheme = "crank-nicolson" },
  { space = "mixed", scheme = "backward-euler" },
  { space = "mixed", scheme = "paoli-schatzman", restitution = 0.5 },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "hybrid" },
  { space = "mixed", scheme = "kane" },
  { space = "mixed", scheme = "generalized-alpha", rho_inf = 0.5 },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "hht", hht_alpha = 0.1 },
  { space = "mixed", scheme = "moreau-jean", theta_scheme = 0.5, restitution = 0.5 },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "discrete-gradient" },
]
"#,
        5.0,
    );
    // contact-stabilized Newmark's contact is in its predictor (a clamp for one dof); its kane
    // step's multiplier is non-zero only when the net force pushes into the obstacle — with
    // f = 0 the spring pulls the mass off and the reported force stays 0 (no switch to count).
    // f = −2 (x_e = −2 below the obstacle) holds it there: one switch, into contact.
    assert_loop_allocates_nothing_with(
        r#"
name = "alloc-osc-csn"
scene = "oscillator"
[fixed]
T = T_FINAL
courant = 0.02
force = -2.0
impact_law = 0.5
space = "mixed"
scheme = "contact-stabilized-newmark"
"#,
        5.0,
        1,
    );
}

/// The frictional layer (contract §1.7, issue 32): every method that defines friction, stick and
/// slip, Coulomb and Tresca — two chains and the friction law's local solve per step,
/// nothing allocated.
#[test]
fn layer1d_frictional_time_loops_allocate_nothing() {
    assert_loop_allocates_nothing(
        r#"
name = "alloc-layer"
scene = "layer1d"
[fixed]
T = T_FINAL
elements = 40
courant = 0.5
velocity_tangential = 1.0
[grid]
law = [
  { friction = "coulomb", friction_coefficient = 0.1 },
  { friction = "coulomb", friction_coefficient = 2.0 },
  { friction = "tresca", tresca_threshold = 0.3 },
]
method = [
  { space = "mixed", mass = "zero-contact", scheme = "crank-nicolson" },
  { space = "mixed", mass = "consistent", scheme = "theta", theta_scheme = 0.7 },
  { space = "mixed", mass = "lumped", scheme = "central-difference" },
  { space = "mixed", scheme = "kane" },
  { space = "mixed", scheme = "contact-stabilized-newmark" },
  { space = "mixed", scheme = "generalized-alpha", rho_inf = 0.5 },
  { space = "mixed", scheme = "moreau-jean" },
  { space = "penalty", penalty_gamma0 = 10.0, scheme = "crank-nicolson" },
]
"#,
        1.25,
    );
}

/// The dry-friction oscillator (contract §1.5, `friction_force`): the relay of every scheme that
/// takes it, with impacts (the obstacle in reach: the relay combined with the contact) and with
/// a stop (the contract's setting, the mass at rest after t ≈ 22.4) — the exact solution's segments
/// are built at setup, the stop watch and the work are scalars.
#[test]
fn dry_friction_oscillator_time_loops_allocate_nothing() {
    assert_loop_allocates_nothing(
        r#"
name = "alloc-osc-dry"
scene = "oscillator"
[fixed]
T = T_FINAL
courant = 0.02
impact_law = 0.5
friction_force = 0.1
[grid]
method = [
  { space = "mixed", scheme = "crank-nicolson" },
  { space = "mixed", scheme = "backward-euler" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "crank-nicolson" },
  { space = "mixed", scheme = "kane" },
  { space = "mixed", scheme = "generalized-alpha", rho_inf = 0.5 },
  { space = "mixed", scheme = "moreau-jean", theta_scheme = 0.5, restitution = 0.5 },
]
"#,
        5.0,
    );
    // Contact-stabilized Newmark reports contact only where the net force holds the mass on
    // the obstacle (as in `oscillator_time_loops_allocate_nothing`): f = −2, one switch.
    assert_loop_allocates_nothing_with(
        r#"
name = "alloc-osc-dry-csn"
scene = "oscillator"
[fixed]
T = T_FINAL
courant = 0.02
force = -2.0
impact_law = 0.5
friction_force = 0.1
space = "mixed"
scheme = "contact-stabilized-newmark"
"#,
        5.0,
        1,
    );
    // No contact at all here (the obstacle 1e3 away): no switch to count.
    assert_loop_allocates_nothing_with(
        r#"
name = "alloc-osc-stop"
scene = "oscillator"
[fixed]
T = T_FINAL
dt = 0.02
amplitude = 12.0
velocity = 6.0
gap = 1e3
friction_force = 1.0
scheme = "moreau-jean"
"#,
        15.0,
        0,
    );
}
