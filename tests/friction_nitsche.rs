//! Coulomb and Tresca friction with `space = "nitsche"` and `space = "penalty"` on the FE
//! scenes (issue 33; contract §1.8, §2.5): GetFEM's full-vector Nitsche form with friction.
//!
//! - μ_f = 0 / s = 0 give `none`'s numbers bit for bit with the penalty and Nitsche at Θ = 0;
//!   at Θ = 1 the full-vector frictionless form differs slightly (5.5e-4 energy scales
//!   measured on the thrown disc) and does no frictional work;
//! - friction does non-negative work per step on bar2d (Nitsche Θ = 0, 1; penalty);
//! - done-when 3: the engine equals GetFEM 5.4 (tests/getfem/disc_nitsche_friction.py, the
//!   GWFL form, GetFEM's Newton) on the P2 disc thrown obliquely, to 1e-8 (measured ~1e-11; the
//!   slip node by node, from the run's recorded displacements, 1e-10), with the same Gauss
//!   points in stick and in slip.
//!
//! The initial tangential velocity is set on the planned run's setup (`FeSetup.v0_tangential`)
//! through the library.

mod common;

use std::path::{Path, PathBuf};

use common::getfem::{disc_mesh, disc_sweep_with, floats, run_script};
use contact_sweep::run::{Outcome, RunConfig, RunContext};
use contact_sweep::space::fe::GmshMesh;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every run of the sweep `text` (as the file `path`) with its series, the initial tangential
/// velocity set on the run's setup (the disc thrown obliquely, contract §1.8), in the context `ctx`.
fn outcomes_with(path: &Path, text: &str, vt: f64, ctx: &RunContext) -> Vec<(String, Outcome)> {
    let thrown = |cfg: &mut RunConfig| {
        if let RunConfig::Fe(fe) = cfg {
            fe.setup.v0_tangential = vt;
        }
    };
    common::outcomes_edited(path, text, thrown, ctx)
}

fn disc(methods: &str, t_final: f64) -> String {
    disc_with(r#"scheme = "crank-nicolson""#, methods, t_final)
}

/// [`disc`] with the fixed line `scheme` (empty: each method sets its scheme).
fn disc_with(scheme: &str, methods: &str, t_final: f64) -> String {
    disc_sweep_with("disc-friction", scheme, methods, t_final)
}

/// A run's W_f series: how many steps report it, its last value and its smallest one-step
/// change (the steps' tangential work as f̄_t enters W_f).
fn work_series(o: &Outcome) -> (usize, f64, f64) {
    let w: Vec<f64> = o.series.rows().filter_map(|r| r.friction_work).collect();
    let min_inc = w.windows(2).fold(f64::INFINITY, |m, p| m.min(p[1] - p[0]));
    (w.len(), *w.last().expect("a frictional series"), min_inc)
}

/// GetFEM's run of the disc thrown obliquely (tests/getfem/disc_nitsche_friction.py): per
/// step the energy, ∫f_n, ∫f_t, ∫Δu_t, W_f, the body's mean tangential velocity 1ᵀMv_x/1ᵀM1_x,
/// the Γ_C mean of v_x (∫_ΓC v_x/∫_ΓC 1), the Gauss points of Γ_C in stick and in slip, the
/// displacement of each Γ_C node (at `contact_xy`); the body's mean normal velocity at T and
/// its mass.
struct Getfem {
    energy: Vec<f64>,
    force_n: Vec<f64>,
    force_t: Vec<f64>,
    slip: Vec<f64>,
    work: Vec<f64>,
    vt: Vec<f64>,
    vt_contact: Vec<f64>,
    vn_final: f64,
    stick_points: Vec<f64>,
    slip_points: Vec<f64>,
    contact_xy: Vec<[f64; 2]>,
    /// Per step, per Γ_C node (the order of `contact_xy`): (u_x, u_y).
    contact_u: Vec<Vec<[f64; 2]>>,
    mass: f64,
}

fn getfem_run(t_final: f64, vt: f64, mu: f64) -> Getfem {
    let args = [t_final, 0.1, 5.0, vt, mu, 1.0, 1e-3].map(|x| x.to_string());
    let v = run_script("disc_nitsche_friction.py", &args);
    let pair = |p: &serde_json::Value| -> [f64; 2] {
        let p = floats(p);
        [p[0], p[1]]
    };
    let pairs = |x: &serde_json::Value| -> Vec<[f64; 2]> {
        x.as_array().unwrap().iter().map(pair).collect()
    };
    Getfem {
        energy: floats(&v["energy"]),
        force_n: floats(&v["force_n"]),
        force_t: floats(&v["force_t"]),
        slip: floats(&v["slip"]),
        work: floats(&v["friction_work"]),
        vt: floats(&v["vt"]),
        vt_contact: floats(&v["vt_contact"]),
        vn_final: v["vn_final"].as_f64().unwrap(),
        stick_points: floats(&v["stick_points"]),
        slip_points: floats(&v["slip_points"]),
        contact_xy: pairs(&v["contact_xy"]),
        contact_u: v["contact_u"]
            .as_array()
            .unwrap()
            .iter()
            .map(pairs)
            .collect(),
        mass: v["body_mass"].as_f64().unwrap(),
    }
}

/// Done-when 3 of issue 33: the engine's Nitsche + Coulomb (Θ = 1, γ0 = 1e-3, μ_f = 0.3)
/// equals GetFEM's on the same Gmsh P2 disc thrown obliquely (gravity 0.1, gap 5, v⁰ = 0.5 e_1,
/// Crank–Nicolson, τ = 0.1), step by step through the first contact phase (steps 101..130, still
/// on at T = 13), to 1e-8:
/// - the energy, in units of energy_scale = m|f|·5 + ½m·V_t² ≈ 785: measured 1.2e-12;
/// - the normal and tangential contact forces, in units of the phase's largest normal force:
///   8.4e-12 and 1.0e-11;
/// - W_f, in units of energy_scale: 3.5e-13;
/// - the series' `v_t_contact`, the Γ_C mean of v_1 over the contact quadrature points
///   (Σ_q w_q v_1(x_q)/Σ_q w_q), against GetFEM's ∫_ΓC v_x/∫_ΓC 1 on the same face rule, every
///   step to T, in units of V: 2.3e-11;
/// - at T, `tangential_velocity_final` and `normal_velocity_final` against GetFEM's body means
///   1ᵀMv_x/1ᵀM1_x (0.43698) and 1ᵀMv_y/1ᵀM1_y (−0.98200), in units of V: 6.0e-12 and 1.1e-12;
/// - `friction_ratio_max`, max over the contact steps of |Σf_t|/Σf_n, against GetFEM's
///   max |∫f_t|/∫f_n: both μ_f = 0.3 (a step where every point in contact slides), 1.1e-16;
/// - the slip pointwise: Δu_t = u_1^{k} − u_1^{k−1} at each of Γ_C's 33 nodes (vertices and edge
///   midpoints, matched to GetFEM's by their coordinates) and each step k ≤ 130, in units of the
///   phase's largest |Δu_t| (0.119): 1.0e-10. Larger than the rest because Δu_t is a difference
///   of displacements ~6.5 (the body drifts V·T): 1.2e-11 absolute, 2e-12 of u.
///
/// Why 1e-8: the matrices agree to round-off in M and F and to ~1e-11 in the curved cells' K
/// (tests/getfem_disc.rs); both Newtons solve to ≤ 1e-11 of their right-hand sides; a contact
/// phase of ~30 steps amplifies that by no more than a few hundred.
///
/// Stick and slip: no Γ_C node sticks in either run (|Δu_t| ≤ 1e-12·h = 4.7e-12 at no node-step;
/// the smallest |Δu_t| in the phase is 4.4e-5, far from the threshold on both sides) — Nitsche's
/// stick is regularised (f_t = σ_t − Δu_t/(γτ) inside the cone) and decided at the Gauss points:
/// there, of the point-steps in contact, 74 stick (|p_t| ≤ μ_f f_n) and 249 slip in both runs,
/// exactly (contract §5's `stick_steps`/`slip_steps` against GetFEM's count).
#[test]
fn nitsche_coulomb_equals_getfem_on_the_thrown_p2_disc() {
    let (t_final, vt, mu) = (13.0, 0.5, 0.3);
    let gf = getfem_run(t_final, vt, mu);
    let text = disc(
        r#"{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, friction = "coulomb", friction_coefficient = 0.3 },"#,
        t_final,
    );
    // Every node's displacement at every step (stride 1 in space and time).
    let record = RunContext {
        reference: None,
        record_reference: Some((1, 1)),
    };
    let runs = outcomes_with(&root().join("t.toml"), &text, vt, &record);
    let (label, o) = &runs[0];
    let scale = o.metrics.energy_scale.unwrap();
    // m|f|·gap + ½m·V_t² (the thrown body's kinetic energy counts, tests/sliding_block.rs).
    let want = gf.mass * 0.5 + 0.5 * gf.mass * vt * vt;
    assert!(
        (scale - want).abs() <= 1e-12 * scale,
        "energy_scale {scale} against m|f|·5 + ½mV² with GetFEM's mass {}",
        gf.mass
    );
    let rows: Vec<_> = o.series.rows().collect();
    assert_eq!(rows.len(), gf.energy.len());
    // The first contact phase: from the first step with a force to the first without after it.
    let first = gf.force_n.iter().position(|&f| f > 0.0).expect("a contact");
    let end = first
        + gf.force_n[first..]
            .iter()
            .position(|&f| f == 0.0)
            .unwrap_or(gf.force_n.len() - 1 - first);
    assert!(
        end - first >= 10,
        "a contact phase of {} steps",
        end - first
    );
    let fmax = gf.force_n[first..end].iter().fold(0.0f64, |m, f| m.max(*f));
    let (mut e_err, mut fn_err, mut ft_err, mut w_err, mut v_err) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (k, r) in rows.iter().enumerate().take(end + 1) {
        e_err = e_err.max((r.energy - gf.energy[k]).abs() / scale);
        fn_err = fn_err.max((-r.sigma_contact - gf.force_n[k]).abs() / fmax);
        if k > 0 {
            ft_err = ft_err.max((r.sigma_t_contact.unwrap() - gf.force_t[k]).abs() / fmax);
            w_err = w_err.max((r.friction_work.unwrap() - gf.work[k]).abs() / scale);
            v_err = v_err.max((r.v_t_contact.unwrap() - gf.vt_contact[k]).abs() / vt);
        }
    }
    // The run's columns at T: the body's mean velocities 1ᵀMv/1ᵀM1 along e_1 and e_d, in units
    // of V; the apparent friction coefficient max_k |∫f_t|/∫f_n over GetFEM's contact steps.
    let m = &o.metrics;
    let vt_t = *gf.vt.last().unwrap();
    let vt_final_err = (m.tangential_velocity_final.unwrap() - vt_t).abs() / vt;
    let vn_final_err = (m.normal_velocity_final.unwrap() - gf.vn_final).abs() / vt;
    let ratio_gf = gf
        .force_n
        .iter()
        .zip(&gf.force_t)
        .filter(|(n, _)| **n > 0.0)
        .fold(0.0f64, |r, (n, t)| r.max(t.abs() / n));
    let ratio_err = (m.friction_ratio_max.unwrap() - ratio_gf).abs();
    eprintln!(
        "{label}: steps {first}..{end}, max normal force {fmax:.4}; errors energy {e_err:.2e}, f_n {fn_err:.2e}, f_t {ft_err:.2e}, W_f {w_err:.2e}, Γ_C mean v_t {v_err:.2e}; at T: v̄_t {vt_final_err:.2e}, v̄_d {vn_final_err:.2e} (GetFEM {:.6}, {:.6}); friction_ratio_max {:.6} against GetFEM's {ratio_gf:.6}: {ratio_err:.2e}",
        vt_t,
        gf.vn_final,
        m.friction_ratio_max.unwrap()
    );
    for (what, err) in [
        ("energy", e_err),
        ("normal force", fn_err),
        ("tangential force", ft_err),
        ("friction work", w_err),
        ("Γ_C mean tangential velocity", v_err),
        ("final mean tangential velocity", vt_final_err),
        ("final mean normal velocity", vn_final_err),
        ("friction_ratio_max", ratio_err),
    ] {
        assert!(
            err <= 1e-8,
            "{label}: {what} differs from GetFEM's by {err:.3e}"
        );
    }
    // Friction acts: the tangential force reaches a sizeable share of μ_f times the normal
    // one, the body slows down tangentially, and W_f grows.
    let ft_max = gf.force_t[first..end]
        .iter()
        .fold(0.0f64, |m, f| m.max(f.abs()));
    assert!(ft_max > 0.1 * mu * fmax, "{ft_max} against {fmax}");
    assert!(gf.vt[end] < vt - 1e-3 && gf.work[end] > 0.0);
    // GetFEM's slip in free flight is the rigid drift V τ over Γ_C (half the circumference
    // 20π of the P2 disc, to the curved cells' geometric error ~1e-5).
    let drift = vt * 0.1 * 20.0 * std::f64::consts::PI;
    assert!(
        (gf.slip[1] - drift).abs() < 1e-4 * drift,
        "{} vs {drift}",
        gf.slip[1]
    );
    compare_nodal_slip(label, o, &gf, first, end);
}

/// The slip node by node: Δu_t = u_1^k − u_1^{k−1} at every Γ_C node (vertices and edge
/// midpoints of the P2 faces) and step k ≤ `end`, the engine's recorded displacements against
/// GetFEM's, nodes matched by their coordinates in the file; and which nodes stick, which
/// Gauss points stick. See the test's doc comment for the figures.
fn compare_nodal_slip(label: &str, o: &Outcome, gf: &Getfem, first: usize, end: usize) {
    let mesh = GmshMesh::read(&disc_mesh()).expect("the committed P2 disc");
    let data = o.reference.as_ref().expect("the run recorded itself");
    let (n, d) = (mesh.coords.len(), 2);
    assert_eq!(data.lattice[0], n, "the record holds every node");
    assert_eq!(data.times, gf.contact_u.len(), "a record a step");
    let u = |k: usize, a: usize| data.u[k * n * d + a * d];
    // GetFEM's Γ_C (faces below the centre) is the engine's `contact` group: the same nodes,
    // each of GetFEM's at exactly one of the engine's (the file's coordinates, read by both).
    let contact = mesh.contact_nodes();
    assert_eq!(contact.len(), gf.contact_xy.len(), "Γ_C's nodes");
    let node: Vec<usize> = gf
        .contact_xy
        .iter()
        .map(|p| {
            let near: Vec<usize> = contact
                .iter()
                .copied()
                .filter(|&a| (mesh.coords[a][0] - p[0]).hypot(mesh.coords[a][1] - p[1]) < 1e-9)
                .collect();
            assert_eq!(
                near.len(),
                1,
                "GetFEM's Γ_C node {p:?}: engine nodes {near:?}"
            );
            near[0]
        })
        .collect();
    let mut sorted = node.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, contact, "a one-to-one match");

    let du_e = |k: usize, j: usize| u(k, node[j]) - u(k - 1, node[j]);
    let du_g = |k: usize, j: usize| gf.contact_u[k][j][0] - gf.contact_u[k - 1][j][0];
    let nodes = 0..node.len();
    let slip_max = (first..=end)
        .flat_map(|k| nodes.clone().map(move |j| du_g(k, j).abs()))
        .fold(0.0f64, f64::max);
    let mut err = 0.0f64;
    // Stick at a node: |Δu_t| ≤ 1e-12·h (contract §5's criterion). The counts are compared per step
    // over the node-steps where both sides are a factor 1e3 or more from the threshold (a
    // difference of 1e-8 of the largest slip could move a node across it otherwise).
    let thr = 1e-12 * mesh.h;
    let (mut stuck_e, mut stuck_g, mut unclear) = (0usize, 0usize, 0usize);
    let mut smallest = f64::INFINITY;
    for k in 1..=end {
        let (mut se, mut sg) = (0, 0);
        for j in nodes.clone() {
            let (e, g) = (du_e(k, j), du_g(k, j));
            err = err.max((e - g).abs() / slip_max);
            if k >= first {
                smallest = smallest.min(e.abs()).min(g.abs());
            }
            let (lo, hi) = (e.abs().min(g.abs()), e.abs().max(g.abs()));
            if lo > 1e3 * thr || hi < 1e-3 * thr {
                se += usize::from(e.abs() <= thr);
                sg += usize::from(g.abs() <= thr);
            } else {
                unclear += 1;
            }
        }
        assert_eq!(se, sg, "{label}: step {k}: Γ_C nodes in stick");
        stuck_e += se;
        stuck_g += sg;
    }
    // The Gauss points of Γ_C in contact (f_n > 0), in stick (|p_t| ≤ μ_f f_n) and in slip:
    // the engine counts them over the run, which ends inside the first contact phase. Equal
    // counts, exactly: in GetFEM's run the points in contact are ≥ 3e-4 from the cone's edge
    // (||p_t| − μ_f f_n|) and have f_n ≥ 1.7e-6, in units of the phase's largest ∫f_n (measured
    // with the script), where the two runs' tractions agree to ~1e-11.
    let sum = |x: &[f64]| x.iter().sum::<f64>() as i64;
    let (gp_stick, gp_slip) = (sum(&gf.stick_points), sum(&gf.slip_points));
    let (m_stick, m_slip) = (o.metrics.stick_steps, o.metrics.slip_steps);
    eprintln!(
        "{label}: Γ_C nodal slip Δu_t over steps 1..={end}: max |Δu_t| {slip_max:.4} in the phase, error {err:.2e} of it; smallest |Δu_t| in the phase {smallest:.2e} (threshold 1e-12·h = {thr:.1e}); node-steps in stick: engine {stuck_e}, GetFEM {stuck_g} (near the threshold, not compared: {unclear}); Gauss point-steps in stick/slip: engine {m_stick:?}/{m_slip:?}, GetFEM {gp_stick}/{gp_slip}"
    );
    assert!(
        err <= 1e-8,
        "{label}: nodal slip differs from GetFEM's by {err:.3e}"
    );
    assert_eq!(end, gf.force_n.len() - 1, "the phase lasts to T");
    assert_eq!(
        (m_stick, m_slip),
        (Some(gp_stick), Some(gp_slip)),
        "{label}"
    );
}

/// contract §2.5: μ_f = 0 (and s = 0) give the frictionless run's numbers bit for bit with the
/// penalty and with Nitsche at Θ = 0 (the frictionless engine solves them: `fe::frictional`);
/// with Θ ≠ 0 the frictional form at μ_f = 0 is the full-vector frictionless Nitsche (σ_t = 0
/// imposed weakly with its Θ term), which differs from `none`'s (σ_t = 0 natural) by a small
/// amount on the disc thrown obliquely — and does no frictional work at all (λ_t = 0 exactly).
#[test]
fn zero_friction_is_frictionless_except_the_full_vector_theta_term() {
    let m = |space: &str, law: &str| format!("{{ {space}{law} }},");
    let (nit0, pen, nit1) = (
        r#"space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-3"#,
        r#"space = "penalty", penalty_gamma0 = 100.0"#,
        r#"space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3"#,
    );
    let laws = [
        "",
        r#", friction = "coulomb", friction_coefficient = 0.0"#,
        r#", friction = "tresca", tresca_threshold = 0.0"#,
    ];
    let methods: String = [nit0, pen, nit1]
        .iter()
        .flat_map(|sp| laws.iter().map(move |l| m(sp, l)))
        .collect();
    let runs = outcomes_with(
        &root().join("t.toml"),
        &disc(&methods, 13.0),
        0.5,
        &RunContext::default(),
    );
    assert_eq!(runs.len(), 9);
    for group in runs.chunks(3) {
        let (l0, o0) = &group[0];
        let scale = o0.metrics.energy_scale.unwrap();
        assert!(
            o0.metrics.first_contact_time.is_some(),
            "{l0}: the disc lands"
        );
        for (l, o) in &group[1..] {
            if l0.contains("Θ=1") {
                // Full-vector form: close to `none`, not equal.
                let d = o
                    .series
                    .energy
                    .iter()
                    .zip(&o0.series.energy)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                    / scale;
                eprintln!("{l} against {l0}: max |ΔE|/scale = {d:.3e}");
                assert!(d > 1e-9 && d < 1e-2, "{l}: {d:.3e}");
                assert_eq!(o.metrics.friction_work, Some(0.0), "{l}");
            } else {
                assert_eq!(o.series.energy, o0.series.energy, "{l} against {l0}");
                assert_eq!(o.series.sigma_contact, o0.series.sigma_contact, "{l}");
            }
        }
    }
}

/// Friction does work on the bars (contract §1.8, §2.5): bar2d dropped with v⁰ = −½ e_d spreads
/// laterally on impact (Poisson), so Γ_C's points slide outwards against the friction. With
/// backward Euler (θ = 1, so f̄ = f^{n+1}) W_f's increments are the per-step tangential work
/// −Σ f_t^{n+1}·Δu_t, which contract §2.5 says is ≥ 0 for position-level methods: pointwise for
/// the penalty (f_t = proj(−κΔu_t)), summed over Γ_C for Nitsche. Checked per step to a
/// round-off allowance of 1e-12 of the run's final W_f, and W_f > 0 at the end.
#[test]
fn friction_does_nonnegative_work_on_the_bars() {
    let text = r#"
name = "bars-friction"
scene = "bar2d"
[fixed]
T = 1.5
h = 0.05
dt = 0.0125
scheme = "backward-euler"
[grid]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, friction = "coulomb", friction_coefficient = 0.3 },
  { space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 0.001, friction = "coulomb", friction_coefficient = 0.3 },
  { space = "penalty", penalty_gamma0 = 100.0, friction = "coulomb", friction_coefficient = 0.3 },
]
"#;
    let runs = common::outcomes(text);
    assert_eq!(runs.len(), 3);
    for (label, o) in &runs {
        let m = &o.metrics;
        let (_, last, min_inc) = work_series(o);
        eprintln!(
            "{label}: W_f {last:.4e} (relative {:?}), smallest step {min_inc:.3e}, stick {:?} slip {:?} ratio {:?} balance drift {:?} max rise {:?}",
            m.friction_work,
            m.stick_steps,
            m.slip_steps,
            m.friction_ratio_max,
            m.energy_balance_drift,
            m.energy_balance_max_increase
        );
        assert!(last > 0.0, "{label}: W_f = {last}");
        assert!(
            min_inc >= -1e-12 * last,
            "{label}: a step's tangential work {min_inc:.3e}"
        );
        // Contact point-steps were counted (at μ_f = 0.3 Nitsche's Γ_C sticks: its
        // regularised stick still moves, hence W_f > 0 from small Δu_t).
        assert!(
            m.stick_steps.unwrap() + m.slip_steps.unwrap() > 0,
            "{label}"
        );
        // |f_t| ≤ μ_f f_n (Coulomb) at every point in contact, to rounding.
        if label.contains("coulomb") {
            assert!(
                m.friction_ratio_max.unwrap() <= 0.3 * (1.0 + 1e-12),
                "{label}"
            );
        }
    }
}

/// The frictional Nitsche/penalty spaces of the generalized-α tests: Θ = 0, Θ = 1 (GetFEM's
/// γ0 = 1e-3) and the penalty.
const ALPHA_SPACES: [&str; 3] = [
    r#"space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 0.001"#,
    r#"space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001"#,
    r#"space = "penalty", penalty_gamma0 = 100.0"#,
];

/// contract §2.5 with generalized-α/HHT (issue 33): μ_f = 0 and s = 0 give the frictionless rows
/// bit for bit with the penalty and with Nitsche at Θ = 0 (the frictionless engine solves them,
/// `fe::frictional`), on the disc thrown obliquely through its first impact.
#[test]
fn zero_friction_is_frictionless_with_generalized_alpha() {
    let laws = [
        "",
        r#", friction = "coulomb", friction_coefficient = 0.0"#,
        r#", friction = "tresca", tresca_threshold = 0.0"#,
    ];
    let mut methods = String::new();
    for space in [ALPHA_SPACES[0], ALPHA_SPACES[2]] {
        for scheme in [
            r#"scheme = "hht", hht_alpha = 0.1"#,
            r#"scheme = "generalized-alpha", rho_inf = 0.5"#,
        ] {
            for law in laws {
                methods += &format!("{{ {space}, {scheme}{law} }},");
            }
        }
    }
    let runs = outcomes_with(
        &root().join("t.toml"),
        &disc_with("", &methods, 13.0),
        0.5,
        &RunContext::default(),
    );
    assert_eq!(runs.len(), 12);
    for group in runs.chunks(3) {
        let (l0, o0) = &group[0];
        assert!(
            o0.metrics.first_contact_time.is_some(),
            "{l0}: the disc lands"
        );
        for (l, o) in &group[1..] {
            assert_eq!(o.series.energy, o0.series.energy, "{l} against {l0}");
            assert_eq!(o.series.sigma_contact, o0.series.sigma_contact, "{l}");
            assert_eq!(o.series.u_contact, o0.series.u_contact, "{l}");
        }
    }
}

/// Generalized-α with ρ∞ = 1 (α_m = α_f = ½, β = ¼, γ = ½) is Crank–Nicolson with friction too
/// (fe_methods header): the same step matrix M + τ²/4 K_Θ with its tangential Θ rows, the same
/// right-hand side while the equation at tⁿ holds (it does at t = 0, and ½ of the equations at
/// tⁿ and t^{n+1} is the step's, so by induction at every step), the same frictional Newton with
/// c = τ²/4 and slip reference u_tⁿ, and f̄_t = ½(f_tⁿ + f_t^{n+1}) is CN's W_f weight. The runs
/// differ only by the arithmetic of the right-hand sides (M ũ − κ_m M aⁿ − κ_f K_Θ uⁿ + κ_f f_cⁿ
/// against M pⁿ), then amplified through the contact phases.
fn rho_one_equals_crank_nicolson(label: &str, runs: &[(String, Outcome)], tol: f64) {
    for pair in runs.chunks(2) {
        let ((lc, cn), (la, al)) = (&pair[0], &pair[1]);
        assert!(
            lc.contains("crank-nicolson") && la.contains("ρ∞"),
            "{lc} / {la}"
        );
        let scale = cn.metrics.energy_scale.unwrap();
        let max_diff = |a: &[f64], b: &[f64]| -> f64 {
            assert_eq!(a.len(), b.len());
            a.iter()
                .zip(b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        };
        let col = |o: &Outcome, f: fn(&contact_sweep::run::SeriesRow) -> Option<f64>| -> Vec<f64> {
            o.series.rows().map(|r| f(&r).unwrap_or(0.0)).collect()
        };
        let fmax = cn
            .series
            .sigma_contact
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        let e = max_diff(&cn.series.energy, &al.series.energy) / scale;
        let f = max_diff(&cn.series.sigma_contact, &al.series.sigma_contact) / fmax;
        let ft = max_diff(
            &col(cn, |r| r.sigma_t_contact),
            &col(al, |r| r.sigma_t_contact),
        ) / fmax;
        let w = max_diff(&col(cn, |r| r.friction_work), &col(al, |r| r.friction_work)) / scale;
        let wf = cn.metrics.friction_work.unwrap();
        eprintln!(
            "{label} {la} against {lc}: energy {e:.2e}, f_n {f:.2e}, f_t {ft:.2e}, W_f {w:.2e} (W_f {wf:.3e}; slip {:?}/{:?}, stick {:?}/{:?})",
            cn.metrics.slip_steps,
            al.metrics.slip_steps,
            cn.metrics.stick_steps,
            al.metrics.stick_steps
        );
        // CN's W_f can be negative (f̄ = ½(fⁿ + f^{n+1}), contract §2.5), not zero: friction acts.
        assert!(wf != 0.0, "{lc}: friction works");
        for (what, d) in [("energy", e), ("f_n", f), ("f_t", ft), ("W_f", w)] {
            assert!(d <= tol, "{label} {la}: {what} differs from CN by {d:.3e}");
        }
        assert_eq!(cn.metrics.slip_steps, al.metrics.slip_steps, "{la}");
        assert_eq!(cn.metrics.stick_steps, al.metrics.stick_steps, "{la}");
    }
}

/// The ρ∞ = 1 runs' distance from CN (energies and W_f over energy_scale, forces over the
/// largest normal force). Measured: bar2d (Coulomb 0.3, Tresca 0.01) ≤ 8.1e-10 (energy,
/// Nitsche Θ = 0 with Tresca), the disc ≤ 3.5e-9 (the penalty's f_n; Nitsche ≤ 1.2e-11); W_f
/// ≤ 2e-11 everywhere, and the same stick/slip point-steps. Rounding of the two right-hand
/// sides (1e-16 of M u, whose increments are far smaller) is amplified through ~50–300
/// contact point-steps of a stiff constraint (the penalty κ = E·100/h, Nitsche's 1/γ); 1e-7
/// leaves a factor 30 over the worst, while any difference in the scheme (f̄_t's weight, the
/// history term κ_f f_cⁿ, the tangential Θ rows of K_Θ) is a change of the discrete
/// solution, O(τ²) and not round-off.
const RHO_ONE_TOL: f64 = 1e-7;

/// [`ALPHA_SPACES`] and Nitsche's skew-symmetric Θ = −1 (its step matrix has +Σ w γ σ σᵀ).
fn cn_and_rho_one(law: &str) -> String {
    let skew = r#"space = "nitsche", nitsche_theta = -1.0, nitsche_gamma0 = 0.001"#;
    ALPHA_SPACES
        .iter()
        .chain([&skew])
        .flat_map(|sp| {
            [
                format!("{{ {sp}, scheme = \"crank-nicolson\"{law} }},\n"),
                format!("{{ {sp}, scheme = \"generalized-alpha\", rho_inf = 1.0{law} }},\n"),
            ]
        })
        .collect()
}

#[test]
fn generalized_alpha_rho_one_is_crank_nicolson_with_friction_on_bar2d() {
    for law in [
        r#", friction = "coulomb", friction_coefficient = 0.3"#,
        r#", friction = "tresca", tresca_threshold = 0.01"#,
    ] {
        let text = format!(
            r#"
name = "bars-friction-cn"
scene = "bar2d"
[fixed]
T = 1.5
h = 0.05
dt = 0.0125
[grid]
method = [
{}]
"#,
            cn_and_rho_one(law)
        );
        let runs = common::outcomes(&text);
        assert_eq!(runs.len(), 8);
        rho_one_equals_crank_nicolson("bar2d", &runs, RHO_ONE_TOL);
    }
}

#[test]
fn generalized_alpha_rho_one_is_crank_nicolson_on_the_thrown_disc() {
    let law = r#", friction = "coulomb", friction_coefficient = 0.3"#;
    let runs = outcomes_with(
        &root().join("t.toml"),
        &disc_with("", &cn_and_rho_one(law), 13.0),
        0.5,
        &RunContext::default(),
    );
    assert_eq!(runs.len(), 8);
    rho_one_equals_crank_nicolson("disc", &runs, RHO_ONE_TOL);
}

/// The allowance on a step's own tangential work −Σ f_t^{n+1}·Δu_t ≥ 0, relative to the run's
/// |W_f|: the tangential rows are solved to their round-off floor, which at stick on bar2d is
/// ~1e-7 of the traction (x_n = P_γ ≈ g quantises the penetration, run/fe/nitsche.rs's
/// `NEWTON_FLOOR_TOL`). Measured: −2.7e-10 energy scales against |W_f| = 2.3e-3 (ρ∞ = 0.5,
/// Θ = 0) and −1.9e-9 against 4.5e-2 (CN, Θ = 1): ≤ 1.2e-7 of |W_f|; 1e-6 leaves a factor 8.
/// The penalty's and backward Euler's minima are 0 exactly (measured).
const OWN_WORK_ALLOWANCE: f64 = 1e-6;

/// contract §2.5 with generalized-α/HHT and Nitsche/penalty (issue 33): on bar2d dropped with
/// v⁰ = −½ e_d (Γ_C slides outwards on impact, [`friction_does_nonnegative_work_on_the_bars`])
/// each step's own tangential work −Σ f_t^{n+1}·Δu_t is ≥ 0 (the law's sign; for Nitsche
/// summed over Γ_C), to [`OWN_WORK_ALLOWANCE`], |f_t| ≤ μ_f f_n, and the
/// rows are ok — ρ∞ = 0.5 with Nitsche Θ = 0 failed at step 65 before the frictional Newton
/// left the kinks it stalled on (run/fe/nitsche.rs). W_f itself is not monotone here: its increment
/// −Σ f̄_t·Δu_t weighs f_tⁿ by α_f, and where the traction turns within a step the mix has the
/// other sign (measured: HHT Θ = 0 loses 9.2e-6 of its final W_f 9.8e-5 in one step; ρ∞ = 0.5
/// Θ = 1 ends at W_f = −9.5e-4). Backward Euler (f̄ = f^{n+1}) has it monotone, above.
#[test]
fn friction_does_nonnegative_work_with_generalized_alpha() {
    let mut methods = String::new();
    for sp in ALPHA_SPACES {
        for scheme in [
            r#"scheme = "hht", hht_alpha = 0.1"#,
            r#"scheme = "generalized-alpha", rho_inf = 0.5"#,
        ] {
            methods += &format!(
                "{{ {sp}, {scheme}, friction = \"coulomb\", friction_coefficient = 0.3 }},\n"
            );
        }
    }
    let text = format!(
        r#"
name = "bars-friction-alpha"
scene = "bar2d"
[fixed]
T = 1.5
h = 0.05
dt = 0.0125
[grid]
method = [
{methods}]
"#
    );
    let runs = common::outcomes(&text);
    assert_eq!(runs.len(), 6);
    for (label, o) in &runs {
        let m = &o.metrics;
        let (steps, last, min_inc) = work_series(o);
        let ft_max = o
            .series
            .rows()
            .filter_map(|r| r.sigma_t_contact)
            .fold(0.0f64, |a, f| a.max(f.abs()));
        eprintln!(
            "{label}: W_f {:?}, smallest W_f step {min_inc:.3e}, own work min {:?}, max |Σf_t| {ft_max:.3e}, stick {:?} slip {:?} ratio {:?} balance drift {:?} max rise {:?}",
            m.friction_work,
            m.tangential_work_min,
            m.stick_steps,
            m.slip_steps,
            m.friction_ratio_max,
            m.energy_balance_drift,
            m.energy_balance_max_increase
        );
        // Every step, step 0's W_f⁰ = 0 included (issue 42: it was null for Nitsche).
        assert_eq!(steps, o.series.energy.len(), "{label}: W_f every step");
        assert!(ft_max > 0.0 && last != 0.0, "{label}: friction acts");
        assert!(
            m.tangential_work_min.unwrap() >= -OWN_WORK_ALLOWANCE * m.friction_work.unwrap().abs(),
            "{label}: a step's own tangential work {:?}",
            m.tangential_work_min
        );
        assert!(
            m.stick_steps.unwrap() > 0 && m.slip_steps.unwrap() > 0,
            "{label}"
        );
        assert!(
            m.friction_ratio_max.unwrap() <= 0.3 * (1.0 + 1e-12),
            "{label}"
        );
        assert!(m.energy_balance_drift.unwrap().is_finite(), "{label}");
        assert!(m.tangential_velocity_final.is_some(), "{label}");
    }
}

/// Regression (run/fe/nitsche.rs's frictional Newton, `NEWTON_FLOOR_TOL`): bar2d, Crank–Nicolson,
/// Nitsche Θ = 0 and 1 (γ0 = 1e-3), Coulomb 0.3 failed at step 32 (the impact) with "did not
/// converge in 100 iterations (residuals 3.6e-16 normal, 1.7e-11 tangential)": every point
/// stuck, x_n = P_γ ≈ g = 0.2 with a penetration of 1.8e-8, so one ulp of x_n moves a
/// tangential row (∂G_t/∂x_n ∝ k = 1/(γτ)) by ~1e-11 — above the tolerance 1e-12·0.16, and the
/// damped Newton's steps of 1e-17 could not lower it. Now accepted at that floor: the runs
/// end ok, and the accepted forces are those of the undamped solve to the floor (the GetFEM
/// comparison above, 1e-11, runs the same Newton).
#[test]
fn bar2d_stick_newton_stalls_at_its_floor() {
    let text = r#"
name = "bars-friction-floor"
scene = "bar2d"
[fixed]
T = 1.5
h = 0.05
dt = 0.0125
scheme = "crank-nicolson"
friction = "coulomb"
friction_coefficient = 0.3
[grid]
method = [
  { space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 0.001 },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001 },
]
"#;
    for (label, o) in common::outcomes(text) {
        let m = &o.metrics;
        eprintln!(
            "{label}: steps {}, Newton max {:?}, stick {:?} slip {:?}, own work min {:?}",
            m.steps, m.iterations_max_step, m.stick_steps, m.slip_steps, m.tangential_work_min
        );
        assert_eq!(m.steps, 120, "{label}");
        assert!(m.iterations_max_step.unwrap() < 100, "{label}");
        assert!(m.stick_steps.unwrap() > 0, "{label}");
        assert!(
            m.tangential_work_min.unwrap() >= -OWN_WORK_ALLOWANCE * m.friction_work.unwrap().abs(),
            "{label}"
        );
    }
}

/// Regression (run/fe/nitsche.rs's frictional Newton, the full step where no halving descends):
/// bar2d with the penalty (γ0 = 100) and Tresca failed at step 34 (backward Euler, s = 0.05:
/// "residuals 3.7e-3 normal, 4.4e-1 tangential") and at step 32 (Crank–Nicolson, s = 0.02,
/// 0.05, 0.1; Coulomb 0.3 too). At step 34 every point sat just below its gap (x_n = g − 3e-10,
/// Λ = 0) while x0 penetrates by 3.7e-3: the inactive Jacobian's step activates the stiff
/// penalty and raises the merit for every step length, so the damped Newton stayed on the kink
/// until the iteration cap. Now every run ends ok; with backward Euler (f̄ = f^{n+1}) W_f never
/// decreases, and no step's own tangential work is negative.
#[test]
fn bar2d_penalty_tresca_newton_leaves_the_gap_kink() {
    let text = r#"
name = "bars-penalty-tresca"
scene = "bar2d"
[fixed]
T = 1.5
h = 0.05
dt = 0.0125
space = "penalty"
penalty_gamma0 = 100.0
friction = "tresca"
[grid]
method = [
  { scheme = "backward-euler" },
  { scheme = "crank-nicolson" },
  { scheme = "hht", hht_alpha = 0.1 },
]
tresca_threshold = [0.02, 0.05, 0.1]
"#;
    let runs = common::outcomes(text);
    assert_eq!(runs.len(), 9);
    for (label, o) in &runs {
        let m = &o.metrics;
        let (_, last, min_inc) = work_series(o);
        eprintln!(
            "{label}: Newton max {:?}, W_f {last:.4e}, smallest W_f step {min_inc:.3e}, own work min {:?}, stick {:?} slip {:?}",
            m.iterations_max_step, m.tangential_work_min, m.stick_steps, m.slip_steps
        );
        assert_eq!(m.steps, 120, "{label}");
        assert!(
            m.slip_steps.unwrap() > 0 && last != 0.0,
            "{label}: friction acts"
        );
        assert!(m.tangential_work_min.unwrap() >= -1e-12, "{label}");
        if label.contains("backward-euler") {
            assert!(
                last > 0.0 && min_inc >= -1e-12 * last,
                "{label}: {min_inc:.3e}"
            );
        }
    }
}
