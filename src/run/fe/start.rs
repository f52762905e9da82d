//! The quasi-static start of the massless dofs (contract §1.3, §2.2; issue 42).
//!
//! With a mass variant whose rows vanish on some dofs (`zero-contact`, `mod1/2/3`, `weights`:
//! the Γ_C nodes and, with degree-2 layers, the midside nodes inside layer 0), those dofs have
//! no inertia: their equation is quasi-static at every time, t = 0 included. Under the body
//! load they carry load, so u⁰ = 0 is not their state at t = 0: the first step would snap them
//! to it and lose energy once, a start-up loss that does not vanish as τ → 0 (measured against
//! GetFEM on the P2 disc: mod1's drift −4.1e-4 with u⁰ = 0, −2.2e-4 from this start). With
//! `contact_init = "consistent"` (the default) they start where their equation puts them, as
//! the 1D bar's contact node does ([`crate::run::bar1d`]):
//!
//!   (K̃ u⁰)_c = F_c + (contact forces)_c,   u⁰_f = 0 on the dofs with inertia,
//!
//! K̃ the run's own stiffness — K, with Nitsche's −Θ Σ_q w_q γ_q s_q s_qᵀ (and its σ_t rows with
//! friction) — and the contact forces of the run's treatment at that state: none when the
//! massless dofs stay off the plane (then E⁰ = −½ F_cᵀ K̃_cc⁻¹ F_c); the nodal Signorini
//! multipliers (`mixed`, an LCP on the Γ_C nodes); φ_q(P_q u) at the points (`nitsche`,
//! `penalty`, the steps' semismooth Newton with cτ² = 1; where a large μ_f makes that problem's
//! sliding fold cycle, the frictionless state, as for mixed). With friction the start includes the
//! massless nodes' tangential force: a node sliding at t = 0 (its tangential v⁰ ≠ 0) has
//! f_t⁰ = −μ_f f_n⁰ v̂ (Coulomb) or −s·w_i v̂ (Tresca, mixed), so Crank–Nicolson's f̄_t = ½(f_t⁰ +
//! f_t¹) is right from step 1 and contract §1.8's invariant holds from t = 0; a node at rest
//! sticks (u_t⁰ = 0, its force the reaction). Then a⁰ on the dofs with inertia from
//! M_ff a⁰_f = (F − K̃u⁰ + contact forces)_f ([`super::load::inertial_solve`]).
//!
//! How: K̃_cc is extracted into its own sparse matrix (the massless dofs only: a layer one
//! element thick) and factored once by sparse Cholesky; the contact problems are condensed onto
//! Γ_C through solves with that factor. Nothing here runs in the time loop.
//!
//! `start = "static"` (contract §1.8, issue 43) replaces that start by the whole body's static
//! state under its load with its contact ([`static_start`]): every dof, not only the massless
//! ones, so a body resting on the plane starts without the bounce an unstressed start gives it.

use std::sync::Arc;

use super::config::{FeConfig, frictional};
use super::geometry::{Geometry, tangential_dofs};
use super::load::inertial_solve;
use super::nitsche::{NewtonWork, NitscheOps, lu_solve, newton};
use crate::contact::friction::FrictionLaw;
use crate::run::Status;
use crate::space::ContactInit;
use crate::space::fe::{Pattern, SymMatrix};
use crate::space::linalg::{Cholesky, SolveWork, SymbolicCholesky};

/// The start of a run whose massless dofs carry load.
#[derive(Debug)]
pub(super) struct Start {
    /// u⁰: the massless dofs' quasi-static values, 0 on the dofs with inertia.
    pub(super) u: Vec<f64>,
    /// a⁰ on the dofs with inertia, 0 on the massless ones.
    pub(super) a: Vec<f64>,
    /// The contact forces at t = 0 in the run's layout: `mixed`, per Γ_C node [f_n, f_t…]
    /// (d per node, node-major); `nitsche`/`penalty`, per point λ_q = w_q f_n (frictionless) or
    /// [λ_n, λ_t…] (frictional, the point-major unknowns of the frictional Newton).
    pub(super) forces: Vec<f64>,
}

/// The status of a run whose start failed: `invalid` where the static start finds no static
/// state to start from (its refusals name `start = "static"`), `solver-failed` otherwise.
pub(super) fn start_failure(message: &str) -> Status {
    if message.starts_with(STATIC) {
        Status::Invalid
    } else {
        Status::SolverFailed
    }
}

/// The prefix of the static start's refusals.
const STATIC: &str = "start = \"static\": ";

/// u⁰, M u⁰ and the contact forces of the start, if it has any.
pub(super) type StartState = (Vec<f64>, Vec<f64>, Option<Vec<f64>>);

/// The state a time loop starts from: (u⁰, M u⁰, the start's forces) with `a` and `ma` = M a
/// replaced, where the quasi-static start applies; (0, 0, None) and both kept otherwise.
#[allow(clippy::too_many_arguments)]
pub(super) fn start_state(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
    nit: Option<&NitscheOps>,
    force: &[f64],
    gaps: &[f64],
    v0: &[f64],
    a: &mut Vec<f64>,
    ma: &mut [f64],
) -> Result<StartState, String> {
    let n = a.len();
    let (mut u, mut mu) = (vec![0.0; n], vec![0.0; n]);
    if cfg.setup.static_start {
        let st = static_start(g, cfg, m, force, gaps, a)?;
        *a = st.a;
        m.matvec_into(&st.u, &mut mu);
        m.matvec_into(a, ma);
        return Ok((st.u, mu, nit.is_none().then_some(st.forces)));
    }
    match quasi_static_start(g, cfg, m, nit, force, gaps, v0, a)? {
        None => Ok((u, mu, None)),
        Some(st) => {
            (u, *a) = (st.u, st.a);
            m.matvec_into(&u, &mut mu);
            m.matvec_into(a, ma);
            Ok((u, mu, Some(st.forces)))
        }
    }
}

/// The static start (contract §1.8 `start = "static"`, issue 43): u⁰ the static state of the
/// body under its loads F with the exact nodal contact of the Γ_C nodes, a⁰ = 0 (up to
/// round-off), so a body resting on the plane starts without the bounce that gravity gives an
/// unstressed start at gap 0 (which makes a Γ_C node's normal force pass through 0 and slip
/// whatever μ_f). Per active node u_d = −g_i with f_n ≥ 0, an inactive node u_d + g_i ≥ 0
/// (Murty's least-index active set on the normal forces, each set one sparse Cholesky of K on
/// the unpinned dofs). Tangentially, with the run's friction, an active node sticks: u_t = 0.
/// That is the well-defined static state: it is the first increment of quasi-static Coulomb
/// (Tresca) friction from the unstressed reference whenever its forces lie in the cone —
/// checked, refused otherwise (the start would slip) — whereas frictionless contact fixes no
/// tangential position of a body held by contact alone (a rigid sliding mode; on an incline no
/// static state at all): frictionless, the start needs a clamp. Nitsche and penalty start from
/// the same state (their own law's static state differs by its regularisation: the penalty's
/// penetration f_n/κ, Nitsche's consistency error), their point forces at t = 0 left to the first
/// step. Returns u⁰, a⁰ and the nodal forces [f_n, f_t…] per Γ_C node.
fn static_start(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
    force: &[f64],
    gaps: &[f64],
    guess: &[f64],
) -> Result<Start, String> {
    let err = |e: &str| format!("{STATIC}{e}");
    if !g.rows.is_unit() {
        return Err(err("two bodies in contact: not implemented yet"));
    }
    let (nc, d) = (g.contact.len(), g.mesh.dim());
    let bound = |i: usize, f_n: f64| match cfg.friction {
        FrictionLaw::Coulomb { coefficient } => coefficient * f_n,
        FrictionLaw::Tresca { threshold } => threshold * g.contact_weight[i] * g.contact_measure,
        FrictionLaw::None => 0.0,
    };
    let stick = match cfg.friction {
        FrictionLaw::Coulomb { coefficient } => coefficient > 0.0,
        FrictionLaw::Tresca { threshold } => threshold > 0.0,
        FrictionLaw::None => false,
    };
    let clamped = g.dofs.n_free() < g.dofs.n_total;
    if !stick && !clamped {
        return Err(err(
            "the body is held by frictionless contact alone, which fixes no position along the plane (and on an incline holds no static state): give the run friction or a clamp, or start at rest",
        ));
    }
    let tangential = if stick {
        tangential_dofs(g)?
    } else {
        Vec::new()
    };
    let mut active: Vec<bool> = gaps.iter().map(|&gap| gap <= 0.0).collect();
    for _ in 0..(100 + 10 * nc) {
        let count = active.iter().filter(|&&a| a).count();
        if !clamped && count < d {
            return Err(err(&format!(
                "{count} Γ_C node(s) on the plane, too few to hold an unclamped body ({d} needed)"
            )));
        }
        let (u, reaction, pinned) = pinned_solve(g, force, gaps, &active, &tangential)?;
        let fscale = reaction
            .iter()
            .fold(f64::MIN_POSITIVE, |s, x| s.max(x.abs()));
        let scale = g
            .contact
            .iter()
            .map(|&c| &u[c])
            .chain(gaps)
            .fold(f64::MIN_POSITIVE, |s, x| s.max(x.abs()));
        let bad = (0..nc).find(|&i| {
            let c = g.contact[i];
            if active[i] {
                reaction[c] < -1e-12 * fscale
            } else {
                u[c] + gaps[i] < -1e-12 * scale
            }
        });
        if let Some(i) = bad {
            active[i] = !active[i];
            continue;
        }
        let mut forces = vec![0.0; nc * d];
        for i in (0..nc).filter(|&i| active[i]) {
            forces[i * d] = reaction[g.contact[i]];
            for (a, &t) in tangential[i * (d - 1)..(i + 1) * (d - 1)]
                .iter()
                .enumerate()
            {
                forces[i * d + 1 + a] = reaction[t];
            }
            let f_t = forces[i * d + 1..(i + 1) * d]
                .iter()
                .map(|x| x * x)
                .sum::<f64>()
                .sqrt();
            let limit = bound(i, forces[i * d]);
            if stick && f_t > limit + 1e-12 * fscale {
                return Err(err(&format!(
                    "the stuck static state is outside the friction cone at Γ_C node {i} (|f_t| = {f_t:e} > {limit:e}, f_n = {:e}): it would slip there (a slipping static start is not implemented); start at rest or raise the friction bound",
                    forces[i * d]
                )));
            }
        }
        // a⁰ from M a⁰ = F − K u⁰ + contact: zero on the pinned rows, round-off elsewhere.
        let r: Vec<f64> = reaction
            .iter()
            .zip(&pinned)
            .map(|(x, &p)| if p { 0.0 } else { -x })
            .collect();
        let a = inertial_solve(m, &r, guess.to_vec())?;
        return Ok(Start { u, a, forces });
    }
    Err(err("the Γ_C contact set did not settle"))
}

/// u, K u − F and which dofs are pinned ([`pinned_solve`]).
type Pinned = (Vec<f64>, Vec<f64>, Vec<bool>);

/// K u = F + reactions with every active Γ_C node pinned: u_d = −g_i, and its `tangential` dofs
/// (empty: frictionless) at 0. Returns u and the residual K u − F (the reactions on the pinned
/// dofs, round-off elsewhere) and which dofs are pinned.
fn pinned_solve(
    g: &Geometry,
    force: &[f64],
    gaps: &[f64],
    active: &[bool],
    tangential: &[usize],
) -> Result<Pinned, String> {
    let n = g.dofs.n_free();
    let d1 = g.mesh.dim() - 1;
    let (mut pinned, mut u) = (vec![false; n], vec![0.0; n]);
    for i in (0..active.len()).filter(|&i| active[i]) {
        pinned[g.contact[i]] = true;
        u[g.contact[i]] = -gaps[i];
        for &t in tangential.get(i * d1..(i + 1) * d1).unwrap_or(&[]) {
            pinned[t] = true;
        }
    }
    let free: Vec<usize> = (0..n).filter(|&j| !pinned[j]).collect();
    let mut kf = factor_massless(g, None, free)
        .map_err(|e| format!("{STATIC}K on the unpinned dofs: {e}"))?;
    let mut r = vec![0.0; n];
    g.k.matvec_into(&u, &mut r);
    let rhs: Vec<f64> = force.iter().zip(&r).map(|(f, k)| f - k).collect();
    for (uj, x) in u.iter_mut().zip(kf.solve(&rhs)) {
        *uj += x;
    }
    g.k.matvec_into(&u, &mut r);
    for (ri, f) in r.iter_mut().zip(force) {
        *ri -= f;
    }
    Ok((u, r, pinned))
}

/// K̃_cc, the run's stiffness on the massless dofs, factored; `index[j]` is dof j's row in it.
struct Massless {
    dofs: Vec<usize>,
    index: Vec<Option<usize>>,
    chol: Cholesky,
    work: SolveWork,
}

impl Massless {
    /// x = K̃_cc⁻¹ r_c, embedded in the free dofs (0 on the dofs with inertia).
    fn solve(&mut self, r: &[f64]) -> Vec<f64> {
        let mut x: Vec<f64> = self.dofs.iter().map(|&j| r[j]).collect();
        self.chol.solve_in_place(&mut x, &mut self.work);
        let mut out = vec![0.0; r.len()];
        for (&j, v) in self.dofs.iter().zip(x) {
            out[j] = v;
        }
        out
    }
}

/// The quasi-static start of `cfg` (module header), or None where u⁰ = 0 is it or is asked
/// for: `contact_init = "interpolant"`, no massless dof, or no load on them (no gravity, or
/// the inertial load, zero on the massless rows). `m` the run's mass, `force` F, `gaps` the
/// Γ_C nodes' gaps, `v0` the initial velocity (the slip direction of a sliding node),
/// `guess` the load's a⁰ (the solve's start).
#[allow(clippy::too_many_arguments)]
pub(super) fn quasi_static_start(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
    nit: Option<&NitscheOps>,
    force: &[f64],
    gaps: &[f64],
    v0: &[f64],
    guess: &[f64],
) -> Result<Option<Start>, String> {
    if cfg.contact_init == ContactInit::Interpolant {
        return Ok(None);
    }
    let diag = m.diagonal();
    let dofs: Vec<usize> = (0..diag.len()).filter(|&j| diag[j] == 0.0).collect();
    if dofs.iter().all(|&j| force[j] == 0.0) {
        return Ok(None);
    }
    let mut ml = factor_massless(g, nit, dofs)
        .map_err(|e| format!("the quasi-static start of the massless dofs: {e}"))?;
    let y = ml.solve(force);
    let (u, contact, forces) = match nit {
        None => mixed_start(g, cfg, &mut ml, force, y, gaps, v0)?,
        Some(ops) => points_start(cfg, ops, &mut ml, force, y, v0)?,
    };
    // a⁰ from M_ff a⁰_f = (F − K̃u⁰ + contact)_f.
    let mut r = vec![0.0; u.len()];
    g.k.matvec_into(&u, &mut r);
    if let Some(ops) = nit {
        theta_terms(ops, |gi, gj, x| r[gi] -= x * u[gj]);
    }
    for ((ri, f), c) in r.iter_mut().zip(force).zip(&contact) {
        *ri = f - *ri + c;
    }
    let a = inertial_solve(m, &r, guess.to_vec())?;
    Ok(Some(Start { u, a, forces }))
}

/// Calls `add(i, j, Θ w_q γ_q σ_i σ_j)` for every entry of Nitsche's −Θ Σ_q w_q γ_q (s_q s_qᵀ +
/// σ_t σ_tᵀ) (to be subtracted; the penalty has Θ = 0 and none).
fn theta_terms(ops: &NitscheOps, mut add: impl FnMut(usize, usize, f64)) {
    if ops.theta == 0.0 {
        return;
    }
    let k = ops.k;
    for q in 0..ops.len() {
        let f = ops.theta * ops.w[q] * ops.gamma[q];
        let d = &ops.dofs[q * k..(q + 1) * k];
        for r in 0..ops.per_point() {
            let s = ops.sigma_row(q, r);
            for (i, &gi) in d.iter().enumerate() {
                for (j, &gj) in d.iter().enumerate() {
                    add(gi, gj, f * s[i] * s[j]);
                }
            }
        }
    }
}

/// K̃ restricted to the massless `dofs`, in its own pattern, factored.
fn factor_massless(
    g: &Geometry,
    nit: Option<&NitscheOps>,
    dofs: Vec<usize>,
) -> Result<Massless, String> {
    let n = g.dofs.n_free();
    let mut index = vec![None; n];
    for (k, &j) in dofs.iter().enumerate() {
        index[j] = Some(k);
    }
    let p = &g.k.pattern;
    let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
    for &j in &dofs {
        for pos in p.col_ptr[j]..p.col_ptr[j + 1] {
            if let Some(i) = index[p.row_idx[pos]] {
                row_idx.push(i);
                values.push(g.k.values[pos]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    let pattern = Arc::new(Pattern::new(dofs.len(), col_ptr, row_idx).map_err(|e| e.to_string())?);
    let mut k = SymMatrix { pattern, values };
    if let Some(ops) = nit {
        theta_terms(ops, |gi, gj, x| {
            if let (Some(i), Some(j)) = (index[gi], index[gj]) {
                let pos = k
                    .pattern
                    .position(i, j)
                    .expect("element dofs are in the pattern");
                k.values[pos] -= x;
            }
        });
    }
    let sym = SymbolicCholesky::new(&k.pattern).map_err(|e| e.to_string())?;
    let chol = Cholesky::new(&sym, &k)
        .map_err(|e| format!("K̃ on the massless dofs is not positive definite: {e}"))?;
    let work = chol.work();
    Ok(Massless {
        dofs,
        index,
        chol,
        work,
    })
}

/// The unit direction of a vector, None if it is zero.
fn direction(v: &[f64]) -> Option<Vec<f64>> {
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (norm > 0.0).then(|| v.iter().map(|x| x / norm).collect())
}

/// What the contact at t = 0 gives: u⁰, the contact forces on the free dofs, and the forces in
/// the run's layout ([`Start::forces`]).
type Solved = (Vec<f64>, Vec<f64>, Vec<f64>);

/// `mixed`: the Γ_C nodes off the plane at y = K̃_cc⁻¹F_c keep u⁰ = y; otherwise the
/// nodal Signorini problem at t = 0 ([`signorini_start`]).
fn mixed_start(
    g: &Geometry,
    cfg: &FeConfig,
    ml: &mut Massless,
    force: &[f64],
    y: Vec<f64>,
    gaps: &[f64],
    v0: &[f64],
) -> Result<Solved, String> {
    let (nc, d) = (g.contact.len(), g.mesh.dim());
    if gaps
        .iter()
        .enumerate()
        .all(|(i, gap)| g.rows.dot(i, &y) + gap >= 0.0)
    {
        let n = y.len();
        return Ok((y, vec![0.0; n], vec![0.0; nc * d]));
    }
    if !g.rows.is_unit() {
        return Err(
            "the quasi-static start: two bodies in contact at t = 0 with massless interface dofs (not yet: issue 44)".into(),
        );
    }
    if let Some(&c) = g.contact.iter().find(|&&c| ml.index[c].is_none()) {
        return Err(format!(
            "the quasi-static start: Γ_C's dof {c} has inertia, the others none"
        ));
    }
    let law = if frictional(cfg) {
        cfg.friction
    } else {
        FrictionLaw::None
    };
    match signorini_start(g, law, ml, force, y.clone(), gaps, v0) {
        // Murty's pivoting is finite for the P-matrices of a small μ_f only; where a large one
        // makes it cycle (μ_f = 5 on a block sliding at t = 0), the start is the frictionless
        // quasi-static state, the sliding nodes' f_t⁰ zero (the first step's f̄_t then misses
        // half a step's friction, as every start did before issue 42).
        Err(e) if e == UNSETTLED && law != FrictionLaw::None => {
            signorini_start(g, FrictionLaw::None, ml, force, y, gaps, v0)
        }
        r => r,
    }
}

/// The error of a Γ_C contact set that cycles instead of settling.
const UNSETTLED: &str = "the quasi-static start: the Γ_C contact set at t = 0 did not settle";

/// The nodal Signorini problem of the massless Γ_C nodes at t = 0, with their friction: per node
/// i the normal force f_n,i ≥ 0 ⊥ u_d,i + g_i ≥ 0; a frictional node sliding at t = 0 has
/// f_t,i = −μ_f f_n,i v̂_i (Coulomb) or −s w_i v̂_i in contact (Tresca), one at rest u_t,i = 0.
/// Condensed through W = C K̃_cc⁻¹ Cᵀ over the normal and tangential rows C (node-major) and
/// solved exactly by Murty's least-index principal pivoting on the active set (finite for
/// the P-matrices of a small μ_f).
fn signorini_start(
    g: &Geometry,
    law: FrictionLaw,
    ml: &mut Massless,
    force: &[f64],
    y: Vec<f64>,
    gaps: &[f64],
    v0: &[f64],
) -> Result<Solved, String> {
    let (n, nc, d) = (y.len(), g.contact.len(), g.mesh.dim());
    let tangential = if law == FrictionLaw::None {
        Vec::new()
    } else {
        tangential_dofs(g)?
    };
    let rows = if tangential.is_empty() { 1 } else { d };
    let dof = |k: usize| {
        let (i, a) = (k / rows, k % rows);
        if a == 0 {
            g.contact[i]
        } else {
            tangential[i * (d - 1) + a - 1]
        }
    };
    let dm = nc * rows;
    let w = condensed(ml, &dof, dm, n);
    // Per node: the slip direction of a sliding node (None: it sticks, or no friction).
    let slip: Vec<Option<Vec<f64>>> = (0..nc)
        .map(|i| {
            let vt: Vec<f64> = (1..rows).map(|a| v0[dof(i * rows + a)]).collect();
            direction(&vt)
        })
        .collect();
    let weight = |i: usize| g.contact_weight[i] * g.contact_measure;
    // The forces (node-major, `rows` per node) of an active set: solve its equations.
    let solve_set = |active: &[bool]| -> Result<Vec<f64>, String> {
        let unknowns: Vec<usize> = (0..dm)
            .filter(|&k| {
                let (i, a) = (k / rows, k % rows);
                active[i] && (a == 0 || (law != FrictionLaw::None && slip[i].is_none()))
            })
            .collect();
        // Column of unknown k over the rows: W's column, with a sliding node's tangential
        // force −μ_f f_n v̂ folded into its normal unknown (Coulomb) or its constant part
        // −s w v̂ moved to the right-hand side (Tresca).
        let column = |k: usize, r: usize| {
            let (i, a) = (k / rows, k % rows);
            let mut x = w[r * dm + k];
            if let (0, Some(t), FrictionLaw::Coulomb { coefficient }) = (a, &slip[i], law) {
                for (b, tb) in t.iter().enumerate() {
                    x -= coefficient * tb * w[r * dm + i * rows + 1 + b];
                }
            }
            x
        };
        let fixed = |r: usize| -> f64 {
            let mut x = 0.0;
            if let FrictionLaw::Tresca { threshold } = law {
                for (i, t) in slip.iter().enumerate() {
                    if let (true, Some(t)) = (active[i], t) {
                        for (b, tb) in t.iter().enumerate() {
                            x -= threshold * weight(i) * tb * w[r * dm + i * rows + 1 + b];
                        }
                    }
                }
            }
            x
        };
        let na = unknowns.len();
        let mut a = vec![0.0; na * na];
        let mut b = vec![0.0; na];
        for (p, &r) in unknowns.iter().enumerate() {
            for (q, &k) in unknowns.iter().enumerate() {
                a[p * na + q] = column(k, r);
            }
            // The target: u_d = −g (normal rows), u_t = 0 (a sticking node's rows).
            let target = if r % rows == 0 { -gaps[r / rows] } else { 0.0 };
            b[p] = target - y[dof(r)] - fixed(r);
        }
        lu_solve(&mut a, na, &mut vec![0; na], &mut b)?;
        let mut f = vec![0.0; dm];
        for (&k, x) in unknowns.iter().zip(b) {
            f[k] = x;
        }
        for (i, t) in slip.iter().enumerate() {
            if let (true, Some(t)) = (active[i], t) {
                let r = match law {
                    FrictionLaw::Coulomb { coefficient } => coefficient * f[i * rows],
                    FrictionLaw::Tresca { threshold } => threshold * weight(i),
                    FrictionLaw::None => 0.0,
                };
                for (b, tb) in t.iter().enumerate() {
                    f[i * rows + 1 + b] = -r * tb;
                }
            }
        }
        Ok(f)
    };
    let scale = gaps
        .iter()
        .chain(g.contact.iter().map(|&c| &y[c]))
        .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    let tol = 1e-12 * scale;
    let mut active: Vec<bool> = g
        .contact
        .iter()
        .zip(gaps)
        .map(|(&c, gap)| y[c] + gap < 0.0)
        .collect();
    for _ in 0..(100 + 10 * nc) {
        let f = solve_set(&active)?;
        // The normal gaps at these forces.
        let gap_of = |i: usize| -> f64 {
            let r = i * rows;
            y[dof(r)] + gaps[i] + (0..dm).map(|k| w[r * dm + k] * f[k]).sum::<f64>()
        };
        let fscale = f.iter().fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
        let bad = (0..nc).find(|&i| {
            if active[i] {
                f[i * rows] < -1e-12 * fscale
            } else {
                gap_of(i) < -tol
            }
        });
        match bad {
            Some(i) => active[i] = !active[i],
            None => {
                // u⁰ = K̃_cc⁻¹(F + Cᵀf)_c.
                let mut contact = vec![0.0; n];
                for (k, fk) in f.iter().enumerate() {
                    contact[dof(k)] += fk;
                }
                let rhs: Vec<f64> = force.iter().zip(&contact).map(|(a, b)| a + b).collect();
                let u = ml.solve(&rhs);
                let mut forces = vec![0.0; nc * d];
                for i in 0..nc {
                    forces[i * d..i * d + rows].copy_from_slice(&f[i * rows..(i + 1) * rows]);
                }
                return Ok((u, contact, forces));
            }
        }
    }
    Err(UNSETTLED.into())
}

/// `nitsche`/`penalty`: the points inactive at y = K̃_cc⁻¹F_c keep u⁰ = y; otherwise the
/// static contact problem K̃_cc u = F_c + (Σ_q φ_q(P_q u) col_q)_c by the steps' semismooth
/// Newton with cτ² = 1, col_q = C's normal column, plus −μ_f v̂_q times its tangential ones
/// at a point sliding at t = 0 (Coulomb; the start of a Tresca point keeps no tangential
/// force).
fn points_start(
    cfg: &FeConfig,
    ops: &NitscheOps,
    ml: &mut Massless,
    force: &[f64],
    y: Vec<f64>,
    v0: &[f64],
) -> Result<Solved, String> {
    let (n, nq) = (y.len(), ops.len());
    let s0: Vec<f64> = (0..nq).map(|q| ops.apply(&ops.p, q, &y)).collect();
    if s0.iter().zip(&ops.gap).all(|(s, g)| s <= g) {
        return Ok((y, vec![0.0; n], vec![0.0; ops.unknowns()]));
    }
    let mu = match (frictional(cfg), cfg.friction) {
        (true, FrictionLaw::Coulomb { coefficient }) => coefficient,
        _ => 0.0,
    };
    match points_solve(ops, ml, force, &y, &s0, mu, v0) {
        // The sliding points' −μ_f v̂ fold makes W unsymmetric; from μ_f ≈ 2 on the block's
        // one-element massless layer (mod3) it is no P-matrix and the semismooth Newton cycles
        // (measured on the campaign's sticking blocks, μ_f = 2.3–5: residuals 1e-4…1e-2 against
        // a scale of 3e-5 after 100 iterations). As mixed's start does where Murty's pivoting
        // cycles ([`mixed_start`]), the start is then the frictionless quasi-static state, the
        // sliding points' f_t⁰ zero (the first step's f̄_t misses half a step's friction).
        Err(_) if mu != 0.0 => points_solve(ops, ml, force, &y, &s0, 0.0, v0),
        r => r,
    }
}

/// [`points_start`]'s static contact problem with the sliding points' coefficient `mu`
/// (0: frictionless), from y = K̃_cc⁻¹F_c and s0 = P y.
fn points_solve(
    ops: &NitscheOps,
    ml: &mut Massless,
    force: &[f64],
    y: &[f64],
    s0: &[f64],
    mu: f64,
    v0: &[f64],
) -> Result<Solved, String> {
    let (n, nq, pp) = (y.len(), ops.len(), ops.per_point());
    // v̂_q, the direction of v⁰_t at a point (its u_t rows applied to v⁰), where μ_f ≠ 0.
    let slip: Vec<Option<Vec<f64>>> = (0..nq)
        .map(|q| {
            let fr = ops.friction.as_ref().filter(|_| mu != 0.0)?;
            let k = ops.k;
            let dofs = &ops.dofs[q * k..(q + 1) * k];
            let vt: Vec<f64> = (0..fr.td)
                .map(|i| {
                    let r = q * fr.td + i;
                    let row = &fr.ut[r * k..(r + 1) * k];
                    row.iter().zip(dofs).map(|(a, &g)| a * v0[g]).sum()
                })
                .collect();
            direction(&vt)
        })
        .collect();
    // Each point's column on the free dofs: its normal column, minus μ_f v̂_q its tangential
    // ones.
    let columns: Vec<Vec<f64>> = (0..nq)
        .map(|q| {
            let mut col = vec![0.0; n];
            let (c, dofs) = ops.c_row(q * pp);
            for (&gd, &x) in dofs.iter().zip(c) {
                col[gd] += x;
            }
            for (i, ti) in slip[q].iter().flatten().enumerate() {
                let (ct, _) = ops.c_row(q * pp + 1 + i);
                for (&gd, &x) in dofs.iter().zip(ct) {
                    col[gd] -= mu * ti * x;
                }
            }
            col
        })
        .collect();
    // W = P K̃_cc⁻¹ col (Q × Q).
    let mut w = vec![0.0; nq * nq];
    for (r, col) in columns.iter().enumerate() {
        let z = ml.solve(col);
        for q in 0..nq {
            w[q * nq + r] = ops.apply(&ops.p, q, &z);
        }
    }
    let mut phi = vec![0.0; nq];
    newton(
        ops,
        &w,
        1.0,
        s0,
        &ops.gap,
        &mut phi,
        &mut NewtonWork::new(nq),
    )
    .map_err(|e| format!("the quasi-static start: {e}"))?;
    let mut contact = vec![0.0; n];
    for (col, f) in columns.iter().zip(&phi) {
        for (c, x) in contact.iter_mut().zip(col) {
            *c += f * x;
        }
    }
    let rhs: Vec<f64> = force.iter().zip(&contact).map(|(a, b)| a + b).collect();
    let u = ml.solve(&rhs);
    // The forces per point along C's columns: λ_n = φ_q, λ_t = −μ_f v̂ φ_q.
    let mut forces = vec![0.0; ops.unknowns()];
    for q in 0..nq {
        forces[q * pp] = phi[q];
    }
    for (q, t) in slip.iter().enumerate() {
        for (i, ti) in t.iter().flatten().enumerate() {
            forces[q * pp + 1 + i] = -mu * ti * phi[q];
        }
    }
    Ok((u, contact, forces))
}

/// W = C K̃_cc⁻¹ Cᵀ (dm × dm, row-major) over the unit rows at `dof(k)`, column by column.
fn condensed(ml: &mut Massless, dof: &dyn Fn(usize) -> usize, dm: usize, n: usize) -> Vec<f64> {
    let mut w = vec![0.0; dm * dm];
    let mut e = vec![0.0; n];
    for s in 0..dm {
        e[dof(s)] = 1.0;
        let z = ml.solve(&e);
        e[dof(s)] = 0.0;
        for r in 0..dm {
            w[r * dm + s] = z[dof(r)];
        }
    }
    w
}
