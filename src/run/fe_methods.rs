//! The methods of the comparison literature (SPEC §3.2) in the sparse finite-element engine:
//! `kane`, `contact-stabilized-newmark`, `moreau-jean` with the nodal multiplier (`mixed`),
//! `generalized-alpha`/`hht` with `mixed`, `nitsche` and `penalty`, the `discrete-gradient`
//! with `penalty` and `nitsche` (Θ = 1), and `central-difference` with `mixed` and the lumped
//! mass (kinematic contact).
//!
//! The 1D engine ([`crate::run::bar1d`]) holds the verified step formulas; here they act on the
//! FE system M ü + K u = F + Bᵀλ, B the vertical dofs of the Γ_C nodes, B u + g ≥ 0, λ ≥ 0.
//! Every implicit step has a constant matrix A = M + cK, factored once per run through the
//! engine's shared cache (its key is (geometry, mass, contact method, c), so a run shares the
//! factor of every other run with the same matrix — kane, CSN and the discrete gradient use
//! Crank–Nicolson's S = M + τ²/4 K, generalized-α with ρ∞ = 1 too), with Z = A⁻¹Bᵀ and
//! H = c B Z condensed once. A step is one sparse solve y = A⁻¹b, a contact problem on the
//! contact set only, and the correction y + c Z μ: the LCP's μ is the contact force scaled by
//! the method's coefficient c_f/c of Bᵀλ in the right-hand side:
//! - `kane`: S Δu = τMvⁿ − τ²/2 Kuⁿ + τ²/2 F + τ²/2 Bᵀλ, v^{n+1} = 2Δu/τ − vⁿ (c_f = 2c, λ = μ/2).
//!   A massless row (mod1/…/zero-contact) is K u^{n+½} = Bᵀλ: quasi-static at the midpoint, as
//!   in 1D; its velocity is the difference quotient Δu/τ (it carries no energy);
//! - `contact-stabilized-newmark`: the predictor u^pred = ũ + M⁻¹Bᵀν, ũ = uⁿ + τvⁿ, with
//!   0 ≤ ν ⊥ Bũ + g + (BM⁻¹Bᵀ)ν ≥ 0 (the M-projection of the free flight), M⁻¹Bᵀ from a sparse
//!   Cholesky of M computed once per (geometry, mass) and cached like the step factors; then
//!   S Δ = −τ²/4 K(uⁿ + u^pred) + τ²/2 F + τ²/2 Bᵀλ, u^{n+1} = u^pred + Δ, v^{n+1} = vⁿ + 2Δ/τ;
//! - `generalized-alpha`: ũ = uⁿ + τvⁿ + τ²(½ − β)aⁿ, and the equation at t^{n+1−α} times
//!   βτ²/(1−α_m): (M + cK)u^{n+1} = M(ũ − κ_m aⁿ) − κ_f K uⁿ + κ_f Bᵀλⁿ + (c + κ_f)F + c Bᵀλ^{n+1}
//!   ([`crate::time::GeneralizedAlphaParams::history_coefficients`]; c_f = c, λ = μ), Newmark's
//!   updates. With ρ∞ = 1 the right-hand side is Crank–Nicolson's whenever M aⁿ = F − Kuⁿ + Bᵀλⁿ
//!   (its equation at tⁿ), and the matrix is the same: the runs agree to round-off;
//! - `moreau-jean`: (M + θ²τ²K)Δv = −τK(uⁿ + θτvⁿ) + τF + Bᵀp, the rows with
//!   (Buⁿ + g) + ½τBvⁿ ≤ 0 active ([`crate::contact::Lcp::solve_on`]), there
//!   0 ≤ p ⊥ Bv^{n+1} + eBvⁿ ≥ 0 (c_f = 1, p = cμ); u^{n+1} = uⁿ + τ(vⁿ + θΔv), reported
//!   force p/τ;
//! - `discrete-gradient` (penalty; Nitsche with Θ = 1, whose linear part K_Θ = K − Σ wγ s sᵀ is in
//!   A as for the hybrid scheme): the midpoint rule (M + τ²/4 K_Θ)Δu = τMvⁿ − τ²/2 K_Θuⁿ + τ²/2 F
//!   − τ²/2 Σ_q D_q p_q with D_q = w_q (φ_q(s_q^{n+1}) − φ_q(s_qⁿ))/(s_q^{n+1} − s_qⁿ),
//!   φ_q(s) = (1/2γ_q)[s − g_q]_+², s_q = p_q·u. Condensed on the points: s = s⁰ + τ²/2 W D(s),
//!   s⁰ = P(uⁿ + A⁻¹b), W = P A⁻¹C (C = −P, the same rows as the hybrid scheme's), solved by
//!   semismooth Newton with each point's scalar difference quotient and its slope
//!   ([`crate::contact::gradient`]) — D_q depends on s_q only, so the Jacobian is
//!   I − τ²/2 W diag(D'_q) on the points with D_q or D'_q ≠ 0. Since Φ(s^{n+1}) − Φ(sⁿ) =
//!   Σ D_q(s_q^{n+1} − s_qⁿ) the midpoint rule conserves E^h + Φ (penalty) and E_Θ (Θ = 1);
//! - kinematic `central-difference` (lumped M, diagonal): v^{n+½} = vⁿ + τ/2 aⁿ,
//!   u^{n+1} = uⁿ + τv^{n+½}, a contact dof below the obstacle put on it by the impulse
//!   Δv = (−g − u)/τ on v^{n+½} (λ = m Δv/τ), a^{n+1} = M⁻¹(F − Ku^{n+1}),
//!   v^{n+1} = v^{n+½} + τ/2 a^{n+1}: no solve at all. Its CFL limit τω_max ≤ 2 uses a
//!   certified upper bound of ω²_max = λ_max(M⁻¹K): a power-iteration estimate raised until
//!   σM − K factors ([`kinematic_dt_limit`]), within 1 % of the true value.
//!
//! Generalized-α with Nitsche/penalty (disc/ball): the linear part K_Θ (Nitsche's Θ-term) sits in
//! A as for the engine's Newmark steps, the contact force is f_c(u) = Σ_q φ_q(p_q·u) C_q with
//! f_cⁿ = f_c(uⁿ) (the previous step's Newton values) and f_c^{n+1} solved by the engine's
//! semismooth Newton with coefficient c ([`super::fe_nitsche`]). With friction (SPEC §2.5,
//! issue 33) the same with the engine's frictional operators and Newton: K_Θ in A holds the
//! tangential Θ rows −Θ Σ w γ σ_t σ_tᵀ too (the history term −κ_f K_Θ uⁿ and M u^{n+1} =
//! A u^{n+1} − cK_Θ u^{n+1} use them), f_c(u) = Σ_j λ_j C_j over the d unknowns per point
//! (C's tangential columns u_t − Θγσ_t), f_cⁿ the previous step's λ (normal and tangential),
//! and f_c^{n+1} from [`super::fe_nitsche`]'s frictional Newton with coefficient c, its x0 =
//! P y + k u_tⁿ (the slip (u_t^{n+1} − u_tⁿ)/τ, position level) and its state (u_tⁿ, the
//! tally). W_f uses f̄_t = (1 − α_f) f_t^{n+1} + α_f f_tⁿ, the weight of f_t^{n+1} in the
//! equation at t^{n+1−α_f}. With ρ∞ = 1 (α_m = α_f = ½) this is the frictional
//! Crank–Nicolson of the engine: the same matrix, the same right-hand side while the equation
//! at tⁿ holds, c = τ²/4 and f̄_t = ½(f_tⁿ + f_t^{n+1}) (tests/friction_nitsche.rs: ≤ 3.5e-9).
//!
//! The energy E^h = ½vᵀMv + ½uᵀKu − Fᵀu needs Mv and Ku (the schemes whose equation does not
//! hold at t^{n+1} cannot use Newmark's identity uᵀKu = uᵀ(F + Bᵀλ − Ma)); they are the next
//! step's right-hand side too. They are carried: a step computes one product, KΔ (Δ its
//! increment), and takes MΔ = AΔ − cKΔ from the system it just solved (AΔ its right-hand side
//! plus the contact term) — a subtraction without division by c, so no round-off is amplified.
//! Contact-stabilized Newmark and Moreau–Jean carry Kv as well (their right-hand sides need
//! K u^pred = Kuⁿ + τKvⁿ + KM⁻¹Bᵀν and K(uⁿ + θτvⁿ)). So a step costs the solve and one sparse
//! product, as Crank–Nicolson's does (measured: `benches/fe.rs`, `bar2d-methods`). Every 64
//! steps the products are recomputed from the state. Nothing is allocated in the time loop.
//!
//! Friction (SPEC §2.5, `space = "mixed"`; issue 33). The contact rows grow from B (the
//! vertical dof of each Γ_C node, normal force λ = f_n ≥ 0 on the body) to C = [B; T], T the
//! node's e_1 (and e_2) dofs carrying the tangential force f_t on the body: the force term
//! Bᵀλ of every step above becomes Cᵀr, r = (f_n, f_t) per node, and the condensation
//! Z = A⁻¹Cᵀ, H = cCZ covers the tangential columns (the frictional factor). A step is still
//! y = A⁻¹b, one contact problem on the contact set, and y + cZμ with μ = (c_f/c) r; the
//! problem is the Coulomb (or Tresca) law on the pair
//!
//!   gap = q_n + (Hμ)_n ≥ 0 ⊥ μ_n ≥ 0,   slip = q_t + (Hμ)_t,   |μ_t| ≤ b, μ_t = −b·slip/|slip|,
//!
//! solved by the semismooth Newton method of [`crate::contact::coulomb`] (the Coulomb disc in
//! 3D). Coulomb's bound b = μ_f μ_n is scale free; Tresca's s·w_j (w_j = ∫_ΓC φ_j, a force) is
//! multiplied by c_f/c, and by τ where the unknown is an impulse. Per method (the slip is the
//! scheme's, SPEC §2.5; f̄_t is the tangential force as it enters the momentum equation over
//! the step, which W_f^{n+1} = W_f^n − Σ_j f̄_t,j·(u_t,j^{n+1} − u_t,j^n) uses):
//! - `kane`: q_n = Buⁿ + g + By, q_t = Ty (slip = u_t^{n+1} − u_tⁿ = TΔu), μ = 2(λ, f_t)^{n+1},
//!   f̄_t = f_t^{n+1}. The trapezoidal rule gives ΔE = Δuᵀ Cᵀr exactly (massless rows included:
//!   their row is K u^{n+½} = F + Cᵀr), so Δ(E + W_f) = λ·BΔu = −λ·(Buⁿ + g) ≤ 0: the normal
//!   force does no positive work and friction's work is all in W_f;
//! - `contact-stabilized-newmark`: the predictor is frictionless (the M-projection onto the
//!   admissible set constrains the normal rows only); the corrector is `kane`'s with
//!   q_n = Bu^pred + g + By, q_t = T(u^pred − uⁿ) + Ty, μ = 2(λ, f_t)^{n+1}, f̄_t = f_t^{n+1};
//! - `generalized-alpha`/`hht`: q_n = By + g, q_t = Ty − Tuⁿ, μ = r^{n+1}; the force of the
//!   previous step enters the right-hand side as κ_f Cᵀrⁿ (tangential rows included), so
//!   f̄_t = (1 − α_f) f_t^{n+1} + α_f f_tⁿ;
//! - `moreau-jean`: De Saxcé's law per node on the velocity-level problem, over the nodes with
//!   (Buⁿ + g) + ½τBvⁿ ≤ 0 only (the solver's active mask; the others carry no impulse):
//!   "gap" = Bv^{n+1} + eBvⁿ, q_n = (1 + e)Bvⁿ + By; "slip" = v_t^{n+1}, q_t = Tvⁿ + Ty; the
//!   impulses p = cμ, reported forces p/τ, Tresca's bound s·w_j·τ. f̄_t = p_t/τ, so
//!   −f̄_t·Δu_t = −p_t·Tv^{n+θ} and with θ = ½ Δ(E + W_f) = p_n·Bv^{n+½} = ½(1 − e) p_n·Bvⁿ:
//!   zero for e = 1 (conserved to round-off), ≤ 0 on a node that approaches for e < 1;
//! - kinematic `central-difference`: after a contact dof is put on the obstacle by the normal
//!   impulse (force λ_j = m_j Δv_j/τ), the node's tangential force is the one that stops its
//!   slip increment, f_t = −m_j(u_t^pred − u_tⁿ)/τ², projected onto the disc |f_t| ≤ b
//!   (b = μ_f λ_j, Tresca s·w_j, none without a normal impulse): u_t += τ²f_t/m_j,
//!   v_t^{n+½} += τf_t/m_j. A local projection per node, no solve; f̄_t = f_t^{n+1}.
//!
//! Measured per step (SPEC §5): W_f, the rise of E + W_f, the contact node-steps in stick
//! (|Δu_t| ≤ 1e-12·h) and in slip, |Σf_t|/Σf_n, and the series' σ_t (the total e_1 contact
//! force), the Γ_C mean of v_1 and W_f; at T the mean velocities 1ᵀMv/1ᵀM1 along e_1 (3D: the
//! norm over e_1, e_2) and e_d. A law with μ_f = 0 or s = 0 never reaches this module's
//! frictional path (the engine routes it to the frictionless one: bit for bit).

use std::sync::Arc;
use std::time::Instant;

use super::{
    CLOCK_EVERY, Cache, FACTORS, Factored, FeConfig, GEOMETRIES, Geometry, LCP_MAX_ITER, LCP_TOL,
    build_geometry, factor, factor_failure, factor_key, frictional, geometry_key, gravity_load,
    lowest_contact, mass_matrix, mean_velocity, ref_map, reference_record, tangential_dofs,
};
use crate::contact::friction::FrictionLaw;
use crate::contact::gradient::{difference_quotient, difference_quotient_slope};
use crate::contact::{FrictionalContact, Lcp};
use crate::run::fe_nitsche::{
    FrictionState, NEWTON_MAX_ITER, NEWTON_TOL, NewtonWork, NitscheOps, lu_solve, newton,
    newton_friction,
};
use crate::run::friction_tally::{FrictionTally, MeanVelocity};
use crate::run::observe::{Divergence, Observer, SampledTimer, StepValues};
use crate::run::{Metrics, Outcome, RunContext, RunOptions, Series, Status, Stop};
use crate::space::fe::SymMatrix;
use crate::space::linalg::Cholesky;
use crate::space::step_solver::StepWork;
use crate::space::{ContactMethod, MassVariant};
use crate::time::{GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, Scheme};

/// Steps between two recomputations of the carried products Mv, Ku (, Kv, Mu).
const REFRESH: usize = 64;

/// The method of a run of this module.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Method {
    Kane,
    Csn,
    Alpha(GeneralizedAlphaParams),
    MoreauJean(MoreauJeanParams),
    Gradient,
    Kinematic,
}

/// Whether `cfg` is central difference with `mixed` and the lumped mass (kinematic contact).
pub(super) fn kinematic(cfg: &FeConfig) -> bool {
    cfg.scheme == Scheme::Newmark(NewmarkParams::central_difference())
        && cfg.mass == MassVariant::Lumped
        && cfg.method == ContactMethod::Mixed
}

/// Whether this module runs `cfg`.
pub(super) fn handles(cfg: &FeConfig) -> bool {
    cfg.scheme.is_comparison() || kinematic(cfg)
}

fn method(cfg: &FeConfig) -> Result<Method, String> {
    let m = match cfg.scheme {
        _ if kinematic(cfg) => Method::Kinematic,
        Scheme::Kane => Method::Kane,
        Scheme::ContactStabilizedNewmark => Method::Csn,
        Scheme::GeneralizedAlpha(p) => Method::Alpha(p),
        Scheme::MoreauJean(p) => Method::MoreauJean(p),
        Scheme::DiscreteGradient => Method::Gradient,
        s => {
            return Err(format!("scheme {} is not a SPEC §3.2 method", s.label()));
        }
    };
    // The scene and the planner refuse these first; an engine entry point (tests, benches)
    // gets the same reasons.
    let mixed = cfg.method == ContactMethod::Mixed;
    let bad = match m {
        Method::Kane | Method::Csn | Method::MoreauJean(_) | Method::Kinematic if !mixed => {
            Some("is defined for space = mixed only")
        }
        Method::Gradient => match cfg.method {
            ContactMethod::Mixed => {
                Some("needs a contact potential (penalty, or nitsche with Θ = 1)")
            }
            ContactMethod::Nitsche { theta, .. } if theta != 1.0 => {
                Some("with space = nitsche needs nitsche_theta = 1")
            }
            _ => None,
        },
        _ => None,
    };
    if let Some(why) = bad {
        return Err(format!("scheme {} {why}", cfg.scheme.label()));
    }
    let needs_mass = matches!(m, Method::Csn | Method::Alpha(_) | Method::MoreauJean(_));
    if needs_mass && cfg.mass.massless_contact() {
        return Err(format!(
            "scheme {} needs inertia on the contact dofs (mass = consistent or lumped)",
            cfg.scheme.label()
        ));
    }
    Ok(m)
}

/// c of the step matrix M + cK (None: the explicit kinematic step has none).
fn step_coefficient(m: Method, tau: f64) -> Option<f64> {
    let t2 = tau * tau;
    match m {
        Method::Kane | Method::Csn | Method::Gradient => Some(0.25 * t2),
        Method::Alpha(p) => Some(p.stiffness_coefficient(tau)),
        Method::MoreauJean(p) => Some(p.theta * p.theta * t2),
        Method::Kinematic => None,
    }
}

/// M⁻¹Bᵀ (n × n_c, column-major) and W_M = B M⁻¹ Bᵀ (row-major) of one geometry and mass: the
/// predictor of contact-stabilized Newmark.
#[derive(Debug)]
struct MassInverse {
    zm: Vec<f64>,
    wm: Vec<f64>,
    /// K M⁻¹Bᵀ (n × n_c): the predictor's K u^pred from carried products.
    kzm: Vec<f64>,
}

static MASS_INVERSES: Cache<MassInverse> = Cache::new();
/// Power iterations of the CFL estimate: its Rayleigh quotient only seeds the certified bound
/// (a low one costs a second Cholesky), 80 leave it within 1 % on the bars.
const POWER_ITERATIONS: usize = 80;
/// The certified ω²_max (and Gershgorin's bound) per geometry and lumped mass.
static FREQUENCIES: Cache<(f64, f64)> = Cache::new();

fn mass_inverse(g: &Geometry, m: &SymMatrix) -> Result<MassInverse, String> {
    // M's own factor (also under `solver = "cg"`: the predictor's W = B M⁻¹ Bᵀ is made once).
    let symbolic = g.symbolic().map_err(|e| e.to_string())?;
    let chol = Cholesky::new(&symbolic, m)
        .map_err(|e| format!("the mass matrix is not positive definite: {e}"))?;
    let (n, nc) = (g.dofs.n_free(), g.contact.len());
    let mut zm = vec![0.0; n * nc];
    for (j, &c) in g.contact.iter().enumerate() {
        zm[j * n + c] = 1.0;
    }
    let mut work = chol.work_for(nc);
    chol.solve_many_in_place(&mut zm, nc, &mut work);
    let mut wm = vec![0.0; nc * nc];
    for (i, &ci) in g.contact.iter().enumerate() {
        for j in 0..nc {
            wm[i * nc + j] = zm[j * n + ci];
        }
    }
    for i in 0..nc {
        for j in 0..i {
            let s = 0.5 * (wm[i * nc + j] + wm[j * nc + i]);
            wm[i * nc + j] = s;
            wm[j * nc + i] = s;
        }
    }
    let mut kzm = vec![0.0; n * nc];
    for j in 0..nc {
        g.k.matvec_into(&zm[j * n..(j + 1) * n], &mut kzm[j * n..(j + 1) * n]);
    }
    Ok(MassInverse { zm, wm, kzm })
}

/// The largest stable step of kinematic central difference, 2/ω_max (τω_max ≤ 2, SPEC §3), with
/// ω²_max = λ_max(M⁻¹K) of the lumped (diagonal) mass certified from above: power iteration on
/// M^{−½}KM^{−½} gives a Rayleigh quotient θ ≤ λ_max, and σ = θ(1 + δ) is an upper bound as
/// soon as σM − K is positive definite — one sparse Cholesky with the geometry's symbolic
/// factor (δ = 0.5 %, doubled until it is; the Gershgorin bound max_i Σ_j |K_ij|/√(m_i m_j)
/// caps σ and is itself guaranteed). So the step allowed is stable and at most ~0.25 % below
/// the true limit (measured against the Gershgorin step: `tests/fe_methods.rs`). Kinematic
/// contact removes dofs, never adds stiffness, so the contact-free bound holds in contact too.
pub(super) fn kinematic_dt_limit(cfg: &FeConfig) -> Result<f64, (&'static str, String)> {
    // Once per geometry and mass (the planner asks for every run of a sweep).
    let key = format!("{}|{:?}|cfl", geometry_key(&cfg.setup), cfg.mass);
    let (sigma, _) = *FREQUENCIES
        .get(key, || {
            kinematic_frequency_sq(cfg).map_err(|(k, e)| format!("{k}\u{1}{e}"))
        })
        .0
        .map_err(|e| {
            let (k, e) = e.split_once('\u{1}').unwrap_or(("mass", &e));
            (if k == "h" { "h" } else { "mass" }, e.to_string())
        })?;
    let bound = cfg
        .scheme
        .explicit_stability_limit()
        .expect("central difference is explicit");
    Ok(bound / sigma.sqrt())
}

/// (certified upper bound of ω²_max, Gershgorin's bound) of the lumped mass (see
/// [`kinematic_dt_limit`]).
pub(super) fn kinematic_frequency_sq(cfg: &FeConfig) -> Result<(f64, f64), (&'static str, String)> {
    let (geo, _) = GEOMETRIES.get(geometry_key(&cfg.setup), || build_geometry(&cfg.setup));
    let g = geo.map_err(|e| ("h", e))?;
    let (m, _) = mass_matrix(&g, &cfg.setup, &cfg.mass).map_err(|e| ("mass", e))?;
    let diag = m.diagonal();
    if let Some(i) = diag
        .iter()
        .position(|&x| x.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
    {
        return Err((
            "mass",
            format!(
                "kinematic contact needs a positive lumped mass on every dof (dof {i} has {}); use degree = 1",
                diag[i]
            ),
        ));
    }
    let p = &*g.k.pattern;
    let n = p.n;
    // Gershgorin on M^{−½}KM^{−½} (full storage: each entry once).
    let mut row = vec![0.0; n];
    for j in 0..n {
        for k in p.col_ptr[j]..p.col_ptr[j + 1] {
            let i = p.row_idx[k];
            row[i] += g.k.values[k].abs() / (diag[i] * diag[j]).sqrt();
        }
    }
    let gershgorin = row.iter().fold(0.0f64, |a, &b| a.max(b));
    // Power iteration from a seeded random start (deterministic: the planner's verdict must
    // not change between two plans of the same sweep).
    let scale: Vec<f64> = diag.iter().map(|d| 1.0 / d.sqrt()).collect();
    let mut rng = fastrand::Rng::with_seed(0x5eed);
    let mut x: Vec<f64> = (0..n).map(|_| rng.f64() - 0.5).collect();
    let (mut t, mut y) = (vec![0.0; n], vec![0.0; n]);
    let mut theta = 0.0;
    for _ in 0..POWER_ITERATIONS {
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        for (ti, (xi, si)) in t.iter_mut().zip(x.iter().zip(&scale)) {
            *ti = xi / norm * si;
        }
        g.k.matvec_into(&t, &mut y);
        theta = 0.0;
        for i in 0..n {
            y[i] *= scale[i];
            theta += x[i] / norm * y[i];
        }
        std::mem::swap(&mut x, &mut y);
    }
    let mut delta = 0.005;
    loop {
        let sigma = (theta * (1.0 + delta)).min(gershgorin);
        if sigma >= gershgorin {
            return Ok((gershgorin, gershgorin));
        }
        let a = SymMatrix::lin_comb(sigma, &m, -1.0, &g.k);
        let symbolic = g.symbolic().map_err(|e| ("h", e.to_string()))?;
        if Cholesky::new(&symbolic, &a).is_ok() {
            return Ok((sigma, gershgorin));
        }
        delta *= 2.0;
    }
}

/// The frictional part of a run (module header): the law, the tangential dofs of each Γ_C node,
/// the step's forces and the run's [`FrictionTally`]. Allocated once per run.
struct Friction {
    law: FrictionLaw,
    /// Tangential directions per node (d − 1).
    nt: usize,
    /// Reduced index of direction k of contact node j: `tdofs[j·nt + k]`.
    tdofs: Vec<usize>,
    /// The nodes' trapezoidal weights (sum 1): Γ_C means.
    mean_weight: Vec<f64>,
    /// Tresca's weights w_j = ∫_ΓC φ_j of the nodes.
    weight: Vec<f64>,
    /// The step's forces on the body, node-major [f_n, f_t…] (forces also where the method's
    /// unknowns are impulses). Until the step's solve, the previous step's: generalized-α's
    /// f_tⁿ of the right-hand side.
    forces: Vec<f64>,
    /// u_tⁿ at the tangential dofs (the slip's reference), then Δu_t.
    u_t_prev: Vec<f64>,
    du_t: Vec<f64>,
    /// The implicit methods' contact problem (None: kinematic central difference).
    implicit: Option<Implicit>,
    tally: FrictionTally,
    /// The body's mean velocities 1ᵀMv/1ᵀM1 per axis from the carried Mv.
    mean: MeanVelocity,
}

/// The implicit methods' frictional contact problem over the step matrix's frictional
/// condensation ([`Factored::friction`]: Z's normal columns, then the tangential ones; W over
/// the rows C node-major, normal then e_1 (, e_2) per node).
struct Implicit {
    fac: Arc<Factored>,
    /// C's rows (dofs) and Z's columns in the node-major order of μ.
    rows: Vec<usize>,
    cols: Vec<usize>,
    solver: FrictionalContact,
    /// The free gaps and slips of the step, the active mask (Moreau–Jean), the unknowns μ
    /// (node-major, the next step's warm start) and Tresca's weights in μ's unit.
    q_n: Vec<f64>,
    q_t: Vec<f64>,
    active: Vec<bool>,
    mu: Vec<f64>,
    weights: Vec<f64>,
}

impl Friction {
    /// `weight_new` is f̄_t's weight of f_t^{n+1} (SPEC §2.5).
    fn new(
        g: &Geometry,
        cfg: &FeConfig,
        m: &SymMatrix,
        weight_new: f64,
    ) -> Result<Friction, String> {
        let d = cfg.setup.dim;
        let nt = d - 1;
        let nc = g.contact.len();
        let tdofs = tangential_dofs(g)?;
        let weight = g
            .contact_weight
            .iter()
            .map(|w| w * g.contact_measure)
            .collect();
        Ok(Friction {
            law: cfg.friction,
            nt,
            tdofs,
            mean_weight: g.contact_weight.clone(),
            weight,
            forces: vec![0.0; nc * d],
            u_t_prev: vec![0.0; nc * nt],
            du_t: vec![0.0; nc * nt],
            implicit: None,
            tally: FrictionTally::new(nc, d, cfg.setup.h, weight_new),
            mean: mean_velocity(g, m),
        })
    }

    /// Attach the implicit methods' contact problem on the factor `fac` (made with the
    /// frictional columns) and the scale of μ: f = `force_per_mu`·μ, so Tresca's bound s·w_j
    /// on the force is s·w_j/`force_per_mu` on μ.
    fn attach(
        &mut self,
        g: &Geometry,
        fac: &Arc<Factored>,
        force_per_mu: f64,
    ) -> Result<(), String> {
        let ff = fac
            .friction
            .as_ref()
            .ok_or("the step factor has no frictional columns")?;
        let (nt, nc) = (self.nt, g.contact.len());
        let d = nt + 1;
        let (mut rows, mut cols) = (Vec::with_capacity(nc * d), Vec::with_capacity(nc * d));
        for (j, &ci) in g.contact.iter().enumerate() {
            rows.push(ci);
            cols.push(j);
            for k in 0..nt {
                rows.push(ff.tangential[j * nt + k]);
                cols.push(nc + j * nt + k);
            }
        }
        self.implicit = Some(Implicit {
            fac: Arc::clone(fac),
            rows,
            cols,
            solver: FrictionalContact::new(nc, d, ff.w.clone()),
            q_n: vec![0.0; nc],
            q_t: vec![0.0; nc * nt],
            active: vec![true; nc],
            mu: vec![0.0; nc * d],
            weights: self.weight.iter().map(|w| w / force_per_mu).collect(),
        });
        Ok(())
    }

    /// Keep u_tⁿ before a step.
    fn begin(&mut self, u: &[f64]) {
        for (p, &r) in self.u_t_prev.iter_mut().zip(&self.tdofs) {
            *p = u[r];
        }
    }

    /// The free gaps q_n and slips q_t = Ty + `off` (T the tangential rows; `off` the method's
    /// slip reference at those rows, module header) into the problem; `gap(j)` is node j's.
    fn set_free(&mut self, y: &[f64], off: impl Fn(usize) -> f64, gap: impl Fn(usize) -> f64) {
        let im = self.implicit.as_mut().expect("an implicit method");
        for (j, q) in im.q_n.iter_mut().enumerate() {
            *q = gap(j);
        }
        for (q, &r) in im.q_t.iter_mut().zip(&self.tdofs) {
            *q = y[r] + off(r);
        }
    }

    /// Solve the step's problem (over the active nodes if `masked`), then y += cZ̄μ and
    /// sd += cCᵀμ; the normal unknowns into `normal` (the frictionless code's λ). Returns the
    /// Newton steps.
    fn solve(
        &mut self,
        c: f64,
        masked: bool,
        y: &mut [f64],
        sd: &mut [f64],
        normal: &mut [f64],
    ) -> Result<usize, String> {
        let d = self.nt + 1;
        let im = self.implicit.as_mut().expect("an implicit method");
        let it = im
            .solver
            .solve(
                &self.law,
                &im.weights,
                &im.q_n,
                &im.q_t,
                masked.then_some(&im.active[..]),
                &mut im.mu,
                LCP_MAX_ITER,
                LCP_TOL,
            )
            .map_err(|e| e.to_string())?;
        let n = y.len();
        for ((&mk, &col), &row) in im.mu.iter().zip(&im.cols).zip(&im.rows) {
            if mk != 0.0 {
                let f = c * mk;
                for (yi, zi) in y.iter_mut().zip(&im.fac.z[col * n..(col + 1) * n]) {
                    *yi += f * zi;
                }
                sd[row] += f;
            }
        }
        for (l, m) in normal.iter_mut().zip(im.mu.iter().step_by(d)) {
            *l = *m;
        }
        Ok(it)
    }

    /// The step's forces f = `s`·μ (s: μ's force, module header).
    fn take_forces(&mut self, s: f64) {
        let im = self.implicit.as_ref().expect("an implicit method");
        for (f, m) in self.forces.iter_mut().zip(&im.mu) {
            *f = s * m;
        }
    }

    /// y += s·f_tⁿ at the tangential rows (generalized-α's history term κ_f Cᵀrⁿ, whose
    /// normal part the frictionless code adds); `forces` still holds the previous step's.
    fn add_previous_tangential(&self, s: f64, y: &mut [f64]) {
        let d = self.nt + 1;
        for (j, f) in self.forces.chunks_exact(d).enumerate() {
            for (k, fk) in f[1..].iter().enumerate() {
                y[self.tdofs[j * self.nt + k]] += s * fk;
            }
        }
    }

    /// Kinematic friction (module header): with the normal impulses' forces in `forces`, the
    /// tangential force of each node that stops its slip increment, projected onto the disc
    /// of radius b, applied to u_t and v_t^{n+½}. `diag` is the lumped mass.
    fn kinematic(&mut self, u: &mut [f64], v: &mut [f64], diag: &[f64], tau: f64) {
        let (nt, d) = (self.nt, self.nt + 1);
        let t2 = tau * tau;
        for (j, f) in self.forces.chunks_exact_mut(d).enumerate() {
            let ts = &self.tdofs[j * nt..(j + 1) * nt];
            let prev = &self.u_t_prev[j * nt..(j + 1) * nt];
            let (fn_j, ft) = f.split_first_mut().expect("d ≥ 2");
            if *fn_j <= 0.0 {
                ft.iter_mut().for_each(|x| *x = 0.0);
                continue;
            }
            let b = self.law.bound(*fn_j, self.weight[j]);
            let mut norm2 = 0.0;
            for ((fk, &r), p) in ft.iter_mut().zip(ts).zip(prev) {
                *fk = -diag[r] * (u[r] - p) / t2;
                norm2 += *fk * *fk;
            }
            let norm = norm2.sqrt();
            // Stick inside the disc (the slip increment is cancelled exactly: u_t = u_tⁿ),
            // slide on its boundary along the stick force.
            let stick = norm <= b;
            for ((fk, &r), p) in ft.iter_mut().zip(ts).zip(prev) {
                if stick {
                    u[r] = *p;
                } else {
                    *fk *= b / norm;
                    u[r] += t2 * *fk / diag[r];
                }
                v[r] += tau * *fk / diag[r];
            }
        }
    }

    /// The step's bookkeeping once u^{n+1} and the forces are known (the tally: W_f, stick
    /// and slip, the apparent friction coefficient, the step's tangential work).
    fn end(&mut self, u: &[f64]) {
        for ((du, p), &r) in self.du_t.iter_mut().zip(&self.u_t_prev).zip(&self.tdofs) {
            *du = u[r] - p;
        }
        self.tally.step(&self.forces, &self.du_t);
    }

    /// The series' friction values: the total e_1 contact force, the Γ_C mean of v_1 (the
    /// nodes' trapezoidal weights), W_f.
    fn series(&self, v: &[f64]) -> [f64; 3] {
        let v_t = self
            .tdofs
            .iter()
            .step_by(self.nt)
            .zip(&self.mean_weight)
            .map(|(&r, w)| w * v[r])
            .sum();
        [self.tally.total_tangential()[0], v_t, self.tally.work()]
    }

    /// After observing step `step` with energy E: E + W_f and the mean e_1 velocity (the
    /// stop time) into the tally.
    fn observed(&mut self, step: usize, tau: f64, energy: f64, mv: &[f64]) {
        self.tally.energy(energy);
        let mut means = [0.0; 3];
        self.mean.means_into(mv, &mut means);
        self.tally.velocity(step as f64 * tau, means[0]);
    }

    /// The friction columns of SPEC §5 (energies over `scale`): the tally's, and the mean
    /// velocities at T (3D: the tangential norm).
    fn report(&self, metrics: &mut Metrics, mv: &[f64], scale: f64) {
        let mut means = [0.0; 3];
        self.mean.means_into(mv, &mut means);
        self.tally
            .finish(metrics, scale, self.mean.tangential(&means), means[2]);
    }
}

/// The discrete gradient's Newton scratch (allocated once per run).
struct GradientWork {
    s: Vec<f64>,
    /// sⁿ − g per point (the difference quotient's left end).
    a: Vec<f64>,
    d: Vec<f64>,
    slope: Vec<f64>,
    g: Vec<f64>,
    delta: Vec<f64>,
    active: Vec<usize>,
    jac: Vec<f64>,
    perm: Vec<usize>,
}

impl GradientWork {
    fn new(nq: usize) -> GradientWork {
        GradientWork {
            s: vec![0.0; nq],
            a: vec![0.0; nq],
            d: vec![0.0; nq],
            slope: vec![0.0; nq],
            g: vec![0.0; nq],
            delta: vec![0.0; nq],
            active: Vec::with_capacity(nq),
            jac: vec![0.0; nq * nq],
            perm: vec![0; nq],
        }
    }
}

/// Solve G(s) = s − s⁰ − c₂ W D(s) = 0, D_q = w_q DQ(1/γ_q, a_q, s_q − g_q) (module header);
/// on exit `wk.d` holds D(s). The residual test is at the round-off of its terms, as in the
/// scalar solve of [`crate::contact::gradient`]: the energy balance is off by D·r. A residual
/// that stops decreasing below SPEC §4's 1e-12 (relative) is accepted as converged.
fn gradient_newton(
    ops: &NitscheOps,
    w: &[f64],
    c2: f64,
    s0: &[f64],
    wk: &mut GradientWork,
) -> Result<usize, String> {
    let nq = ops.len();
    let scale = s0
        .iter()
        .chain(&ops.gap)
        .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    // Start from the free motion (the previous step's s is sⁿ: a poorer guess after a kink).
    wk.s.copy_from_slice(s0);
    let mut prev_res = f64::INFINITY;
    for it in 0..=NEWTON_MAX_ITER {
        for q in 0..nq {
            let k = ops.w[q] / ops.gamma[q];
            let x = wk.s[q] - ops.gap[q];
            wk.d[q] = k * difference_quotient(1.0, wk.a[q], x);
            wk.slope[q] = k * difference_quotient_slope(1.0, wk.a[q], x);
        }
        let mut res = 0.0f64;
        let mut noisy = true;
        for q in 0..nq {
            let row = &w[q * nq..(q + 1) * nq];
            let (mut acc, mut mag) = (0.0, 0.0);
            for (x, d) in row.iter().zip(&wk.d) {
                if *d != 0.0 {
                    acc += x * d;
                    mag += (x * d).abs();
                }
            }
            let g = wk.s[q] - s0[q] - c2 * acc;
            wk.g[q] = g;
            res = res.max(g.abs());
            let noise = 8.0 * f64::EPSILON * (wk.s[q].abs() + s0[q].abs() + c2 * mag);
            noisy &= g.abs() <= noise;
        }
        if noisy || (res <= NEWTON_TOL * scale && res >= prev_res) {
            return Ok(it);
        }
        if it == NEWTON_MAX_ITER {
            if res <= NEWTON_TOL * scale {
                return Ok(it);
            }
            return Err(format!(
                "discrete-gradient Newton did not converge in {NEWTON_MAX_ITER} iterations (residual {res:.3e}, scale {scale:.3e})"
            ));
        }
        prev_res = res;
        wk.active.clear();
        wk.active
            .extend((0..nq).filter(|&q| wk.d[q] != 0.0 || wk.slope[q] != 0.0));
        let na = wk.active.len();
        for (i, &qi) in wk.active.iter().enumerate() {
            for (j, &qj) in wk.active.iter().enumerate() {
                wk.jac[i * na + j] =
                    f64::from(u8::from(i == j)) - c2 * w[qi * nq + qj] * wk.slope[qj];
            }
            wk.delta[i] = -wk.g[qi];
        }
        lu_solve(
            &mut wk.jac[..na * na],
            na,
            &mut wk.perm[..na],
            &mut wk.delta[..na],
        )
        .map_err(|e| format!("discrete-gradient Newton: {e} (iteration {it})"))?;
        for q in 0..nq {
            if wk.d[q] != 0.0 || wk.slope[q] != 0.0 {
                continue;
            }
            let mut acc = -wk.g[q];
            for (j, &qj) in wk.active.iter().enumerate() {
                acc += c2 * w[q * nq + qj] * wk.slope[qj] * wk.delta[j];
            }
            wk.s[q] += acc;
        }
        for (j, &qj) in wk.active.iter().enumerate() {
            wk.s[qj] += wk.delta[j];
        }
    }
    unreachable!("the loop returns at its last iteration")
}

/// Run one finite-element simulation with a method of SPEC §3.2 (module header).
pub(super) fn simulate(cfg: &FeConfig, opts: &RunOptions, ctx: &RunContext) -> Outcome {
    let start = Instant::now();
    let mut metrics = Metrics {
        dofs: cfg.unknowns() as i64,
        length_scale: Some(cfg.setup.geometry.length_scale()),
        ..Metrics::default()
    };
    let fail = |status, msg: String, metrics: Metrics| Outcome {
        status,
        message: Some(msg),
        metrics,
        series: Series::default(),
        reference: None,
    };
    let meth = match method(cfg) {
        Ok(m) => m,
        Err(e) => return fail(Status::Invalid, e, metrics),
    };
    let tau = cfg.dt;
    let (geo, _) = GEOMETRIES.get(geometry_key(&cfg.setup), || build_geometry(&cfg.setup));
    let geo = match geo {
        Ok(g) => g,
        Err(e) => return fail(Status::Invalid, e, metrics),
    };
    if let Some((status, msg)) = opts.setup_stop(start, "the mesh and operators") {
        return fail(status, msg, metrics);
    }
    let g = &*geo;
    // The step factor (the engine's cache, the engine's key) or, for the explicit step, the
    // lumped mass alone.
    let c = step_coefficient(meth, tau);
    let (fac, own_mass): (Option<Arc<Factored>>, Option<SymMatrix>) = match c {
        Some(c) => {
            // The engine's key: with friction the factor carries the tangential columns (not
            // the frictionless entry), and the solver is part of it (a `cg` entry holds A
            // itself, not its factor: a direct and a cg run must not share it).
            let (fac, hit) = FACTORS.get(factor_key(g, cfg, c), || factor(g, cfg, c));
            let fac = match fac {
                Ok(f) => f,
                Err(e) => return fail(factor_failure(&e), e, metrics),
            };
            // CG factors nothing (the engine's bookkeeping): no factorisation made, none reused.
            let factored = fac.chol.is_factored();
            metrics.factorizations = i64::from(!hit && factored);
            metrics.factor_cache_hits = factored.then_some(i64::from(hit));
            metrics.mass_total = Some(fac.mass_total);
            (Some(fac), None)
        }
        None => match kinematic_dt_limit(cfg) {
            Err((_, e)) => return fail(Status::Invalid, e, metrics),
            Ok(limit) if tau > limit * (1.0 + 1e-12) => {
                return fail(
                    Status::Invalid,
                    format!(
                        "dt = {tau:.6e} is above the CFL limit {limit:.6e} of kinematic central difference"
                    ),
                    metrics,
                );
            }
            Ok(_) => match mass_matrix(g, &cfg.setup, &cfg.mass) {
                Ok((m, total)) => {
                    metrics.mass_total = Some(total);
                    metrics.factorizations = 0;
                    (None, Some(m))
                }
                Err(e) => return fail(Status::Invalid, e, metrics),
            },
        },
    };
    // The factor keeps M; the explicit step owns its lumped M.
    let m: &SymMatrix = match (&fac, &own_mass) {
        (Some(f), _) => &f.m,
        (None, Some(m)) => m,
        (None, None) => unreachable!("one of the two is built above"),
    };
    let minv = match meth {
        Method::Csn => {
            let key = format!("{}|{:?}|mass-inverse", geometry_key(&cfg.setup), cfg.mass);
            let (mi, hit) = MASS_INVERSES.get(key, || mass_inverse(g, m));
            // The Cholesky of M counts as a factorisation of this run when it built it.
            metrics.factorizations += i64::from(!hit);
            match mi {
                Ok(x) => Some(x),
                Err(e) => return fail(Status::SolverFailed, e, metrics),
            }
        }
        _ => None,
    };
    if let Some((status, msg)) = opts.setup_stop(start, "the factorisation") {
        return fail(status, msg, metrics);
    }
    let refmap = match ctx.reference.as_ref().map(|r| ref_map(g, cfg, r)) {
        Some(Err(e)) => return fail(Status::Invalid, e, metrics),
        Some(Ok(m)) => Some(m),
        None => None,
    };

    let n = g.dofs.n_free();
    let nit = fac.as_ref().and_then(|f| f.nitsche.as_ref());
    // Contact unknowns: the Γ_C nodes (mixed) or the points' values (d per point with
    // friction).
    let nc = nit.map_or(g.contact.len(), NitscheOps::unknowns);
    metrics.contact_dofs = Some(nc as i64);
    let base_gap = if g.gap_in_geometry {
        0.0
    } else {
        cfg.setup.gap
    };
    let gaps: Vec<f64> = g.contact_height.iter().map(|h| h + base_gap).collect();

    // Workspace, allocated once.
    let mut u = vec![0.0; n];
    let mut v = vec![0.0; n];
    let mut a = vec![0.0; n];
    let mut mu = vec![0.0; n];
    let mut mv = vec![0.0; n];
    let mut ma = vec![0.0; n];
    let mut ku = vec![0.0; n];
    // K v (CSN, Moreau–Jean), K Δ, and the step's right-hand side A Δ (or A u^{n+1}): the
    // products a step carries instead of recomputing them (module header).
    let mut kv = vec![0.0; n];
    let mut kd = vec![0.0; n];
    let mut sd = vec![0.0; n];
    let mut y = vec![0.0; n];
    let mut pred = vec![0.0; n];
    let mut tmp = vec![0.0; n];
    let mut err = vec![0.0; n];
    let mut q = vec![0.0; nc];
    let mut lambda = vec![0.0; nc];
    let mut lambda_prev = vec![0.0; nc];
    let mut nu = vec![0.0; g.contact.len()];
    let mut rows = vec![false; g.contact.len()];
    let mut lcp = Lcp::new(
        g.contact.len(),
        match (&fac, nit) {
            (Some(f), None) => f.h.clone(),
            _ => vec![0.0; g.contact.len().pow(2)],
        },
    );
    let mut lcp_pred = minv
        .as_ref()
        .map(|mi| Lcp::new(g.contact.len(), mi.wm.clone()));
    let mut grad_work = GradientWork::new(nit.map_or(0, NitscheOps::len));
    let mut newton_work = match nit {
        Some(o) if o.friction.is_some() => NewtonWork::frictional(nc, o.per_point()),
        _ => NewtonWork::new(nit.map_or(0, NitscheOps::len)),
    };
    let mut work: Option<StepWork> = fac.as_ref().map(|f| f.chol.work());
    let diag = m.diagonal();
    // Friction (module header): f̄_t's weight of f_t^{n+1} is generalized-α's 1 − α_f, the
    // other methods' force of the step itself.
    // Friction with Nitsche/penalty (generalized-α/HHT only; module header): the engine's
    // frictional state, f̄_t's weight of f_t^{n+1} 1 − α_f.
    let mut nit_fric = match (nit, meth) {
        (Some(o), Method::Alpha(p)) if o.friction.is_some() => Some(FrictionState::new(
            o,
            cfg.friction,
            mean_velocity(g, m),
            1.0 - p.alpha_f,
            cfg.setup.h,
        )),
        (Some(o), _) if o.friction.is_some() => {
            return fail(
                Status::Invalid,
                format!(
                    "scheme {} has no frictional version with space = {} (SPEC §2.5)",
                    cfg.scheme.label(),
                    cfg.method.name()
                ),
                metrics,
            );
        }
        _ => None,
    };
    let mut fric = if frictional(cfg) && nit.is_none() {
        let weight_new = match meth {
            Method::Alpha(p) => 1.0 - p.alpha_f,
            _ => 1.0,
        };
        // μ's unit: the force enters the right-hand side as c_f·Cᵀr and the solution is
        // y + cZ̄μ, so r = (c/c_f)μ (module header); Moreau–Jean's impulse p = cμ is the force
        // p/τ.
        let force_per_mu = match (meth, c) {
            (Method::Kinematic, _) => None,
            (Method::Kane | Method::Csn, Some(_)) => Some(0.5),
            (Method::Alpha(_), Some(_)) => Some(1.0),
            (Method::MoreauJean(_), Some(c)) => Some(c / tau),
            _ => {
                return fail(
                    Status::Invalid,
                    format!(
                        "scheme {} has no frictional version (SPEC §2.5)",
                        cfg.scheme.label()
                    ),
                    metrics,
                );
            }
        };
        let mut fr = match Friction::new(g, cfg, m, weight_new) {
            Ok(f) => f,
            Err(e) => return fail(Status::Invalid, e, metrics),
        };
        if let (Some(s), Some(f)) = (force_per_mu, &fac)
            && let Err(e) = fr.attach(g, f, s)
        {
            return fail(Status::SolverFailed, e, metrics);
        }
        Some(fr)
    } else {
        None
    };
    // Dofs without inertia (mod1/…/zero-contact with kane): their velocity is Δu/τ.
    let massless: Vec<usize> = (0..n).filter(|&i| diag[i] == 0.0).collect();
    for &r in &g.vertical {
        v[r] = cfg.setup.v0;
    }
    for &r in &g.tangential {
        v[r] = cfg.setup.v0_tangential;
    }
    if let Some((delta, seed)) = cfg.perturbation {
        let mut rng = fastrand::Rng::with_seed(seed);
        for x in v.iter_mut() {
            *x *= 1.0 + delta * (2.0 * rng.f64() - 1.0);
        }
    }
    // Gravity as in the engine ([`gravity_load`]): F, and a⁰ with M a⁰ = F − Ku⁰ on the dofs
    // with inertia (u⁰ = 0, no contact at t = 0), the start of generalized-α and of central
    // difference.
    // The fall along e_d: on an incline (SPEC §1.8) the load's e_d part is −g cos α (cos 0 = 1:
    // the flat runs' numbers unchanged); free_fall_error compares the centre of mass with it.
    let fall = -cfg.setup.gravity * cfg.setup.incline.to_radians().cos();
    let (force_vec, m_ed, vertical_mass, energy_scale) = match gravity_load(g, cfg, m) {
        Err(e) => return fail(Status::Invalid, e, metrics),
        Ok(None) => (vec![0.0; n], vec![0.0; n], 0.0, None),
        Ok(Some(load)) => {
            a.copy_from_slice(&load.a0);
            m.matvec_into(&a, &mut ma);
            (
                load.force,
                load.m_ed,
                load.vertical_mass,
                Some(load.energy_scale),
            )
        }
    };
    m.matvec_into(&v, &mut mv);
    let mut record = match reference_record(g, cfg, ctx) {
        Err(e) => return fail(Status::Invalid, e, metrics),
        Ok(r) => r,
    };
    if let Some((status, msg)) = opts.setup_stop(start, "the workspace") {
        return fail(status, msg, metrics);
    }
    metrics.setup_time_s = Some(start.elapsed().as_secs_f64());
    let loop_start = Instant::now();

    let mut obs = Observer::new(tau, opts.series_every, cfg.steps);
    if let Some(sc) = energy_scale {
        obs = obs.with_energy_scale(sc);
    }
    let lowest = lowest_contact(g);
    let mean = |x: &[f64]| -> f64 {
        g.contact
            .iter()
            .zip(&g.contact_weight)
            .map(|(&c, w)| w * x[c])
            .sum()
    };
    let mut fall_error = 0.0f64;
    let mut touched = false;
    // Observe step n: state (u, v) with the products Mv, Ku and the step's total contact force.
    #[allow(clippy::too_many_arguments)]
    let mut observe = |step: usize,
                       u: &[f64],
                       v: &[f64],
                       mv: &[f64],
                       ku: &[f64],
                       force: f64,
                       tmp: &mut [f64],
                       err: &mut [f64],
                       friction: Option<[f64; 3]>|
     -> Result<f64, Divergence> {
        let kinetic = 0.5 * v.iter().zip(mv).map(|(x, y)| x * y).sum::<f64>();
        let elastic = 0.5 * u.iter().zip(ku).map(|(x, y)| x * y).sum::<f64>();
        let gravity = -u.iter().zip(&force_vec).map(|(x, y)| x * y).sum::<f64>();
        let penetration = g
            .contact
            .iter()
            .zip(&gaps)
            .fold(0.0f64, |m, (&c, gap)| m.max(-u[c] - gap));
        let (e, theta_term) = match nit {
            Some(ops) => {
                let (pot, t, _) = ops.energy_terms_and_force(u);
                (kinetic + elastic + gravity + pot, t)
            }
            None => (kinetic + elastic + gravity, None),
        };
        let uc = mean(u);
        if fall != 0.0 && !touched {
            if force > 0.0 {
                touched = true;
            } else {
                let t = step as f64 * tau;
                // e_dᵀ M u / e_dᵀ M e_d.
                let com: f64 =
                    m_ed.iter().zip(u.iter()).map(|(x, y)| x * y).sum::<f64>() / vertical_mass;
                fall_error = fall_error.max((com - 0.5 * fall * t * t).abs());
            }
        }
        if let Some((slots, data)) = record.as_mut()
            && step.is_multiple_of(data.time_stride)
        {
            data.u.extend(slots.iter().map(|s| s.map_or(0.0, |r| u[r])));
            data.force.push(force);
            data.energy.push(e);
            data.u_contact.push(uc);
        }
        let exact = refmap.as_ref().map(|rm| rm.compare(g, step, u, err, tmp));
        if let Some([sigma_t, v_t, work]) = friction {
            obs.set_friction(sigma_t, v_t, work);
        }
        obs.observe(
            StepValues {
                step,
                t: step as f64 * tau,
                u_contact: uc,
                v_contact: mean(v),
                sigma_contact: -force,
                sigma_mid: None,
                energy: e,
                energy_theta: theta_term.map(|t| e + t),
                energy_kinetic: Some(kinetic),
                energy_elastic: Some(elastic),
                energy_gravity: (fall != 0.0).then_some(gravity),
                u_lowest: lowest.map(|c| u[c]),
                penetration: Some(penetration),
            },
            exact,
        )
        .map(|()| e)
    };

    let mut done = 0usize;
    let mut iterations = 0i64;
    let mut newton_max = 0usize;
    let mut observe_timer = SampledTimer::default();
    let t2 = tau * tau;
    // E of the last observed step (the frictional Nitsche/penalty run's E + W_f balance).
    let mut e_last = 0.0;
    let stop = (|| -> Result<(), Stop<String>> {
        g.k.matvec_into(&u, &mut ku);
        g.k.matvec_into(&v, &mut kv);
        if let Some(ops) = nit {
            // The state's own contact force at t = 0 (zero unless the body starts in contact).
            let (_, _, f) = ops.energy_terms_and_force(&u);
            e_last = observe(0, &u, &v, &mv, &ku, f, &mut tmp, &mut err, None)
                .map_err(Stop::Diverged)?;
            if let Some(st) = nit_fric.as_mut() {
                st.start(&mv);
            }
        } else {
            let fv = fric.as_ref().map(|fr| fr.series(&v));
            let e = observe(0, &u, &v, &mv, &ku, 0.0, &mut tmp, &mut err, fv)
                .map_err(Stop::Diverged)?;
            if let Some(fr) = fric.as_mut() {
                fr.observed(0, tau, e, &mv);
            }
        }
        for step in 1..=cfg.steps {
            if let Some(fr) = fric.as_mut() {
                fr.begin(&u);
            }
            let force = match meth {
                Method::Kinematic => {
                    for i in 0..n {
                        v[i] += 0.5 * tau * a[i];
                        u[i] += tau * v[i];
                    }
                    let mut force = 0.0;
                    for (j, (&ci, gi)) in g.contact.iter().zip(&gaps).enumerate() {
                        let (uc, dv, l) = crate::time::kinematic_impulse(u[ci], -gi, diag[ci], tau);
                        u[ci] = uc;
                        v[ci] += dv;
                        force += l;
                        if let Some(fr) = fric.as_mut() {
                            fr.forces[j * (fr.nt + 1)] = l;
                        }
                    }
                    if let Some(fr) = fric.as_mut() {
                        fr.kinematic(&mut u, &mut v, &diag, tau);
                    }
                    g.k.matvec_into(&u, &mut ku);
                    for i in 0..n {
                        a[i] = (force_vec[i] - ku[i]) / diag[i];
                        v[i] += 0.5 * tau * a[i];
                        mv[i] = diag[i] * v[i];
                    }
                    force
                }
                _ => {
                    let f = fac.as_ref().expect("implicit methods have a factor");
                    let c = c.expect("implicit methods have a step matrix");
                    let work = work.as_mut().expect("implicit methods have solve scratch");
                    match meth {
                        Method::Kane => {
                            // b = τMvⁿ − τ²/2 Kuⁿ + τ²/2 F, kept in `sd` for S Δ below.
                            for i in 0..n {
                                y[i] = tau * mv[i] - 2.0 * c * ku[i] + 2.0 * c * force_vec[i];
                            }
                            sd.copy_from_slice(&y);
                            f.chol.solve_in_place(&mut y, work);
                            work.check()
                                .map_err(|e| Stop::Solver(step, e.to_string()))?;
                            // Slip = TΔu: q_t = Ty.
                            let it = implicit_contact_correction(
                                fric.as_mut(),
                                &mut lcp,
                                f,
                                &g.contact,
                                &gaps,
                                &u,
                                |_| 0.0,
                                c,
                                (&mut q, &mut lambda),
                                &mut y,
                                &mut sd,
                            )
                            .map_err(|e| Stop::Solver(step, e))?;
                            newton_max = newton_max.max(it);
                            iterations += it as i64;
                            // One product: KΔ; then MΔ = SΔ − cKΔ (no division by c).
                            g.k.matvec_into(&y, &mut kd);
                            for i in 0..n {
                                let md = sd[i] - c * kd[i];
                                v[i] = 2.0 * y[i] / tau - v[i];
                                mv[i] = 2.0 * md / tau - mv[i];
                                u[i] += y[i];
                                ku[i] += kd[i];
                            }
                            for &i in &massless {
                                v[i] = y[i] / tau;
                            }
                            // μ = 2λ: the contact force enters with τ²/2 = 2c.
                            0.5 * lambda.iter().sum::<f64>()
                        }
                        Method::Csn => {
                            let mi = minv.as_ref().expect("CSN has M⁻¹Bᵀ");
                            let lp = lcp_pred.as_mut().expect("CSN has its predictor LCP");
                            for i in 0..n {
                                pred[i] = u[i] + tau * v[i];
                            }
                            for ((qi, &ci), gi) in q.iter_mut().zip(&g.contact).zip(&gaps) {
                                *qi = pred[ci] + gi;
                            }
                            let it = lp
                                .solve(&q, &mut nu, LCP_MAX_ITER, LCP_TOL)
                                .map_err(|e| Stop::Solver(step, format!("predictor: {e}")))?;
                            iterations += it as i64;
                            add_columns(&mi.zm, &nu, 1.0, &mut pred);
                            // K u^pred = Kuⁿ + τKvⁿ + (KM⁻¹Bᵀ)ν, from the carried products.
                            for i in 0..n {
                                tmp[i] = ku[i] + tau * kv[i];
                            }
                            add_columns(&mi.kzm, &nu, 1.0, &mut tmp);
                            for i in 0..n {
                                y[i] = -c * (ku[i] + tmp[i]) + 2.0 * c * force_vec[i];
                            }
                            sd.copy_from_slice(&y);
                            f.chol.solve_in_place(&mut y, work);
                            work.check()
                                .map_err(|e| Stop::Solver(step, e.to_string()))?;
                            // Slip = u_t^{n+1} − u_tⁿ = T(u^pred − uⁿ) + TΔ.
                            let it2 = implicit_contact_correction(
                                fric.as_mut(),
                                &mut lcp,
                                f,
                                &g.contact,
                                &gaps,
                                &pred,
                                |r| pred[r] - u[r],
                                c,
                                (&mut q, &mut lambda),
                                &mut y,
                                &mut sd,
                            )
                            .map_err(|e| Stop::Solver(step, e))?;
                            newton_max = newton_max.max(it + it2);
                            iterations += it2 as i64;
                            g.k.matvec_into(&y, &mut kd);
                            for i in 0..n {
                                let md = sd[i] - c * kd[i];
                                v[i] += 2.0 * y[i] / tau;
                                mv[i] += 2.0 * md / tau;
                                u[i] = pred[i] + y[i];
                                ku[i] = tmp[i] + kd[i];
                                kv[i] += 2.0 * kd[i] / tau;
                            }
                            0.5 * lambda.iter().sum::<f64>()
                        }
                        Method::Alpha(ga) if nit.is_some() => {
                            // Nitsche/penalty: K_Θ is in A, the contact force f_c(u) =
                            // Σ_q φ_q(p_q·u) C_q, f_cⁿ = f_c(uⁿ) (φⁿ kept from the last step's
                            // Newton, which solved φ at uⁿ), f_c^{n+1} by the engine's Newton.
                            let ops = nit.expect("checked");
                            let (km, kf) = ga.history_coefficients(tau);
                            let kp = t2 * (0.5 - ga.beta);
                            let bt2 = ga.beta * t2;
                            for i in 0..n {
                                pred[i] = u[i] + tau * v[i] + kp * a[i];
                                y[i] = mu[i] + tau * mv[i] + (kp - km) * ma[i] - kf * ku[i]
                                    + (c + kf) * force_vec[i];
                            }
                            add_theta_term(ops, &u, kf, &mut y);
                            add_point_columns(ops, &lambda_prev, kf, &mut y);
                            sd.copy_from_slice(&y);
                            f.chol.solve_in_place(&mut y, work);
                            work.check()
                                .map_err(|e| Stop::Solver(step, e.to_string()))?;
                            let it = if let Some(st) = nit_fric.as_mut() {
                                // Friction (fe_nitsche header, coefficient c): x0 = P y +
                                // k u_tⁿ (the slip from uⁿ), λ the previous step's forces
                                // (the warm start), kept for f̄_t.
                                st.start_step(ops, &y, &u, &mut q);
                                newton_friction(
                                    ops,
                                    st.law,
                                    &f.h,
                                    c,
                                    &q,
                                    &mut lambda,
                                    &mut st.slides,
                                    &mut newton_work,
                                )
                            } else {
                                for (k, qk) in q.iter_mut().enumerate() {
                                    *qk = ops.apply(&ops.p, k, &y);
                                }
                                newton(ops, &f.h, c, &q, &ops.gap, &mut lambda, &mut newton_work)
                            }
                            .map_err(|e| Stop::Solver(step, e))?;
                            newton_max = newton_max.max(it);
                            iterations += it as i64;
                            add_columns(&f.z, &lambda, c, &mut y);
                            add_point_columns(ops, &lambda, c, &mut sd);
                            lambda_prev.copy_from_slice(&lambda);
                            // M u^{n+1} = A u^{n+1} − cK_Θu^{n+1}, one product K u^{n+1}.
                            std::mem::swap(&mut u, &mut y);
                            g.k.matvec_into(&u, &mut ku);
                            for i in 0..n {
                                sd[i] -= c * ku[i];
                            }
                            add_theta_term(ops, &u, c, &mut sd);
                            let g1 = 1.0 - ga.gamma;
                            for i in 0..n {
                                let an = (u[i] - pred[i]) / bt2;
                                let mpred = mu[i] + tau * mv[i] + kp * ma[i];
                                let man = (sd[i] - mpred) / bt2;
                                v[i] += tau * (g1 * a[i] + ga.gamma * an);
                                mv[i] += tau * (g1 * ma[i] + ga.gamma * man);
                                a[i] = an;
                                ma[i] = man;
                                mu[i] = sd[i];
                            }
                            // The normal forces (d per point with friction).
                            lambda.iter().step_by(ops.per_point()).sum::<f64>()
                        }
                        Method::Alpha(ga) => {
                            let (km, kf) = ga.history_coefficients(tau);
                            let kp = t2 * (0.5 - ga.beta);
                            let bt2 = ga.beta * t2;
                            for i in 0..n {
                                pred[i] = u[i] + tau * v[i] + kp * a[i];
                                y[i] = mu[i] + tau * mv[i] + (kp - km) * ma[i] - kf * ku[i]
                                    + (c + kf) * force_vec[i];
                            }
                            add_rows(&g.contact, &lambda_prev, kf, &mut y);
                            if let Some(fr) = fric.as_ref() {
                                fr.add_previous_tangential(kf, &mut y);
                            }
                            sd.copy_from_slice(&y);
                            f.chol.solve_in_place(&mut y, work);
                            work.check()
                                .map_err(|e| Stop::Solver(step, e.to_string()))?;
                            let it = if let Some(fr) = fric.as_mut() {
                                // y is u^{n+1} without contact: slip = Ty − Tuⁿ + (TZ̄μ)c.
                                fr.set_free(&y, |r| -u[r], |j| y[g.contact[j]] + gaps[j]);
                                let it = fr
                                    .solve(c, false, &mut y, &mut sd, &mut lambda)
                                    .map_err(|e| Stop::Solver(step, e))?;
                                fr.take_forces(1.0);
                                it
                            } else {
                                for ((qi, &ci), gi) in q.iter_mut().zip(&g.contact).zip(&gaps) {
                                    *qi = y[ci] + gi;
                                }
                                let it = lcp
                                    .solve(&q, &mut lambda, LCP_MAX_ITER, LCP_TOL)
                                    .map_err(|e| Stop::Solver(step, e.to_string()))?;
                                add_columns(&f.z, &lambda, c, &mut y);
                                add_rows(&g.contact, &lambda, c, &mut sd);
                                it
                            };
                            newton_max = newton_max.max(it);
                            iterations += it as i64;
                            lambda_prev.copy_from_slice(&lambda);
                            // One product, K u^{n+1}; M u^{n+1} = A u^{n+1} − cKu^{n+1}, and
                            // M a^{n+1} = (M u^{n+1} − M ũ)/(βτ²) from the carried products.
                            std::mem::swap(&mut u, &mut y);
                            g.k.matvec_into(&u, &mut ku);
                            let g1 = 1.0 - ga.gamma;
                            for i in 0..n {
                                let an = (u[i] - pred[i]) / bt2;
                                let mpred = mu[i] + tau * mv[i] + kp * ma[i];
                                let mun = sd[i] - c * ku[i];
                                let man = (mun - mpred) / bt2;
                                v[i] += tau * (g1 * a[i] + ga.gamma * an);
                                mv[i] += tau * (g1 * ma[i] + ga.gamma * man);
                                a[i] = an;
                                ma[i] = man;
                                mu[i] = mun;
                            }
                            lambda.iter().sum::<f64>()
                        }
                        Method::MoreauJean(mj) => {
                            // b = −τK(uⁿ + θτvⁿ) + τF from the carried products.
                            for i in 0..n {
                                y[i] = -tau * (ku[i] + mj.theta * tau * kv[i]) + tau * force_vec[i];
                            }
                            sd.copy_from_slice(&y);
                            f.chol.solve_in_place(&mut y, work);
                            work.check()
                                .map_err(|e| Stop::Solver(step, e.to_string()))?;
                            let mut any = false;
                            for (j, (&ci, gi)) in g.contact.iter().zip(&gaps).enumerate() {
                                let active = u[ci] + gi + 0.5 * tau * v[ci] <= 0.0;
                                rows[j] = active;
                                any |= active;
                                q[j] = if active {
                                    (1.0 + mj.restitution) * v[ci] + y[ci]
                                } else {
                                    0.0
                                };
                            }
                            if let Some(fr) = fric.as_mut() {
                                // De Saxcé on velocities over the active nodes: "gap" =
                                // Bv^{n+1} + eBvⁿ (q as above), slip = v_t^{n+1} = T(vⁿ + Δv).
                                if any {
                                    fr.set_free(&y, |r| v[r], |j| q[j]);
                                    fr.implicit
                                        .as_mut()
                                        .expect("attached")
                                        .active
                                        .copy_from_slice(&rows);
                                    let it = fr
                                        .solve(c, true, &mut y, &mut sd, &mut lambda)
                                        .map_err(|e| Stop::Solver(step, e))?;
                                    newton_max = newton_max.max(it);
                                    iterations += it as i64;
                                } else {
                                    let im = fr.implicit.as_mut().expect("attached");
                                    im.mu.iter_mut().for_each(|x| *x = 0.0);
                                    lambda.iter_mut().for_each(|l| *l = 0.0);
                                }
                                fr.take_forces(c / tau);
                            } else if any {
                                let it = lcp
                                    .solve_on(&q, &mut lambda, &rows, LCP_MAX_ITER, LCP_TOL)
                                    .map_err(|e| Stop::Solver(step, e.to_string()))?;
                                newton_max = newton_max.max(it);
                                iterations += it as i64;
                                add_columns(&f.z, &lambda, c, &mut y);
                                add_rows(&g.contact, &lambda, c, &mut sd);
                            } else {
                                lambda.iter_mut().for_each(|l| *l = 0.0);
                            }
                            g.k.matvec_into(&y, &mut kd);
                            for i in 0..n {
                                let md = sd[i] - c * kd[i];
                                u[i] += tau * (v[i] + mj.theta * y[i]);
                                ku[i] += tau * (kv[i] + mj.theta * kd[i]);
                                v[i] += y[i];
                                mv[i] += md;
                                kv[i] += kd[i];
                            }
                            // p = cμ, reported as the mean force p/τ.
                            c * lambda.iter().sum::<f64>() / tau
                        }
                        Method::Gradient => {
                            let ops = nit.expect("the discrete gradient has contact points");
                            // b = τMvⁿ − τ²/2 K_Θuⁿ + τ²/2 F, K_Θ u = Ku − Θ Σ w γ s (s·u).
                            for i in 0..n {
                                y[i] = tau * mv[i] - 2.0 * c * ku[i] + 2.0 * c * force_vec[i];
                            }
                            add_theta_term(ops, &u, 2.0 * c, &mut y);
                            sd.copy_from_slice(&y);
                            f.chol.solve_in_place(&mut y, work);
                            work.check()
                                .map_err(|e| Stop::Solver(step, e.to_string()))?;
                            for k in 0..ops.len() {
                                let sn = ops.apply(&ops.p, k, &u);
                                grad_work.a[k] = sn - ops.gap[k];
                                q[k] = sn + ops.apply(&ops.p, k, &y);
                            }
                            let it = gradient_newton(ops, &f.h, 2.0 * c, &q, &mut grad_work)
                                .map_err(|e| Stop::Solver(step, e))?;
                            newton_max = newton_max.max(it);
                            iterations += it as i64;
                            // Δu = y + τ²/2 Z D = y + c Z (2D); A Δu = b + c Σ 2D_q C_q.
                            for (l, dq) in lambda.iter_mut().zip(&grad_work.d) {
                                *l = 2.0 * dq;
                            }
                            add_columns(&f.z, &lambda, c, &mut y);
                            for (k, l) in lambda.iter().enumerate() {
                                if *l != 0.0 {
                                    for (&gd, &ck) in ops.dofs[k * ops.k..(k + 1) * ops.k]
                                        .iter()
                                        .zip(&ops.c[k * ops.k..(k + 1) * ops.k])
                                    {
                                        sd[gd] += c * l * ck;
                                    }
                                }
                            }
                            // MΔ = AΔ − cK_ΘΔ with KΔ by one product.
                            g.k.matvec_into(&y, &mut kd);
                            for i in 0..n {
                                sd[i] -= c * kd[i];
                            }
                            add_theta_term(ops, &y, c, &mut sd);
                            for i in 0..n {
                                v[i] = 2.0 * y[i] / tau - v[i];
                                mv[i] = 2.0 * sd[i] / tau - mv[i];
                                u[i] += y[i];
                                ku[i] += kd[i];
                            }
                            for &i in &massless {
                                v[i] = y[i] / tau;
                            }
                            grad_work.d.iter().sum::<f64>()
                        }
                        Method::Kinematic => unreachable!("explicit"),
                    }
                }
            };
            // The carried products drift by round-off (and would hide a step that does not
            // solve its equation): every REFRESH steps they are recomputed from the state, so
            // a discrepancy shows as an energy jump the per-step energy checks see.
            if step.is_multiple_of(REFRESH) && !matches!(meth, Method::Kinematic) {
                m.matvec_into(&v, &mut mv);
                g.k.matvec_into(&u, &mut ku);
                match meth {
                    Method::Csn | Method::MoreauJean(_) => g.k.matvec_into(&v, &mut kv),
                    Method::Alpha(_) => m.matvec_into(&u, &mut mu),
                    _ => {}
                }
            }
            if let Some(fr) = fric.as_mut() {
                fr.end(&u);
            }
            let mut fv = fric.as_ref().map(|fr| fr.series(&v));
            if let (Some(st), Some(ops)) = (nit_fric.as_mut(), nit) {
                // W_f with generalized-α's f̄_t = (1 − α_f) f_t^{n+1} + α_f f_tⁿ (SPEC §2.5).
                let (ft, vt, wf) = st.after_step(ops, &u, &v, &mv, &lambda, step as f64 * tau);
                fv = Some([ft, vt, wf]);
            }
            let e = observe_timer
                .time(step, || {
                    observe(step, &u, &v, &mv, &ku, force, &mut tmp, &mut err, fv)
                })
                .map_err(Stop::Diverged)?;
            if let Some(fr) = fric.as_mut() {
                fr.observed(step, tau, e, &mv);
            }
            if let Some(st) = nit_fric.as_mut() {
                st.balance(e_last, e);
            }
            e_last = e;
            done = step;
            opts.step_stop(step, CLOCK_EVERY, start)?;
        }
        Ok(())
    })();
    metrics.steps = done as i64;
    metrics.iterations = iterations;
    metrics.iterations_max_step = Some(newton_max as i64);
    if let (Some(f), Some(w)) = (&fac, &work)
        && !f.chol.is_factored()
    {
        metrics.solver_iterations = Some(w.iterations_total() as i64);
        metrics.solver_iterations_max_step = Some(w.iterations_max() as i64);
    }
    metrics.stepping_time_s = Some(loop_start.elapsed().as_secs_f64());
    metrics.observe_time_s = observe_timer.estimate_s();
    let (status, message) = Stop::status(stop, tau, cfg.steps, start, &mut metrics);
    obs.finish(&mut metrics, status == Status::Ok);
    metrics.free_fall_error = (fall != 0.0).then_some(fall_error);
    metrics.err_force_l2 = metrics.err_sigma_l2.take();
    metrics.err_sigma_mid_l2 = None;
    metrics.contact_toggles = Some(metrics.contact_switches);
    metrics.energy_scale = energy_scale.or(metrics.energy_initial);
    if let (Some(fr), Some(scale)) = (&fric, metrics.energy_scale) {
        fr.report(&mut metrics, &mv, scale);
    }
    if let Some(st) = &nit_fric {
        // As the engine's frictional Nitsche/penalty runs ([`super::Stepper`]).
        let scale = metrics.energy_scale.filter(|s| *s != 0.0).unwrap_or(1.0);
        st.finish(&mut metrics, scale);
    }
    let reference = match record {
        Some((_, data)) if status == Status::Ok => Some(data),
        _ => None,
    };
    Outcome {
        status,
        message,
        metrics,
        series: std::mem::take(&mut obs.series),
        reference,
    }
}

/// y += s Σ_j μ_j Z_j over the columns with μ_j ≠ 0 (Z column-major, n rows).
/// The contact correction `kane` and `contact-stabilized-newmark` share (one step matrix
/// S = M + cK, c = τ²/4): `y` = S⁻¹b is the contact-free increment from `base` (uⁿ for
/// `kane`, u^pred for CSN) and `sd` = b. Frictional: the condensed Coulomb/Tresca problem
/// with gaps base + y + g and slips off + Ty (off = 0, or u^pred − uⁿ), its forces taken as
/// the scheme's (μ = 2λ: ½); frictionless: the LCP on the same gaps, Z's columns added to `y`
/// and the contact rows to `sd` with weight c. `q`, `lambda`: the LCP's gaps and the normal
/// multipliers (warm start in, solution out). Returns the Newton steps.
#[allow(clippy::too_many_arguments)]
fn implicit_contact_correction(
    fric: Option<&mut Friction>,
    lcp: &mut Lcp,
    f: &Factored,
    contact: &[usize],
    gaps: &[f64],
    base: &[f64],
    off: impl Fn(usize) -> f64,
    c: f64,
    (q, lambda): (&mut [f64], &mut [f64]),
    y: &mut [f64],
    sd: &mut [f64],
) -> Result<usize, String> {
    if let Some(fr) = fric {
        fr.set_free(y, off, |j| base[contact[j]] + y[contact[j]] + gaps[j]);
        let it = fr.solve(c, false, y, sd, lambda)?;
        fr.take_forces(0.5);
        Ok(it)
    } else {
        for ((qi, &ci), gi) in q.iter_mut().zip(contact).zip(gaps) {
            *qi = base[ci] + y[ci] + gi;
        }
        let it = lcp
            .solve(q, lambda, LCP_MAX_ITER, LCP_TOL)
            .map_err(|e| e.to_string())?;
        add_columns(&f.z, lambda, c, y);
        add_rows(contact, lambda, c, sd);
        Ok(it)
    }
}

fn add_columns(z: &[f64], mu: &[f64], s: f64, y: &mut [f64]) {
    let n = y.len();
    for (j, &l) in mu.iter().enumerate() {
        if l != 0.0 {
            let zj = &z[j * n..(j + 1) * n];
            let f = s * l;
            for (yi, zi) in y.iter_mut().zip(zj) {
                *yi += f * zi;
            }
        }
    }
}

/// y_{c_j} += s μ_j: s Bᵀμ on the contact rows.
fn add_rows(contact: &[usize], mu: &[f64], s: f64, y: &mut [f64]) {
    for (&c, l) in contact.iter().zip(mu) {
        y[c] += s * l;
    }
}

/// y += s Θ Σ_q w_q γ_q Σ_r (σ_r,q·x) σ_r,q: the Nitsche Θ-term of −K_Θ x = −Kx + Θ Σ w γ
/// s (s·x) (with friction also the σ_t rows' −Θ∫γ σ_t(u)·σ_t(v), as the step matrix,
/// [`NitscheOps::sigma_row`]), scaled by s (nothing for the penalty, Θ = 0).
fn add_theta_term(ops: &NitscheOps, x: &[f64], s: f64, y: &mut [f64]) {
    if ops.theta == 0.0 {
        return;
    }
    for k in 0..ops.len() {
        let dofs = &ops.dofs[k * ops.k..(k + 1) * ops.k];
        for r in 0..ops.per_point() {
            let row = ops.sigma_row(k, r);
            let sx: f64 = row.iter().zip(dofs).map(|(a, &g)| a * x[g]).sum();
            let f = s * ops.theta * ops.w[k] * ops.gamma[k] * sx;
            for (&gd, &sk) in dofs.iter().zip(row) {
                y[gd] += f * sk;
            }
        }
    }
}

/// y += s Σ_j φ_j C_j: the Nitsche/penalty contact force of the unknowns' values φ (point
/// forces, d per point with friction) along their columns of C (C_q = −t_q, the upward
/// direction of point q; with friction also u_t − Θγσ_t, [`NitscheOps::c_row`]).
fn add_point_columns(ops: &NitscheOps, phi: &[f64], s: f64, y: &mut [f64]) {
    for (j, p) in phi.iter().enumerate() {
        if *p != 0.0 {
            let (row, dofs) = ops.c_row(j);
            for (&gd, &ck) in dofs.iter().zip(row) {
                y[gd] += s * p * ck;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{BarScene, Physics, Scene, SceneSetup};
    use crate::space::step_solver::Solver;

    /// The certified ω²_max is an upper bound (σM − K positive definite, by construction) and
    /// tight: 1 % below it σM − K is indefinite (so the CFL step is within ~0.5 % of the true
    /// one), and it never exceeds Gershgorin's bound. Measured on bar2d h = 0.05 and bar3d
    /// h = 0.1 (lumped): σ/Gershgorin printed.
    #[test]
    fn kinematic_frequency_bound_is_certified_and_tight() {
        for (dim, h) in [(2, 0.05), (3, 0.1)] {
            let scene = BarScene { dim };
            let physics = Physics(
                scene
                    .physics()
                    .iter()
                    .map(|k| (k.name, k.default))
                    .collect(),
            );
            let SceneSetup::Fe(setup) =
                scene.setup(&physics, scene.mesh_from_h(&physics, h).unwrap())
            else {
                unreachable!("the bars are FE scenes")
            };
            let cfg = FeConfig {
                setup,
                method: ContactMethod::Mixed,
                mass: MassVariant::Lumped,
                scheme: Scheme::Newmark(NewmarkParams::central_difference()),
                dt: 1e-3,
                steps: 1,
                perturbation: None,
                solver: Solver::Direct,
                friction: crate::contact::friction::FrictionLaw::None,
            };
            let (sigma, gersh) = kinematic_frequency_sq(&cfg).unwrap();
            eprintln!(
                "bar{dim}d h = {h}: ω²_max ≤ {sigma:.6e}, Gershgorin {gersh:.6e} (ratio {:.4})",
                sigma / gersh
            );
            assert!(sigma <= gersh);
            let (geo, _) = GEOMETRIES.get(geometry_key(&cfg.setup), || build_geometry(&cfg.setup));
            let g = geo.unwrap();
            let (m, _) = mass_matrix(&g, &cfg.setup, &cfg.mass).unwrap();
            let symbolic = g.symbolic().unwrap();
            let ok =
                |s: f64| Cholesky::new(&symbolic, &SymMatrix::lin_comb(s, &m, -1.0, &g.k)).is_ok();
            assert!(ok(sigma), "σM − K must be positive definite");
            assert!(!ok(0.99 * sigma), "the bound is not tight to 1 %");
        }
    }
}
