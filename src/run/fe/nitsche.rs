//! Nitsche's contact term in the sparse engine (contract §2.3, §4; 003 §2): the operators of one
//! run and the per-step semismooth Newton on the condensed problem.
//!
//! With the contact points q of Γ_C ([`crate::space::fe::nitsche`]), weights w_q, γ_q = γ0·h_K,
//! gaps g_q and the rows p_q (P_γ,q(u) = p_q·u = u_n − γ_q σ_n(u)) and t_q (P_Θγ,q(v) = t_q·v),
//! a Newmark/θ step at t^{n+1} reads
//!   A u + cτ² Σ_q φ_q(p_q·u) t_q = M p^n + cτ² F,   A = M + cτ²(K − Θ Σ_q w_q γ_q s_q s_qᵀ),
//! with φ_q(s) = (w_q/γ_q)[s − g_q]_+ and s_q the σ_n rows. A is constant: factored once per
//! run. With y = A⁻¹(M p^n + cτ²F), Z = A⁻¹C, C = [−t_q] (the upward directions) and
//! W = P Z (Q × Q), the unknowns reduce to the Q values s = P u:
//!   G(s) = s − P y − cτ² W φ(s) = 0,   then u = y + cτ² Z φ(s).
//! G is piecewise linear; semismooth Newton with the generalised Jacobian
//! J = I − cτ² W D(s), D = diag((w_q/γ_q) H(s_q − g_q)), restricted to the active points
//! (inactive columns of W D vanish, so only the active block is factored), warm-started from
//! the previous step; tolerance 1e-12 relative to max(|P y|, |g|), at most 100 iterations. The
//! total contact force is Σ_q φ_q (the integral of the pressure −σ_C = (1/γ)[P_γ − g]_+).
//!
//! The hybrid scheme (003 (10)–(11), contract §3) is the midpoint rule with the contact term
//! (1/γ)Φ P_Θγ(v), Φ = H(P̃ⁿ)[(P̃ⁿ + P̃ⁿ⁺¹)/2]_+ + H(−P̃ⁿ)([P̃ⁿ]_+ + [P̃ⁿ⁺¹]_+)/2, P̃ = P_γ − g.
//! Its step matrix is Crank–Nicolson's (c = ¼), and since P̃ⁿ is known, Φ = ½[P̃ⁿ⁺¹ − k]_+ with
//! the kink k = −max(P̃ⁿ, 0) (H(0) = ½ gives the same value as P̃ⁿ < 0): the same Newton with
//! per-step kinks g − max(P̃ⁿ, 0), the factor ½ absorbed by τ²/2·½ = cτ².
//!
//! The penalty (contract §2.4) is the same operator with P = P_Θγ = u_n (Θ = 0, no σ_n term) and
//! 1/γ_q = κ_q = E·γ0/h_K: the force φ_q = w_q κ_q [u_n − g_q]_+, its potential
//! ½Σ w κ [u_n − g]_+² added to E^h ([`NitscheOps::penalty`]).

//!
//! Friction (contract §2.5; [`FrictionOps`]): GetFEM's full-vector Nitsche with Coulomb or Tresca
//! friction. Per point, besides P_γ the d − 1 tangential values
//!   P_t,q(u) = σ_t,q(u) − k_q (u_t,q − u_t,q^n),   k_q = 1/(γ_q τ)  (penalty: k_q = κ_q,
//! σ_t rows 0), and the tangential traction f_t = proj onto the disc of radius r of P_t, with
//! r = μ_f f_n (Coulomb, f_n = (1/γ)[P_γ − g]_+) or r = s while f_n > 0 (Tresca, contract §2.5:
//! acting only in contact). The residual's Θ terms add −cτ²Θ Σ w γ σ_t σ_tᵀ to A (Θ ≠ 0) and
//! the tangential test direction is Θγσ_t(v) − v_t, so C gains the columns u_t − Θγσ_t and P
//! the rows P_t: the condensed unknowns are x = (P_γ, P_t) per point (d of them), W = P A⁻¹C
//! over all of them, λ_q = w_q (f_n, f_t) the point's forces along C's columns, and
//!   G(x) = x − x0 − cτ² W Λ(x) = 0,   x0 = P y (+ k_q u_t^n in the tangential rows).
//! Semismooth Newton with the generalised Jacobian of Λ per point block: ∂λ_n/∂x_n = w/γ when
//! active; in stick (|P_t| ≤ r) ∂λ_t/∂P_t = w I; in slip λ_t = w r P̂_t, whose derivative is
//! w (r/|P_t|)(I − P̂_t P̂_tᵀ) (2D: 0, the clamp) and, for Coulomb, ∂λ_t/∂x_n = w (μ_f/γ) P̂_t.
//! A point without normal contact has λ = 0 and a zero block, so only the active points' d × d
//! blocks enter the dense LU. Large problems (from [`SPARSE_MIN_ACTIVE`] unknowns) make their
//! steps and W Λ in the space of the contact dofs instead ([`super::schur`]): W = P_R S C_R with
//! S = R A⁻¹ Rᵀ, and each Newton step an m × m solve (GMRES with a reused LU). With μ_f = 0 and Θ ≠ 0 this is the full-vector frictionless
//! Nitsche (the Θ terms of σ_t stay), which is why such runs take this path.

use super::schur::{ContactSchur, SchurNewton};
use crate::contact::friction::FrictionLaw;
use crate::contact::lemke;
use crate::run::friction_tally::{FrictionTally, MeanVelocity};
use crate::space::fe::nitsche::ContactPoint;

/// Semismooth Newton: relative tolerance and iteration cap (contract §4).
pub(crate) const NEWTON_TOL: f64 = 1e-12;
pub(crate) const NEWTON_MAX_ITER: usize = 100;
/// The frictional Newton's acceptance at its round-off floor ([`newton_friction`]): where
/// the line search finds no descent, residuals within 1e-8 of their scales are the floor.
/// x_n = P_γ holds the gap (|x_n| ≈ g) while the penetration is orders smaller, and a
/// tangential row's ∂G_t/∂x_n = −cτ² W_tn w/γ carries k = 1/(γτ) from P_t: on bar2d (CN,
/// Nitsche γ0 = 1e-3, x_n ≈ 0.2, penetration 1.8e-8, all points stuck) one ulp of x_n moves
/// G_t by ~1e-11, measured 1.7e-11 against the tolerance 1e-12·0.16; the Newton steps were
/// 1e-17 and the run failed at the iteration cap (`bar2d_stick_newton_stalls_at_its_floor`).
/// 1e-8 leaves a factor ~100 over that floor and still bounds the forces' relative error.
pub(crate) const NEWTON_FLOOR_TOL: f64 = 1e-8;

/// The contact rows of one run (γ0 and Θ applied), flat over the points.
#[derive(Debug)]
pub(crate) struct NitscheOps {
    /// Dofs per point (the element's).
    pub k: usize,
    pub dofs: Vec<usize>,
    /// p_q (P_γ), −t_q (upward direction C), s_q (σ_n), k per point.
    pub p: Vec<f64>,
    pub c: Vec<f64>,
    pub s: Vec<f64>,
    pub w: Vec<f64>,
    pub gamma: Vec<f64>,
    pub gap: Vec<f64>,
    pub theta: f64,
    /// Penalty (contract §2.4) instead of Nitsche: P = u_n, 1/γ_q = κ_q, and the penalty
    /// potential ½Σ w κ [u_n − g]_+² belongs to E^h.
    pub penalty: bool,
    /// The tangential rows of a frictional run (module header); `None` without friction, and
    /// then the unknowns are the Q normal values as before.
    pub friction: Option<FrictionOps>,
}

/// The tangential rows of a frictional run, flat over points and directions (point q's
/// direction i at row q·(d − 1) + i, each row k long over the point's dofs).
#[derive(Debug)]
pub(crate) struct FrictionOps {
    /// Tangential directions per point, d − 1.
    pub td: usize,
    /// u_t (the e_i component of u at the point).
    pub ut: Vec<f64>,
    /// σ_t (Nitsche; zero for the penalty), for A's Θ term.
    pub st: Vec<f64>,
    /// P_t's linear part σ_t − k u_t.
    pub pt: Vec<f64>,
    /// C's tangential columns u_t − Θγσ_t (the traction's direction on the body).
    pub ct: Vec<f64>,
    /// k_q = 1/(γ_q τ) (Nitsche) or κ_q (penalty), per point.
    pub kt: Vec<f64>,
}

impl NitscheOps {
    /// From the points computed with γ0 = 1 (their `gamma` is h_K) and the run's Θ, γ0.
    pub fn new(points: &[ContactPoint], theta: f64, gamma0: f64) -> NitscheOps {
        let k = points.first().map_or(0, |p| p.dofs.len());
        let mut o = NitscheOps {
            k,
            dofs: Vec::with_capacity(points.len() * k),
            p: Vec::with_capacity(points.len() * k),
            c: Vec::with_capacity(points.len() * k),
            s: Vec::with_capacity(points.len() * k),
            w: Vec::with_capacity(points.len()),
            gamma: Vec::with_capacity(points.len()),
            gap: Vec::with_capacity(points.len()),
            theta,
            penalty: false,
            friction: None,
        };
        for pt in points {
            let g = gamma0 * pt.gamma;
            o.dofs.extend_from_slice(&pt.dofs);
            for (un, sn) in pt.un.iter().zip(&pt.sn) {
                o.p.push(un - g * sn);
                o.c.push(-(un - theta * g * sn));
                o.s.push(*sn);
            }
            o.w.push(pt.weight);
            o.gamma.push(g);
            o.gap.push(pt.gap);
        }
        o
    }

    /// The penalty of contract §2.4 as the same operators: κ_q = E·γ0/h_K with E Young's modulus
    /// and h_K the point's element diameter (the h of Nitsche's γ_h = γ0·h_K), and P_q = t_q =
    /// u_n, Θ = 0 — Nitsche's rows with γ = 0 — so φ_q(s) = w_q κ_q [s − g_q]_+ is the penalty
    /// force and the Newton, the step matrix and the hybrid kinks are unchanged.
    pub fn penalty(points: &[ContactPoint], young: f64, gamma0: f64) -> NitscheOps {
        // γ = 0 in the rows: p = u_n, c = −u_n exactly.
        let mut o = NitscheOps::new(points, 0.0, 0.0);
        o.penalty = true;
        for (g, pt) in o.gamma.iter_mut().zip(points) {
            // 1/κ_q stored as γ_q (h_K is the points' γ with γ0 = 1).
            *g = pt.gamma / (young * gamma0);
        }
        o
    }

    /// The tangential rows for friction with step τ (module header): from the same points
    /// as [`NitscheOps::new`] or [`NitscheOps::penalty`] (their γ_q already set).
    pub fn with_friction(mut self, points: &[ContactPoint], tau: f64) -> NitscheOps {
        let k = self.k;
        let td = points.first().map_or(0, |p| p.ut.len() / k.max(1));
        let rows = points.len() * td * k;
        let mut f = FrictionOps {
            td,
            ut: Vec::with_capacity(rows),
            st: Vec::with_capacity(rows),
            pt: Vec::with_capacity(rows),
            ct: Vec::with_capacity(rows),
            kt: Vec::with_capacity(points.len()),
        };
        for (q, p) in points.iter().enumerate() {
            let g = self.gamma[q];
            // Penalty: f_t = proj(−κ Δu_t), no σ_t; Nitsche: σ_t − Δu_t/(γτ).
            let (kq, sig) = if self.penalty {
                (1.0 / g, 0.0)
            } else {
                (1.0 / (g * tau), 1.0)
            };
            f.kt.push(kq);
            for (u, st) in p.ut.iter().zip(&p.st) {
                let st = sig * st;
                f.ut.push(*u);
                f.st.push(st);
                f.pt.push(st - kq * u);
                f.ct.push(u - self.theta * g * st);
            }
        }
        self.friction = Some(f);
        self
    }

    pub fn len(&self) -> usize {
        self.w.len()
    }

    /// Unknowns per point: 1 (frictionless) or d (normal and tangential).
    pub fn per_point(&self) -> usize {
        1 + self.friction.as_ref().map_or(0, |f| f.td)
    }

    /// The condensed unknowns: Q, or Q·d with friction.
    pub fn unknowns(&self) -> usize {
        self.len() * self.per_point()
    }

    /// Unknown j's row of P (P_γ or P_t's linear part) and column of C, over its point's dofs.
    pub fn p_row(&self, j: usize) -> (&[f64], &[usize]) {
        self.rows(j, false)
    }

    pub fn c_row(&self, j: usize) -> (&[f64], &[usize]) {
        self.rows(j, true)
    }

    fn rows(&self, j: usize, c: bool) -> (&[f64], &[usize]) {
        let d = self.per_point();
        let (q, a) = (j / d, j % d);
        let dofs = self.row(&self.dofs, q);
        let k = self.k;
        let row = match (&self.friction, a) {
            (_, 0) => self.row(if c { &self.c } else { &self.p }, q),
            (Some(f), a) => {
                let r = q * f.td + a - 1;
                &(if c { &f.ct } else { &f.pt })[r * k..(r + 1) * k]
            }
            (None, _) => unreachable!("one unknown per point without friction"),
        };
        (row, dofs)
    }

    /// Point q's stress row r: σ_n (r = 0) or, with friction, σ_t along direction r − 1 — the
    /// rows of the step matrix's Θ-term −Θ Σ w γ (s sᵀ + σ_t σ_tᵀ) (the engine's `factor_nitsche`).
    pub fn sigma_row(&self, q: usize, r: usize) -> &[f64] {
        match (&self.friction, r) {
            (_, 0) => self.row(&self.s, q),
            (Some(f), r) => {
                let i = q * f.td + r - 1;
                &f.st[i * self.k..(i + 1) * self.k]
            }
            (None, _) => unreachable!("one stress row per point without friction"),
        }
    }

    fn row<'a, T>(&self, v: &'a [T], q: usize) -> &'a [T] {
        &v[q * self.k..(q + 1) * self.k]
    }

    /// row_q · u for the rows `v` (p, c or s).
    pub fn apply(&self, v: &[f64], q: usize, u: &[f64]) -> f64 {
        self.row(v, q)
            .iter()
            .zip(self.row(&self.dofs, q))
            .map(|(a, &g)| a * u[g])
            .sum()
    }

    /// The contact terms of the energies at u and the total contact force Σ φ_q(P_q(u)):
    /// Nitsche: (0, E_Θ − E^h = −(Θ/2)(Σ w γ σ_n² − Σ (w/γ)[P_γ − g]_+²), force) (contract §2.3);
    /// penalty: (½ Σ w κ [u_n − g]_+², the part of E^h, no E_Θ, force) (contract §2.4).
    pub fn energy_terms_and_force(&self, u: &[f64]) -> (f64, Option<f64>, f64) {
        let (mut a, mut b, mut f) = (0.0, 0.0, 0.0);
        for q in 0..self.len() {
            if !self.penalty {
                let sn = self.apply(&self.s, q, u);
                a += self.w[q] * self.gamma[q] * sn * sn;
            }
            let pg = (self.apply(&self.p, q, u) - self.gap[q]).max(0.0);
            b += self.w[q] / self.gamma[q] * pg * pg;
            f += self.w[q] / self.gamma[q] * pg;
        }
        if self.penalty {
            (0.5 * b, None, f)
        } else {
            (0.0, Some(-0.5 * self.theta * (a - b)), f)
        }
    }
}

/// Scratch of the Newton iteration, allocated once per run.
#[derive(Debug)]
pub(crate) struct NewtonWork {
    s: Vec<f64>,
    g: Vec<f64>,
    delta: Vec<f64>,
    active: Vec<usize>,
    /// The points with φ_q ≠ 0: the only columns of W a residual reads.
    nonzero: Vec<usize>,
    jac: Vec<f64>,
    perm: Vec<usize>,
    /// Friction only ([`NewtonWork::frictional`]): the points' d × d derivative blocks, which
    /// points are in normal contact, and D δ over the active unknowns.
    blocks: Vec<f64>,
    point_active: Vec<bool>,
    d_delta: Vec<f64>,
    /// The full Newton step and the iterate it starts from (the line search's).
    step: Vec<f64>,
    x_old: Vec<f64>,
    /// Large frictional problems: the Newton steps in the contact dofs' space ([`SchurNewton`]).
    schur: Option<SchurNewton>,
    /// The last forces a [`continuation`] stage solved for, and those of its narrowest
    /// Tresca ramp before a restart.
    lambda_ok: Vec<f64>,
    lambda_best: Vec<f64>,
    /// The iterations of [`newton_friction`]'s stages over the run: from the previous forces,
    /// from rest, the continuation in the bound, Gauss–Seidel's sweeps, its Newton polish,
    /// Lemke's pivots with their Newton polish.
    pub stages: [usize; 6],
    /// Whether [`lemke_stage`] has solved a step of this run: it is then tried right after the
    /// Newton from rest ([`newton_friction`]).
    lemke_first: bool,
}

impl NewtonWork {
    pub fn new(nq: usize) -> NewtonWork {
        NewtonWork {
            s: vec![f64::NEG_INFINITY; nq],
            g: vec![0.0; nq],
            delta: vec![0.0; nq],
            active: Vec::with_capacity(nq),
            nonzero: Vec::with_capacity(nq),
            jac: vec![0.0; nq * nq],
            perm: vec![0; nq],
            blocks: Vec::new(),
            point_active: Vec::new(),
            d_delta: Vec::new(),
            step: Vec::new(),
            x_old: Vec::new(),
            schur: None,
            lambda_ok: Vec::new(),
            lambda_best: Vec::new(),
            stages: [0; 6],
            lemke_first: false,
        }
    }

    /// The next [`newton`] starts from s0 (its first step's start), not from this iterate.
    pub fn restart(&mut self) {
        self.s.fill(f64::NEG_INFINITY);
    }

    /// The frictional Newton's scratch: `nu` unknowns in points of `d` ([`newton_friction`]).
    pub fn frictional(nu: usize, d: usize) -> NewtonWork {
        let mut w = NewtonWork::new(nu);
        w.blocks = vec![0.0; nu * d];
        w.point_active = vec![false; nu / d.max(1)];
        w.d_delta = vec![0.0; nu];
        w.step = vec![0.0; nu];
        w.x_old = vec![0.0; nu];
        w.lambda_ok = vec![0.0; nu];
        w.lambda_best = vec![0.0; nu];
        w
    }

    /// The workspace a run's contact solve needs: none for mixed (`ops` None), the frictional
    /// one (with the Newton in the contact dofs' space where `schur` is at hand,
    /// [`NewtonWork::frictional_for`]) or the frictionless one.
    pub fn for_run(
        ops: Option<&NitscheOps>,
        schur: Option<&ContactSchur>,
    ) -> Result<NewtonWork, String> {
        match ops {
            Some(o) if o.friction.is_some() => NewtonWork::frictional_for(o, schur),
            _ => Ok(NewtonWork::new(ops.map_or(0, NitscheOps::len))),
        }
    }

    /// [`NewtonWork::frictional`] for the rows `ops`, with the Newton steps through S = R A⁻¹ Rᵀ
    /// ([`SchurNewton`]) where the run made it (its active set can reach [`SPARSE_MIN_ACTIVE`]).
    pub fn frictional_for(
        ops: &NitscheOps,
        schur: Option<&ContactSchur>,
    ) -> Result<NewtonWork, String> {
        let mut w = NewtonWork::frictional(ops.unknowns(), ops.per_point());
        if let Some(s) = schur {
            let nu = ops.unknowns();
            let (mut prow, mut crow) = (
                Vec::with_capacity(nu * ops.k),
                Vec::with_capacity(nu * ops.k),
            );
            for j in 0..nu {
                prow.extend_from_slice(ops.p_row(j).0);
                crow.extend_from_slice(ops.c_row(j).0);
            }
            w.schur = Some(SchurNewton::new(
                s.clone(),
                ops.k,
                ops.per_point(),
                prow,
                crow,
            )?);
        }
        Ok(w)
    }

    /// [`Self::stages`] as the run record's three stage columns: the Newton from the previous
    /// forces and from rest, the continuation, the fallbacks (Gauss–Seidel's sweeps, Lemke's
    /// pivots, with their polish).
    pub fn stage_columns(&self) -> [usize; 3] {
        let s = self.stages;
        [s[0] + s[1], s[2], s[3] + s[4] + s[5]]
    }

    /// The Newton's linear solves over the run, when made in the contact dofs' space: (K's
    /// factorisations, GMRES iterations) ([`SchurNewton`]).
    #[cfg(test)]
    pub fn schur_counts(&self) -> Option<(usize, usize)> {
        self.schur.as_ref().map(|s| (s.refactors, s.krylov))
    }
}

/// One point's forces λ_q = w (f_n, f_t) at x_q = (P_γ, P_t) and their derivative block
/// D[b][a] = ∂λ_b/∂x_a (module header). Returns whether the point is in normal contact and
/// whether it slides (the projection is active).
#[allow(clippy::too_many_arguments)]
pub(super) fn point_forces(
    x: &[f64],
    gap: f64,
    w: f64,
    gamma: f64,
    law: FrictionLaw,
    ramp: f64,
    lambda: &mut [f64],
    block: &mut [f64],
) -> (bool, bool) {
    let d = x.len();
    block.iter_mut().for_each(|b| *b = 0.0);
    let pen = x[0] - gap;
    if pen <= 0.0 {
        lambda.iter_mut().for_each(|l| *l = 0.0);
        return (false, false);
    }
    let f_n = pen / gamma;
    lambda[0] = w * f_n;
    block[0] = w / gamma;
    // The disc's radius and its derivative in x_n.
    let (r, dr) = match law {
        FrictionLaw::Coulomb { coefficient } => (coefficient * f_n, coefficient / gamma),
        // Tresca's onset ramp (`ramp` > 0, [`newton_friction`]'s fallback): s·min(1, pen/ramp).
        FrictionLaw::Tresca { threshold } if pen < ramp => {
            (threshold * pen / ramp, threshold / ramp)
        }
        FrictionLaw::Tresca { threshold } => (threshold, 0.0),
        FrictionLaw::None => (0.0, 0.0),
    };
    let z = &x[1..];
    let norm = z.iter().map(|v| v * v).sum::<f64>().sqrt();
    if r <= 0.0 {
        lambda[1..].iter_mut().for_each(|l| *l = 0.0);
        return (true, false);
    }
    if norm <= r {
        for i in 0..d - 1 {
            lambda[1 + i] = w * z[i];
            block[(1 + i) * d + 1 + i] = w;
        }
        return (true, false);
    }
    let s = r / norm;
    for i in 0..d - 1 {
        let zi = z[i] / norm;
        lambda[1 + i] = w * r * zi;
        block[(1 + i) * d] = w * dr * zi;
        for j in 0..d - 1 {
            let delta = if i == j { 1.0 } else { 0.0 };
            block[(1 + i) * d + 1 + j] = w * s * (delta - zi * z[j] / norm);
        }
    }
    (true, true)
}

/// Tolerances and weights of one frictional solve ([`newton_friction`]).
struct Scales {
    /// max(|x0_n|, |g|): the normal rows' scale.
    n: f64,
    /// max |x0_t|: the tangential rows' fixed scale (the merit's weight).
    t0: f64,
    /// Tresca's onset ramp width in x_n − g (0: the literal law; [`newton_friction`]).
    ramp: f64,
}

/// Λ(x), the blocks, G(x) into `work` at x = `work.s`; returns the residual's sizes
/// ([`Residuals`]: max |G_n| relative, max |G_t|, the tangential rows' scale
/// max(|x0_t|, |x_t|, Σ_r |cτ² W_jr Λ_r|), the merit Σ (G/scale)² with the fixed scales).
#[allow(clippy::too_many_arguments)]
fn evaluate(
    ops: &NitscheOps,
    law: FrictionLaw,
    w: &[f64],
    c_tau2: f64,
    x0: &[f64],
    sc: &Scales,
    lambda: &mut [f64],
    slides: &mut [bool],
    work: &mut NewtonWork,
) -> Residuals {
    let (nq, d) = (ops.len(), ops.per_point());
    let nu = nq * d;
    work.nonzero.clear();
    work.active.clear();
    for q in 0..nq {
        let (on, slide) = point_forces(
            &work.s[q * d..(q + 1) * d],
            ops.gap[q],
            ops.w[q],
            ops.gamma[q],
            law,
            sc.ramp,
            &mut lambda[q * d..(q + 1) * d],
            &mut work.blocks[q * d * d..(q + 1) * d * d],
        );
        work.point_active[q] = on;
        slides[q] = slide;
        if on {
            work.active.extend(q * d..(q + 1) * d);
            work.nonzero
                .extend((q * d..(q + 1) * d).filter(|&r| lambda[r] != 0.0));
        }
    }
    // W Λ in the contact dofs' space on large problems ([`SchurNewton::apply_w`]): the
    // terms' sizes are then bounds (`Residuals::strict`).
    if let Some(sn) = work.schur.as_mut() {
        sn.apply_w(lambda, &work.nonzero);
    }
    let (mut res_n, mut res_t, mut scale_t, mut merit) = (0.0f64, 0.0f64, sc.t0, 0.0);
    let (mut n_strict, mut t_strict) = (0.0f64, sc.t0);
    for j in 0..nu {
        // (WΛ)_j and Σ_r |W_jr Λ_r|: the size of the terms the sum cancels (its rounding).
        let (wl, wabs) = match &work.schur {
            Some(sn) => (sn.wl[j], sn.wabs[j]),
            None => {
                let row = &w[j * nu..(j + 1) * nu];
                let (mut wl, mut wabs) = (0.0, 0.0);
                for &r in &work.nonzero {
                    let t = row[r] * lambda[r];
                    wl += t;
                    wabs += t.abs();
                }
                (wl, wabs)
            }
        };
        let (wl, wabs) = (c_tau2 * wl, c_tau2 * wabs);
        let g = work.s[j] - x0[j] - wl;
        work.g[j] = g;
        if j % d == 0 {
            // Relative to the fixed normal scale, or to the terms if they are larger.
            res_n = res_n.max(g.abs() * (sc.n / sc.n.max(wabs)));
            n_strict = n_strict.max(g.abs());
            merit += (g / sc.n).powi(2);
        } else {
            res_t = res_t.max(g.abs());
            scale_t = scale_t.max(work.s[j].abs()).max(wabs);
            t_strict = t_strict.max(work.s[j].abs());
            merit += (g / sc.t0).powi(2);
        }
    }
    Residuals {
        n: res_n,
        t: res_t,
        scale_t,
        merit,
        strict: work.schur.is_some().then_some((n_strict, t_strict)),
    }
}

/// The residual's sizes at an iterate ([`evaluate`]): max_j |G_j| over the normal rows
/// relative as [`newton_friction`] states, max |G_t|, the tangential rows' scale and the
/// merit. Where W Λ was made in the contact dofs' space ([`SchurNewton::apply_w`]) the terms'
/// sizes Σ_r |W_jr Λ_r| are bounds from above: `n` and `scale_t` are then the most lenient
/// values the exact sizes can give, and `strict` holds the least lenient ones (the sizes 0);
/// [`passes`] decides with the exact sizes where the two disagree.
#[derive(Clone, Copy, Debug)]
struct Residuals {
    n: f64,
    t: f64,
    scale_t: f64,
    merit: f64,
    strict: Option<(f64, f64)>,
}

/// Whether `test(res_n, res_t, scale_t)` holds — monotone: easier for a smaller `res_n`, a
/// larger `scale_t` — at the exact residual sizes. With bounds ([`Residuals`]) the test at
/// the lenient values failing or at the strict ones holding decides; between them the exact
/// sizes are made from W's rows (once, then kept in `r`).
fn passes(
    r: &mut Residuals,
    p: &Problem,
    sc: &Scales,
    lambda: &[f64],
    work: &NewtonWork,
    test: impl Fn(f64, f64, f64) -> bool,
) -> bool {
    let Some((n_strict, t_strict)) = r.strict else {
        return test(r.n, r.t, r.scale_t);
    };
    if !test(r.n, r.t, r.scale_t) {
        return false;
    }
    if test(n_strict, r.t, t_strict) {
        return true;
    }
    (r.n, r.scale_t) = exact_sizes(p, sc, lambda, work);
    r.strict = None;
    test(r.n, r.t, r.scale_t)
}

/// The relative normal residual and the tangential scale of [`evaluate`] with the exact
/// Σ_r |cτ² W_jr Λ_r| from W's rows, at the residual `work.g` (the same sums as the dense
/// evaluation's: the zero forces add exact zeros).
fn exact_sizes(p: &Problem, sc: &Scales, lambda: &[f64], work: &NewtonWork) -> (f64, f64) {
    let nu = p.ops.unknowns();
    let d = p.ops.per_point();
    let (mut res_n, mut scale_t) = (0.0f64, sc.t0);
    for j in 0..nu {
        let row = &p.w[j * nu..(j + 1) * nu];
        let wabs = p.c_tau2
            * row
                .iter()
                .zip(lambda)
                .map(|(a, l)| (a * l).abs())
                .sum::<f64>();
        let g = work.g[j];
        if j % d == 0 {
            res_n = res_n.max(g.abs() * (sc.n / sc.n.max(wabs)));
        } else {
            scale_t = scale_t.max(work.s[j].abs()).max(wabs);
        }
    }
    (res_n, scale_t)
}

/// The frictional condensed problem G(x) = x − x0 − cτ² W Λ(x) = 0 (module header) over the
/// Q·d unknowns (point-major), the normal kinks the gaps. `lambda` holds the previous step's
/// forces on entry (the warm start x = x0 + cτ²Wλ) and Λ(x) on return; `slides` receives
/// whether each point slides. Tolerance 1e-12 relative, per kind of unknown: the normal rows
/// against max(|x0_n|, |g|) as the frictionless Newton, the tangential rows (a traction, not
/// a length) against the largest of |x0_t|, |x_t| and Σ_r |cτ² W_jr Λ_r| — the terms they
/// cancel, whose rounding a normal force's coupling into a tangential row can leave at 1e-11
/// of a tiny |x_t| (measured on bar2d: a 2.97e-11 floor that never met 1e-12·max|x_t|); the
/// normal rows likewise when those terms exceed max(|x0_n|, |g|). The full semismooth step can cycle: in 2D a sliding point's force w r sign(P_t) has a zero
/// derivative in P_t, so a step that flips the sign is not seen coming, and the next flips it
/// back (measured on the disc thrown obliquely: a 2-cycle from the second contact step). So
/// each step is damped by backtracking on the merit Σ (G/scale)² (halving up to 30 times):
/// a shorter step lands in the stick band |P_t| ≤ r, whose Jacobian is exact. Where no
/// halving descends, the iterate is at the round-off floor (accepted within
/// [`NEWTON_FLOOR_TOL`]) or on a kink of Λ, which the full step leaves.
/// Returns the iteration count. Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub(crate) fn newton_friction(
    ops: &NitscheOps,
    law: FrictionLaw,
    w: &[f64],
    c_tau2: f64,
    x0: &[f64],
    lambda: &mut [f64],
    slides: &mut [bool],
    work: &mut NewtonWork,
) -> Result<usize, String> {
    // The damped Newton can settle on a local minimum of its merit that is no root (measured
    // on the sliding block, Nitsche Θ = 0 + backward Euler, as it comes to rest at t = 25.75:
    // merit 0.25, a tangential residual 3.2 against its scale 35, every point active, the
    // steps' sizes 2 for 100 iterations) — the 2D law's sign flips between stick and reverse
    // slip. Started cold (λ = 0: x = x0, the free predictor) it converges (in ≤ 69 more
    // iterations on the block's runs); the counts of both attempts are reported
    // (`backward_euler_stops_the_block_at_the_rigid_time`).
    let p = Problem { ops, w, c_tau2, x0 };
    let first = match newton_friction_from(&p, law, 0.0, lambda, slides, work) {
        Ok(it) => {
            work.stages[0] += it;
            return Ok(it);
        }
        Err(e) => e,
    };
    work.stages[0] += NEWTON_MAX_ITER;
    lambda.iter_mut().for_each(|l| *l = 0.0);
    if let Ok(it) = newton_friction_from(&p, law, 0.0, lambda, slides, work) {
        work.stages[1] += it;
        return Ok(it + NEWTON_MAX_ITER);
    }
    work.stages[1] += NEWTON_MAX_ITER;
    // A run whose step only Lemke solved ([`lemke_stage`]) tries it next from then on: its
    // later steps are new numbers anyway (the run ended `solver-failed` before that stage
    // existed), and where the continuation and Gauss–Seidel failed once they tend to fail
    // again, at ~4 000 iterations a step (measured on the campaign's block on the 18°
    // incline, Nitsche γ0 = 1e-4, μ_f 4.15: 92 000 iterations over the run). Runs that never
    // needed it keep their stages' order, hence their bits.
    let tried = work.lemke_first;
    if tried {
        let before = work.stages[5];
        if lemke_stage(&p, law, lambda, slides, work).is_ok() {
            return Ok(2 * NEWTON_MAX_ITER + work.stages[5] - before);
        }
    }
    let mut spent = 0;
    let second = match continuation(&p, law, lambda, slides, work, &mut spent) {
        Ok(()) => {
            work.stages[2] += spent;
            return Ok(spent + 2 * NEWTON_MAX_ITER);
        }
        Err(e) => e,
    };
    work.stages[2] += spent;
    // The fallbacks' iterations: Gauss–Seidel's sweeps and polish, then Lemke's pivots and
    // polish (where Gauss–Seidel fails too, 2D).
    let fallback = |w: &NewtonWork| w.stages[3] + w.stages[4] + w.stages[5];
    let before = fallback(work);
    let gs = gauss_seidel(&p, law, lambda, slides, work);
    let gs = match gs {
        Ok(()) => Ok(()),
        Err(e) if tried => Err(format!(
            "Gauss–Seidel: {e}; Lemke failed before the continuation"
        )),
        Err(e) => lemke_stage(&p, law, lambda, slides, work)
            .map_err(|l| format!("Gauss–Seidel: {e}; {l}")),
    };
    match gs {
        Ok(()) => Ok(spent + 2 * NEWTON_MAX_ITER + fallback(work) - before),
        Err(e) => Err(format!("{first}; continuation in the bound: {second}; {e}")),
    }
}

/// Widths of Tresca's onset ramp [`lemke_stage`] tries, relative to the normal scale: the
/// narrowest the continuation aims at ([`NEWTON_TOL`]), then wider ones down to the floor's
/// ([`NEWTON_FLOOR_TOL`]) — contract §2.5's closure of a grazing point within its tolerance.
/// And the perturbations of q ([`crate::contact::lemke`]'s header): the smaller first.
const LEMKE_RAMPS: [f64; 3] = [NEWTON_TOL, 1e-10, NEWTON_FLOOR_TOL];
const LEMKE_PERTURBATIONS: [f64; 2] = [1e-9, 1e-6];

/// [`newton_friction`]'s last stage in 2D, where Gauss–Seidel failed as well: Lemke's
/// complementary pivoting on the step's LCP ([`crate::contact::lemke`]), which follows the
/// solution path through the folds that stall the continuation in the bound (measured on the
/// issue 43 campaign: Nitsche γ0 = 1e-4 and the penalty γ0 = 1e3 at μ_f 3.4–4.6, and Tresca
/// s ≈ the weight with HHT — every step solved). Its forces start the full Newton
/// ([`newton_friction_from`]) on the exact law (Tresca: with the ramp), and only that Newton's
/// convergence to its tolerance ends the stage. Counts pivots and Newton iterations into the
/// stages. Allocates the LCP (a rescue, not a step's path).
fn lemke_stage(
    p: &Problem,
    law: FrictionLaw,
    lambda: &mut [f64],
    slides: &mut [bool],
    work: &mut NewtonWork,
) -> Result<(), String> {
    let ops = p.ops;
    if ops.per_point() != 2 {
        return Err("Lemke: 2D only".into());
    }
    let sc = scales(ops, p.x0, 0.0);
    let lcp = lemke::Frictional2d {
        gap: &ops.gap,
        w: &ops.w,
        gamma: &ops.gamma,
        wm: p.w,
        c_tau2: p.c_tau2,
        x0: p.x0,
    };
    let attempts: Vec<(lemke::Bound, f64)> = match law {
        FrictionLaw::Coulomb { coefficient } => {
            vec![(lemke::Bound::Coulomb { mu: coefficient }, 0.0)]
        }
        FrictionLaw::Tresca { threshold } => LEMKE_RAMPS
            .iter()
            .map(|r| {
                let width = r * sc.n;
                (lemke::Bound::TrescaRamp { threshold, width }, width)
            })
            .collect(),
        FrictionLaw::None => return Err("Lemke: no friction".into()),
    };
    let mut last = String::from("Lemke: not tried");
    for (bound, ramp) in attempts {
        for perturb in LEMKE_PERTURBATIONS {
            match lemke::solve_2d(&lcp, bound, perturb) {
                Ok((forces, pivots)) => {
                    work.stages[5] += pivots;
                    lambda.copy_from_slice(&forces);
                    match newton_friction_from(p, law, ramp, lambda, slides, work) {
                        Ok(it) => {
                            work.stages[5] += it;
                            work.lemke_first = true;
                            return Ok(());
                        }
                        Err(e) => {
                            work.stages[5] += NEWTON_MAX_ITER;
                            last = format!("Lemke's start: {e}");
                        }
                    }
                }
                Err(e) => last = e,
            }
        }
    }
    Err(last)
}

/// Sweeps of [`gauss_seidel`] at most, and how often its Newton polish is tried.
const GS_MAX_SWEEPS: usize = 400;
const GS_POLISH_EVERY: usize = 20;

/// [`newton_friction`]'s last stage, where the continuation stalled too (measured on the
/// campaign's sticking blocks, Nitsche γ0 = 1e-4 and penalty γ0 = 1e3 at μ_f 3–5: the Newton
/// of a bound t·μ_f fails however close t is to the last solved one — the solution path
/// folds): projected block Gauss–Seidel on the law itself, as mixed's rescue
/// ([`crate::contact::FrictionalContact`]). Point by point, the others' forces held, the
/// point's d unknowns solve x_q = b_q + cτ² W_qq Λ_q(x_q), b_q = x0_q + cτ² Σ_{r≠q} W_qr λ_r
/// — a d × d semismooth Newton with backtracking on |G_q|, whose W_qq block makes it a
/// monotone local problem — and the other points' x follow the change of λ_q. Each sweep is a
/// descent on the stick problem, slow but not cycling; every [`GS_POLISH_EVERY`] sweeps the
/// full Newton ([`newton_friction_from`]) is started from its forces, and only its convergence
/// (to [`NEWTON_TOL`], the primary Newton's test) ends the stage. Counts sweeps and polish
/// iterations into the stages.
fn gauss_seidel(
    p: &Problem,
    law: FrictionLaw,
    lambda: &mut [f64],
    slides: &mut [bool],
    work: &mut NewtonWork,
) -> Result<(), String> {
    let (nq, d) = (p.ops.len(), p.ops.per_point());
    let nu = nq * d;
    lambda.copy_from_slice(&work.lambda_ok);
    let mut last = String::new();
    for sweep in 1..=GS_MAX_SWEEPS {
        // x = x0 + cτ² W λ, made afresh each sweep (the Newton polish overwrites it).
        for j in 0..nu {
            let row = &p.w[j * nu..(j + 1) * nu];
            let wl: f64 = row.iter().zip(&*lambda).map(|(a, l)| a * l).sum();
            work.s[j] = p.x0[j] + p.c_tau2 * wl;
        }
        for q in 0..nq {
            slides[q] = relax_point(p, law, q, lambda, work);
        }
        work.stages[3] += 1;
        if sweep % GS_POLISH_EVERY == 0 || sweep == GS_MAX_SWEEPS {
            work.lambda_best.copy_from_slice(lambda);
            match newton_friction_from(p, law, 0.0, lambda, slides, work) {
                Ok(it) => {
                    work.stages[4] += it;
                    return Ok(());
                }
                Err(e) => {
                    work.stages[4] += NEWTON_MAX_ITER;
                    lambda.copy_from_slice(&work.lambda_best);
                    last = e;
                }
            }
        }
    }
    Err(format!("{GS_MAX_SWEEPS} sweeps: {last}"))
}

/// One point's block of a [`gauss_seidel`] sweep: solve its d unknowns with the others'
/// forces held, update λ_q and every x_j by cτ² W_jq Δλ_q. Returns whether it slides.
fn relax_point(
    p: &Problem,
    law: FrictionLaw,
    q: usize,
    lambda: &mut [f64],
    work: &mut NewtonWork,
) -> bool {
    let (ops, c) = (p.ops, p.c_tau2);
    let d = ops.per_point();
    let nu = ops.unknowns();
    let base = q * d;
    // The point's block cτ² W_qq and b = x_q − cτ² W_qq λ_q (the others' part).
    let (mut wqq, mut b, mut x, mut old) = ([0.0; 9], [0.0; 3], [0.0; 3], [0.0; 3]);
    for a in 0..d {
        old[a] = lambda[base + a];
        x[a] = work.s[base + a];
        for e in 0..d {
            wqq[a * d + e] = c * p.w[(base + a) * nu + base + e];
        }
        b[a] = x[a] - (0..d).map(|e| wqq[a * d + e] * old[e]).sum::<f64>();
    }
    let (mut lq, mut blk, mut g) = ([0.0; 3], [0.0; 9], [0.0; 3]);
    let local = |x: &[f64; 3], lq: &mut [f64; 3], blk: &mut [f64; 9], g: &mut [f64; 3]| {
        let (_, slide) = point_forces(
            &x[..d],
            ops.gap[q],
            ops.w[q],
            ops.gamma[q],
            law,
            0.0,
            &mut lq[..d],
            &mut blk[..d * d],
        );
        let mut norm = 0.0f64;
        for a in 0..d {
            g[a] = x[a] - b[a] - (0..d).map(|e| wqq[a * d + e] * lq[e]).sum::<f64>();
            norm = norm.max(g[a].abs());
        }
        (norm, slide)
    };
    let scale = x[..d]
        .iter()
        .chain(&b[..d])
        .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    let (mut norm, mut slide) = local(&x, &mut lq, &mut blk, &mut g);
    for _ in 0..50 {
        if norm <= 1e-15 * scale {
            break;
        }
        // J = I − cτ² W_qq D_q; δ = −G.
        let (mut jac, mut step) = ([0.0; 9], [0.0; 3]);
        for a in 0..d {
            for e in 0..d {
                let wd: f64 = (0..d).map(|f| wqq[a * d + f] * blk[f * d + e]).sum();
                jac[a * d + e] = f64::from(u8::from(a == e)) - wd;
            }
            step[a] = -g[a];
        }
        if lu_solve(&mut jac[..d * d], d, &mut [0; 3][..d], &mut step[..d]).is_err() {
            break;
        }
        let start = x;
        let mut alpha = 1.0;
        let mut moved = false;
        for _ in 0..30 {
            for a in 0..d {
                x[a] = start[a] + alpha * step[a];
            }
            let (n, s) = local(&x, &mut lq, &mut blk, &mut g);
            if n < norm {
                (norm, slide, moved) = (n, s, true);
                break;
            }
            alpha *= 0.5;
        }
        if !moved {
            // No descent along the step: the full step leaves a kink of Λ (as the Newton's).
            for a in 0..d {
                x[a] = start[a] + step[a];
            }
            (norm, slide) = local(&x, &mut lq, &mut blk, &mut g);
        }
    }
    for a in 0..d {
        let dl = lq[a] - old[a];
        lambda[base + a] = lq[a];
        if dl != 0.0 {
            for j in 0..nu {
                work.s[j] += c * p.w[j * nu + base + a] * dl;
            }
        }
    }
    slide
}

/// One step's condensed frictional problem: the rows, W, cτ² and x0 ([`newton_friction`]).
struct Problem<'a> {
    ops: &'a NitscheOps,
    w: &'a [f64],
    c_tau2: f64,
    x0: &'a [f64],
}

/// The law with its bound (μ_f or s) scaled by `t` ∈ [0, 1].
fn scaled(law: FrictionLaw, t: f64) -> FrictionLaw {
    match law {
        FrictionLaw::Coulomb { coefficient } => FrictionLaw::Coulomb {
            coefficient: t * coefficient,
        },
        FrictionLaw::Tresca { threshold } => FrictionLaw::Tresca {
            threshold: t * threshold,
        },
        FrictionLaw::None => FrictionLaw::None,
    }
}

/// [`newton_friction`]'s third stage, where the Newton from the previous forces and from
/// rest both failed: a homotopy in the friction bound. The bound (μ_f or s) is scaled by t
/// from 0 (frictionless in the tangential forces: the normal problem alone, which Newton
/// solves) to 1, each stage's Newton started from the last solved one's forces, the
/// increment doubled after a success and quartered after a failure (down to 2⁻¹²). Tresca's
/// bound jumps from 0 to s at contact onset, and on coupled rows the literal law can then
/// have no solution (contract §2.5): the stages run with the bound ramped over a width ε of
/// x_n − g, s·min(1, (x_n − g)/ε), ε from 1e-2 of the normal scale down by 100 per stage
/// (milder where a reduction fails) to [`NEWTON_TOL`] of it, or to [`NEWTON_FLOOR_TOL`] of it
/// where no milder reduction goes further — a point left inside the ramp is at its gap to the tolerance with a
/// bound in [0, s], contract §2.5's closure (a grazing point); elsewhere the law is the
/// literal one. Adds the iterations of all its stages to `total`.
fn continuation(
    p: &Problem,
    law: FrictionLaw,
    lambda: &mut [f64],
    slides: &mut [bool],
    work: &mut NewtonWork,
    total: &mut usize,
) -> Result<(), String> {
    let sc = scales(p.ops, p.x0, 0.0);
    let tresca = matches!(law, FrictionLaw::Tresca { .. });
    let (ramp_end, ramp_ok) = (NEWTON_TOL * sc.n, NEWTON_FLOOR_TOL * sc.n);
    let mut ramp = if tresca { 1e-2 * sc.n } else { 0.0 };
    let (mut prev, mut shrink, mut restarts) = (ramp, 1e-2, 0);
    let (mut t, mut dt) = (0.0f64, 0.25f64);
    lambda.iter_mut().for_each(|l| *l = 0.0);
    work.lambda_ok.copy_from_slice(lambda);
    loop {
        let next = if t < 1.0 { (t + dt).min(1.0) } else { 1.0 };
        match newton_friction_from(p, scaled(law, next), ramp, lambda, slides, work) {
            Ok(it) => {
                *total += it;
                work.lambda_ok.copy_from_slice(lambda);
                t = next;
                if t < 1.0 {
                    dt *= 2.0;
                } else if ramp > ramp_end {
                    prev = ramp;
                    ramp = (ramp * shrink).max(ramp_end);
                } else {
                    return Ok(());
                }
            }
            Err(e) => {
                *total += NEWTON_MAX_ITER;
                lambda.copy_from_slice(&work.lambda_ok);
                if t == 1.0 {
                    // A reduction of the ramp failed: retried with a milder one (1e-2, 0.1,
                    // 0.32, 0.56 of the width; measured on the sliding block at 5°, Tresca
                    // s = 0.04, Nitsche and penalty: 1e-2 stalled at 1e-4 and 1e-6 of the
                    // scale). At the mildest, the last solved width, if it is within the floor
                    // tolerance of the gap, is the closure (its state restored by a Newton
                    // started at its solution).
                    if shrink < 0.5 {
                        shrink = shrink.sqrt();
                        ramp = (prev * shrink).max(ramp_end);
                        continue;
                    }
                    // Then the homotopy in t once more from rest at the narrower width
                    // (measured: the penalty's block at 5°, s = 0.04, stalled at 3e-5 of the
                    // scale from the wider width's solution).
                    if restarts < 2 {
                        restarts += 1;
                        work.lambda_best.copy_from_slice(&work.lambda_ok);
                        (t, dt, shrink) = (0.0, 0.25, 1e-2);
                        lambda.iter_mut().for_each(|l| *l = 0.0);
                        work.lambda_ok.copy_from_slice(lambda);
                        continue;
                    }
                    if prev <= ramp_ok {
                        let r = newton_friction_from(p, law, prev, lambda, slides, work);
                        *total += *r.as_ref().unwrap_or(&NEWTON_MAX_ITER);
                        return r.map(|_| ());
                    }
                    return Err(format!("the Tresca ramp stalled at width {ramp:.1e}: {e}"));
                }
                dt *= 0.25;
                if dt < 1.0 / 4096.0 {
                    // After a restart: the closure already solved, if within the floor.
                    if restarts > 0 && prev <= ramp_ok {
                        lambda.copy_from_slice(&work.lambda_best);
                        let r = newton_friction_from(p, law, prev, lambda, slides, work);
                        *total += *r.as_ref().unwrap_or(&NEWTON_MAX_ITER);
                        return r.map(|_| ());
                    }
                    return Err(format!("stalled at t = {t:.4} (ramp {ramp:.1e}): {e}"));
                }
            }
        }
    }
}

/// The solve's scales at the start x0 ([`Scales`]) with Tresca's onset `ramp`.
fn scales(ops: &NitscheOps, x0: &[f64], ramp: f64) -> Scales {
    let d = ops.per_point();
    let mut sc = Scales {
        n: f64::MIN_POSITIVE,
        t0: f64::MIN_POSITIVE,
        ramp,
    };
    for q in 0..ops.len() {
        sc.n = sc.n.max(x0[q * d].abs()).max(ops.gap[q].abs());
        for a in 1..d {
            sc.t0 = sc.t0.max(x0[q * d + a].abs());
        }
    }
    sc
}

/// Active unknowns from which the frictional Newton solves its step in the contact dofs'
/// space ([`SchurNewton`]) instead of by the dense LU of its active block, whose (2/3)·n_a³
/// (n_a = d × the active points) dominates the step from about this size on; below it the
/// dense LU is the cheaper. Runs with at least this many unknowns make S at set-up
/// ([`ContactSchur`]) and their residuals' W Λ with it at every step; smaller runs keep the
/// dense W and their bits.
pub(crate) const SPARSE_MIN_ACTIVE: usize = 384;

/// The full semismooth Newton step into `work.step` at the iterate `work.s` (its G, blocks
/// and active set from [`evaluate`]): J δ = −G with J = I − cτ² W D. Small active sets solve the
/// active block densely and the inactive rows from it; from [`SPARSE_MIN_ACTIVE`] active
/// unknowns on, where the dense LU's cube dominates the step, [`SchurNewton`] makes the same
/// step in the contact dofs' space.
fn newton_step(
    ops: &NitscheOps,
    w: &[f64],
    c_tau2: f64,
    work: &mut NewtonWork,
) -> Result<(), String> {
    if work.active.len() >= SPARSE_MIN_ACTIVE
        && let Some(sn) = work.schur.as_mut()
    {
        let nu = ops.unknowns();
        for (r, g) in work.delta[..nu].iter_mut().zip(&work.g) {
            *r = -g;
        }
        return sn.step(
            &work.point_active,
            &work.blocks,
            &work.delta[..nu],
            c_tau2,
            &mut work.step[..nu],
        );
    }
    let (nq, d) = (ops.len(), ops.per_point());
    let nu = nq * d;
    let na = work.active.len();
    // J_AA = I − cτ² W_AA D_A, D block diagonal over the active points.
    for (i, &ji) in work.active.iter().enumerate() {
        let row = &w[ji * nu..(ji + 1) * nu];
        for (c, &jc) in work.active.iter().enumerate() {
            let (q, a) = (jc / d, jc % d);
            let blk = &work.blocks[q * d * d..(q + 1) * d * d];
            let wd: f64 = (0..d).map(|b| row[q * d + b] * blk[b * d + a]).sum();
            work.jac[i * na + c] = f64::from(u8::from(i == c)) - c_tau2 * wd;
        }
        work.delta[i] = -work.g[ji];
    }
    lu_solve(
        &mut work.jac[..na * na],
        na,
        &mut work.perm[..na],
        &mut work.delta[..na],
    )?;
    // The full step: (D δ)_A, δ_I = −G_I + cτ² W_IA (D δ)_A, δ_A from the LU.
    for (i, &ji) in work.active.iter().enumerate() {
        let (q, b) = (ji / d, ji % d);
        let blk = &work.blocks[q * d * d..(q + 1) * d * d];
        let base = i - b;
        work.d_delta[i] = (0..d).map(|a| blk[b * d + a] * work.delta[base + a]).sum();
    }
    for q in 0..nq {
        if work.point_active[q] {
            continue;
        }
        for j in q * d..(q + 1) * d {
            let row = &w[j * nu..(j + 1) * nu];
            let mut acc = -work.g[j];
            for (i, &ji) in work.active.iter().enumerate() {
                acc += c_tau2 * row[ji] * work.d_delta[i];
            }
            work.step[j] = acc;
        }
    }
    for (i, &ji) in work.active.iter().enumerate() {
        work.step[ji] = work.delta[i];
    }
    Ok(())
}

/// [`newton_friction`]'s iteration from the start `lambda` holds, for the law `law` with
/// Tresca's onset `ramp` (0: the literal law; [`continuation`]).
fn newton_friction_from(
    p: &Problem,
    law: FrictionLaw,
    ramp: f64,
    lambda: &mut [f64],
    slides: &mut [bool],
    work: &mut NewtonWork,
) -> Result<usize, String> {
    let (ops, w, c_tau2, x0) = (p.ops, p.w, p.c_tau2, p.x0);
    let (nq, d) = (ops.len(), ops.per_point());
    let nu = nq * d;
    let sc = scales(ops, x0, ramp);
    // Warm start from the previous step's forces.
    work.nonzero.clear();
    work.nonzero.extend((0..nu).filter(|&r| lambda[r] != 0.0));
    if let Some(sn) = work.schur.as_mut() {
        sn.apply_w(lambda, &work.nonzero);
        for j in 0..nu {
            work.s[j] = x0[j] + c_tau2 * sn.wl[j];
        }
    } else {
        for j in 0..nu {
            let row = &w[j * nu..(j + 1) * nu];
            let wl: f64 = work.nonzero.iter().map(|&r| row[r] * lambda[r]).sum();
            work.s[j] = x0[j] + c_tau2 * wl;
        }
    }
    let mut res = evaluate(ops, law, w, c_tau2, x0, &sc, lambda, slides, work);
    for it in 0..=NEWTON_MAX_ITER {
        if passes(&mut res, p, &sc, lambda, work, |n, t, st| {
            n <= NEWTON_TOL * sc.n && t <= NEWTON_TOL * st
        }) {
            return Ok(it);
        }
        if it == NEWTON_MAX_ITER {
            break;
        }
        newton_step(ops, w, c_tau2, work)
            .map_err(|e| format!("semismooth Newton (friction): {e} (iteration {it})"))?;
        work.x_old[..nu].copy_from_slice(&work.s[..nu]);
        // A Newton step of round-off size (≤ 1e-13 of the iterate) is the floor too, even
        // where the merit still falls by noise: the iterate cannot move in floating point, and
        // with J nonsingular |G| ≤ ‖J‖·|step| is round-off. The tangential residual is judged
        // against the normal scale there: its floor comes from x_n's last bits (module
        // constant's note), not from the tangential forces, which may be orders smaller.
        // Measured on bar2d (Nitsche Θ = 1, γ0 = 0.01, Coulomb 0.3, CN, t = 0.4): steps of
        // 1e-17 at |x| = 0.2 and tangential residuals 8e-13 … 1.6e-12 against a tangential
        // scale of 5e-5, for 100 iterations whose line searches kept "descending"
        // (`gmsh_bar_reproduces_bar2d_with_friction_for_every_method`).
        let step_size = work.step[..nu].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let size = work.x_old[..nu].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if step_size <= 1e-13 * size
            && passes(&mut res, p, &sc, lambda, work, |n, t, st| {
                n <= NEWTON_FLOOR_TOL * sc.n && t <= NEWTON_FLOOR_TOL * sc.n.max(st)
            })
        {
            return Ok(it + 1);
        }
        let mut alpha = 1.0;
        let mut descended = false;
        for _ in 0..30 {
            for j in 0..nu {
                work.s[j] = work.x_old[j] + alpha * work.step[j];
            }
            let r = evaluate(ops, law, w, c_tau2, x0, &sc, lambda, slides, work);
            if r.merit < res.merit {
                res = r;
                descended = true;
                break;
            }
            // The merit stays the last accepted iterate's.
            res = Residuals {
                merit: res.merit,
                ..r
            };
            alpha *= 0.5;
        }
        // No step along the Newton direction lowers the merit, down to 2⁻²⁹ of it. Either the
        // residual is at its round-off floor Σ_a |∂G_j/∂x_a| ulp(x_a), which the tolerance
        // above can miss ([`NEWTON_FLOOR_TOL`]): accepted there. Or the iterate sits on a kink
        // of Λ whose one-sided Jacobian is not the other side's: measured on bar2d (penalty,
        // Tresca s = 0.05, backward Euler, step 34) every point just below its gap
        // (x_n = g − 3e-10, Λ = 0) while x0 penetrates by 3.7e-3; the inactive Jacobian's step
        // activates the stiff penalty and raises the merit for every α, so the damped Newton
        // stayed on the kink to the iteration cap. The full step leaves the kink: the next
        // Jacobian is the active side's (`bar2d_penalty_tresca_newton_leaves_the_gap_kink`).
        if !descended {
            if passes(&mut res, p, &sc, lambda, work, |n, t, st| {
                n <= NEWTON_FLOOR_TOL * sc.n && t <= NEWTON_FLOOR_TOL * st
            }) {
                return Ok(it + 1);
            }
            for j in 0..nu {
                work.s[j] = work.x_old[j] + work.step[j];
            }
            res = evaluate(ops, law, w, c_tau2, x0, &sc, lambda, slides, work);
        }
    }
    Err(format!(
        "semismooth Newton (friction) did not converge in {NEWTON_MAX_ITER} iterations (residuals {:.3e} normal, {:.3e} tangential; scale {:.3e})",
        res.n, res.t, sc.n
    ))
}

/// Solve G(s) = s − s0 − cτ² W φ(s) = 0 with φ_q(s) = (w_q/γ_q)[s − k_q]_+ (module header;
/// the kinks k are the gaps for Newmark/θ, shifted per step for the hybrid scheme); `phi`
/// receives φ(s). Returns the iteration count. Allocates nothing.
pub(crate) fn newton(
    ops: &NitscheOps,
    w: &[f64],
    c_tau2: f64,
    s0: &[f64],
    kink: &[f64],
    phi: &mut [f64],
    work: &mut NewtonWork,
) -> Result<usize, String> {
    let nq = ops.len();
    let scale = s0
        .iter()
        .chain(kink)
        .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
    // Warm start: the previous step's s where it was active, s0 elsewhere (first step: s0).
    for q in 0..nq {
        let prev = work.s[q];
        work.s[q] = if prev > kink[q] { prev } else { s0[q] };
    }
    let mut res = f64::INFINITY;
    for it in 0..=NEWTON_MAX_ITER {
        work.nonzero.clear();
        for q in 0..nq {
            phi[q] = ops.w[q] / ops.gamma[q] * (work.s[q] - kink[q]).max(0.0);
            if phi[q] != 0.0 {
                work.nonzero.push(q);
            }
        }
        // (W φ)_q over the nonzero φ_r only, in ascending r: O(Q·|active|), not O(Q²) — in
        // free flight (most steps) the residual is then O(Q).
        res = 0.0;
        for q in 0..nq {
            let row = &w[q * nq..(q + 1) * nq];
            let wphi: f64 = work.nonzero.iter().map(|&r| row[r] * phi[r]).sum();
            work.g[q] = work.s[q] - s0[q] - c_tau2 * wphi;
            res = res.max(work.g[q].abs());
        }
        if res <= NEWTON_TOL * scale {
            return Ok(it);
        }
        if it == NEWTON_MAX_ITER {
            break;
        }
        work.active.clear();
        work.active.extend((0..nq).filter(|&q| work.s[q] > kink[q]));
        let na = work.active.len();
        // Active block: (I − cτ² W_AA D_A) δ_A = −G_A.
        for (i, &qi) in work.active.iter().enumerate() {
            for (j, &qj) in work.active.iter().enumerate() {
                let d = ops.w[qj] / ops.gamma[qj];
                work.jac[i * na + j] = f64::from(u8::from(i == j)) - c_tau2 * w[qi * nq + qj] * d;
            }
            work.delta[i] = -work.g[qi];
        }
        lu_solve(
            &mut work.jac[..na * na],
            na,
            &mut work.perm[..na],
            &mut work.delta[..na],
        )
        .map_err(|e| format!("semismooth Newton: {e} (iteration {it})"))?;
        // Inactive points: δ_I = −G_I + cτ² W_IA D_A δ_A; then s += δ.
        for q in 0..nq {
            if work.s[q] > kink[q] {
                continue;
            }
            let mut acc = -work.g[q];
            for (j, &qj) in work.active.iter().enumerate() {
                acc += c_tau2 * w[q * nq + qj] * ops.w[qj] / ops.gamma[qj] * work.delta[j];
            }
            work.s[q] += acc;
        }
        for (j, &qj) in work.active.iter().enumerate() {
            work.s[qj] += work.delta[j];
        }
    }
    Err(format!(
        "semismooth Newton did not converge in {NEWTON_MAX_ITER} iterations (residual {res:.3e}, scale {scale:.3e})"
    ))
}

/// A frictional run's state besides the engine's (contract §2.5): the slip's reference u_t^n,
/// the points' stick/slip states from the contact solve, and the run's
/// [`FrictionTally`] over the quadrature points (W_f with the scheme's f̄_t, E + W_f, the
/// apparent coefficient |Σf_t|/Σf_n, `stop_time` — the mixed engines' accounting, with
/// Nitsche's stick decided by its cone); the body's mean velocities per axis from M v and the
/// series' Γ_C mean of v_1 over the points. All allocated once per run.
#[derive(Debug)]
pub(crate) struct FrictionState {
    pub law: FrictionLaw,
    /// u_t,q^n per point and direction, set by the step's contact solve from u^n; then Δu_t.
    pub ut_n: Vec<f64>,
    du_t: Vec<f64>,
    /// Whether each point slides (the disc projection active) at the last step.
    pub slides: Vec<bool>,
    tally: FrictionTally,
    /// The body's mean velocities per axis 1ᵀMv/1ᵀM1 (the last step's in `means`), and
    /// Σ_q w_q (the Γ_C means' divisor).
    mean: MeanVelocity,
    means: [f64; 3],
    weight_sum: f64,
    /// Whether E⁰ is in the tally (the first [`Self::balance`]).
    balanced: bool,
}

impl FrictionState {
    /// For `ops` (with friction), the run's law, the body's mean velocities `mean` and the
    /// weight of f_t^{n+1} in f̄_t (contract §2.5: the scheme's γ or θ, generalized-α's 1 − α_f);
    /// `h` the mesh size (the tally's increment rule, unused here: the cone decides).
    pub fn new(
        ops: &NitscheOps,
        law: FrictionLaw,
        mean: MeanVelocity,
        weight: f64,
        h: f64,
    ) -> FrictionState {
        let td = ops.friction.as_ref().map_or(0, |f| f.td);
        FrictionState {
            law,
            ut_n: vec![0.0; ops.len() * td],
            du_t: vec![0.0; ops.len() * td],
            slides: vec![false; ops.len()],
            tally: FrictionTally::new(ops.len(), ops.per_point(), h, weight),
            mean,
            means: [f64::NAN; 3],
            weight_sum: ops.w.iter().sum(),
            balanced: false,
        }
    }

    /// x0 = P y with the tangential rows' k_q u_t^n (module header), u_t^n kept.
    pub fn start_step(&mut self, ops: &NitscheOps, y: &[f64], u_n: &[f64], x0: &mut [f64]) {
        let f = ops
            .friction
            .as_ref()
            .expect("a frictional run has tangential rows");
        let d = ops.per_point();
        for (j, x) in x0.iter_mut().enumerate() {
            let (row, dofs) = ops.p_row(j);
            *x = row.iter().zip(dofs).map(|(a, &g)| a * y[g]).sum();
            let (q, a) = (j / d, j % d);
            if a > 0 {
                let r = q * f.td + a - 1;
                let urow = &f.ut[r * ops.k..(r + 1) * ops.k];
                let ut = urow.iter().zip(dofs).map(|(a, &g)| a * u_n[g]).sum::<f64>();
                self.ut_n[r] = ut;
                *x += f.kt[q] * ut;
            }
        }
    }

    /// After step n's update (u = u^{n+1}, v = v^{n+1}, `mv` = M v^{n+1}, `lambda` = λ^{n+1},
    /// point-major [λ_n, λ_t…] with the points' weights): the tally's step over the points'
    /// Δu_t and states, the mean velocities at `t`. Returns (Σ λ_t along e_1 — the total
    /// tangential force on the body —, the Γ_C mean of v_1, W_f).
    pub fn after_step(
        &mut self,
        ops: &NitscheOps,
        u: &[f64],
        v: &[f64],
        mv: &[f64],
        lambda: &[f64],
        t: f64,
    ) -> (f64, f64, f64) {
        let f = ops
            .friction
            .as_ref()
            .expect("a frictional run has tangential rows");
        let mut wv = 0.0;
        for q in 0..ops.len() {
            let dofs = &ops.dofs[q * ops.k..(q + 1) * ops.k];
            for i in 0..f.td {
                let r = q * f.td + i;
                let urow = &f.ut[r * ops.k..(r + 1) * ops.k];
                let ut = urow.iter().zip(dofs).map(|(a, &g)| a * u[g]).sum::<f64>();
                if i == 0 {
                    wv += ops.w[q] * urow.iter().zip(dofs).map(|(a, &g)| a * v[g]).sum::<f64>();
                }
                self.du_t[r] = ut - self.ut_n[r];
            }
        }
        let work = self.tally.step_with(lambda, &self.du_t, Some(&self.slides));
        self.mean.means_into(mv, &mut self.means);
        self.tally.velocity(t, self.means[0]);
        let v_contact = if self.weight_sum > 0.0 {
            wv / self.weight_sum
        } else {
            0.0
        };
        (self.tally.total_tangential()[0], v_contact, work)
    }

    /// The points' forces at t = 0 (point-major [λ_n, λ_t…]): f̄_t's f_t⁰ in the first step.
    pub fn start_forces(&mut self, forces: &[f64]) {
        self.tally.start_forces(forces);
    }

    /// Step 0: the initial mean velocities.
    pub fn start(&mut self, mv: &[f64]) {
        self.mean.means_into(mv, &mut self.means);
        self.tally.velocity(0.0, self.means[0]);
    }

    /// After step n's observation: E^{n+1} = `energy` into the tally (E + W_f's rise); `e_prev`
    /// is E^n, taken as E⁰ at the first step.
    pub fn balance(&mut self, e_prev: f64, energy: f64) {
        if !self.balanced {
            self.tally.energy(e_prev);
            self.balanced = true;
        }
        self.tally.energy(energy);
    }

    /// The friction columns (contract §5), energies over `scale`, with the contact solve's
    /// iterations per stage `stages` ([`NewtonWork::stage_columns`]).
    pub fn finish(&self, m: &mut crate::run::Metrics, scale: f64, stages: [usize; 3]) {
        let vt = self.mean.tangential(&self.means);
        self.tally.finish(m, scale, vt, self.means[2]);
        crate::run::friction_tally::stage_columns(m, stages);
    }
}

/// In-place LU with partial pivoting of the n×n row-major `a`, then solve for `b` (overwritten).
pub(crate) fn lu_solve(
    a: &mut [f64],
    n: usize,
    perm: &mut [usize],
    b: &mut [f64],
) -> Result<(), String> {
    for (i, p) in perm.iter_mut().enumerate() {
        *p = i;
    }
    for k in 0..n {
        let (piv, max) = (k..n)
            .map(|i| (i, a[i * n + k].abs()))
            .fold((k, -1.0), |m, x| if x.1 > m.1 { x } else { m });
        if !(max > 0.0 && max.is_finite()) {
            return Err(format!("singular Jacobian at column {k}"));
        }
        if piv != k {
            for j in 0..n {
                a.swap(k * n + j, piv * n + j);
            }
            b.swap(k, piv);
            perm.swap(k, piv);
        }
        let akk = a[k * n + k];
        for i in k + 1..n {
            let l = a[i * n + k] / akk;
            if l == 0.0 {
                continue;
            }
            a[i * n + k] = l;
            for j in k + 1..n {
                a[i * n + j] -= l * a[k * n + j];
            }
            b[i] -= l * b[k];
        }
    }
    for k in (0..n).rev() {
        let mut acc = b[k];
        for j in k + 1..n {
            acc -= a[k * n + j] * b[j];
        }
        b[k] = acc / a[k * n + k];
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lu_solves_a_small_system() {
        // [[0, 2], [1, 1]] x = [2, 3] needs a pivot: x = (2, 1), exact in binary.
        let mut a = [0.0, 2.0, 1.0, 1.0];
        let mut b = [2.0, 3.0];
        lu_solve(&mut a, 2, &mut [0; 2], &mut b).unwrap();
        assert_eq!(b, [2.0, 1.0]);
        assert!(lu_solve(&mut [0.0; 4], 2, &mut [0; 2], &mut [1.0, 1.0]).is_err());
    }

    /// contract §5's friction columns of a frictional run, by hand: two penalty points in 2D on two
    /// nodes (dofs x, y each), weights 1 and 3, u_t = the node's u_x; identity mass. Forces
    /// λ = w(f_n, f_t) = (1, 0.5) and (3, −1.5): each point on its cone |f_t| = 0.5 f_n, but
    /// |Σλ_t|/Σλ_n = |0.5 − 1.5|/4 = 0.25, the apparent coefficient. v = (1, 0 | 3, 0): the
    /// Γ_C mean of v_1 is (1·1 + 3·3)/4 = 2.5, the body's mean (1 + 3)/2 = 2 along e_1 and 0
    /// along e_d. Binary fractions: exact.
    #[test]
    fn friction_state_sums_forces_and_averages_velocities() {
        use crate::contact::friction::FrictionLaw;
        use crate::run::friction_tally::MeanVelocity;
        use crate::space::fe::SymMatrix;
        let point = |node: usize, weight: f64| ContactPoint {
            weight,
            gamma: 1.0,
            gap: 0.0,
            dofs: vec![2 * node, 2 * node + 1],
            un: vec![0.0, -1.0],
            sn: vec![0.0, 0.0],
            ut: vec![1.0, 0.0],
            st: vec![0.0, 0.0],
        };
        let points = [point(0, 1.0), point(1, 3.0)];
        let ops = NitscheOps::penalty(&points, 1.0, 1.0).with_friction(&points, 1.0);
        let mut eye = vec![0.0; 16];
        (0..4).for_each(|i| eye[i * 5] = 1.0);
        let m = SymMatrix::from_dense(4, &eye).unwrap();
        let law = FrictionLaw::Coulomb { coefficient: 0.5 };
        let mut st = FrictionState::new(&ops, law, MeanVelocity::new(2, &m, |r| r % 2), 0.5, 1.0);
        let v = [1.0, 0.0, 3.0, 0.0];
        st.start(&v);
        let lambda = [1.0, 0.5, 3.0, -1.5];
        let (ft, v_contact, _) = st.after_step(&ops, &[0.0; 4], &v, &v, &lambda, 1.0);
        assert_eq!((ft, v_contact), (-1.0, 2.5));
        let mut metrics = crate::run::Metrics::default();
        st.finish(&mut metrics, 1.0, [3, 0, 0]);
        assert_eq!(metrics.friction_ratio_max, Some(0.25));
        assert_eq!(metrics.tangential_velocity_final, Some(2.0));
        assert_eq!(metrics.normal_velocity_final, Some(0.0));
        assert_eq!(
            (metrics.stick_steps, metrics.slip_steps),
            (Some(2), Some(0))
        );
        assert_eq!(metrics.friction_newton_iterations, Some(3));
        assert_eq!(metrics.friction_fallback_iterations, Some(0));
    }

    /// Tresca on coupled rows without a solution (contract §2.5), by hand: one 2D point,
    /// w = γ = 1, gap 0, s = 1, cτ² = 1, W = [[−1, −4], [0, −1]], x0 = (1, 10). In contact the
    /// sliding force λ_t = 1 pulls x_n to −1.5 (out of contact; stick would need |x_t| = 5 ≤ 1);
    /// out of contact λ = 0 leaves x_n = 1 (in contact): no root, so the Newton from the
    /// previous forces and from rest both fail, and the continuation with Tresca's onset ramp
    /// finds the closure — the point grazing (x_n = ε/(2ε + 4) ≈ ε/4 → 0, λ_n = x_n) with the
    /// bound λ_t = (1 − 2x_n)/4 → 1/4 ∈ [0, s]. Its residual G = x − x0 − WΛ meets §4's 1e-12
    /// relative to the normal scale max(|x0_n|, |g|) = 1; x_n is within the floor tolerance
    /// 1e-8 of the gap and λ_t within 1e-8 of 1/4 (λ_t = 1/4 − x_n/2 exactly).
    #[test]
    fn tresca_without_a_root_takes_the_grazing_closure() {
        let ops = NitscheOps {
            k: 1,
            dofs: vec![0],
            p: vec![1.0],
            c: vec![-1.0],
            s: vec![0.0],
            w: vec![1.0],
            gamma: vec![1.0],
            gap: vec![0.0],
            theta: 0.0,
            penalty: true,
            friction: Some(FrictionOps {
                td: 1,
                ut: vec![1.0],
                st: vec![0.0],
                pt: vec![-1.0],
                ct: vec![1.0],
                kt: vec![1.0],
            }),
        };
        let w = [-1.0, -4.0, 0.0, -1.0];
        let x0 = [1.0, 10.0];
        let law = FrictionLaw::Tresca { threshold: 1.0 };
        let mut work = NewtonWork::frictional(2, 2);
        let (mut lambda, mut slides) = ([0.0; 2], [false]);
        let it =
            newton_friction(&ops, law, &w, 1.0, &x0, &mut lambda, &mut slides, &mut work).unwrap();
        assert!(
            it > 2 * NEWTON_MAX_ITER,
            "{it}: the fallback was not needed"
        );
        assert_eq!(work.stages[0], NEWTON_MAX_ITER);
        assert!(work.stages[2] > 0);
        let x = [work.s[0], work.s[1]];
        for j in 0..2 {
            let g = x[j] - x0[j] - (w[2 * j] * lambda[0] + w[2 * j + 1] * lambda[1]);
            assert!(g.abs() <= 1e-12, "G_{j} = {g:e}");
        }
        assert!((0.0..=1e-8).contains(&x[0]), "x_n = {:e}", x[0]);
        assert!((lambda[1] - 0.25).abs() <= 1e-8, "{lambda:?}");
        assert!(slides[0]);
    }

    /// The last fallback alone ([`gauss_seidel`], from rest as after a failed continuation):
    /// two 2D penalty points (w = γ = 1, gaps 0), cτ² = 1, W = −S with S symmetric positive
    /// definite and coupled (off-diagonal 0.3–0.9 of the diagonal's), x0 penetrating at both
    /// points with large tangential predictors, Coulomb μ_f = 4. Its answer meets contract §4's
    /// tolerance: G = x − x0 − cτ² W Λ(x) within 1e-12 of the normal scale max|x0_n| = 1 in the
    /// normal rows and of the tangential scale max|x0_t| = 3 in the tangential ones (the
    /// Newton polish's test; here both points' forces are O(1), so the rounding of W Λ is
    /// ~1e-16), and the stages record sweeps and polish.
    #[test]
    fn gauss_seidel_fallback_meets_the_tolerance() {
        let friction = FrictionOps {
            td: 1,
            ut: vec![1.0, 1.0],
            st: vec![0.0; 2],
            pt: vec![-1.0, -1.0],
            ct: vec![1.0, 1.0],
            kt: vec![1.0, 1.0],
        };
        let ops = NitscheOps {
            k: 1,
            dofs: vec![0, 1],
            p: vec![1.0, 1.0],
            c: vec![-1.0, -1.0],
            s: vec![0.0; 2],
            w: vec![1.0, 1.0],
            gamma: vec![1.0, 1.0],
            gap: vec![0.0, 0.0],
            theta: 0.0,
            penalty: true,
            friction: Some(friction),
        };
        let spd = [
            2.0, 0.6, 0.9, 0.3, //
            0.6, 1.5, 0.4, 0.5, //
            0.9, 0.4, 2.5, 0.7, //
            0.3, 0.5, 0.7, 1.2,
        ];
        let w: Vec<f64> = spd.iter().map(|x| -x).collect();
        let x0 = [1.0, 3.0, 0.7, -2.5];
        let law = FrictionLaw::Coulomb { coefficient: 4.0 };
        let p = Problem {
            ops: &ops,
            w: &w,
            c_tau2: 1.0,
            x0: &x0,
        };
        let mut work = NewtonWork::frictional(4, 2);
        let (mut lambda, mut slides) = ([0.0; 4], [false; 2]);
        gauss_seidel(&p, law, &mut lambda, &mut slides, &mut work).unwrap();
        assert!(work.stages[3] >= GS_POLISH_EVERY, "{:?}", work.stages);
        assert_eq!(work.stage_columns()[2], work.stages[3] + work.stages[4]);
        for j in 0..4 {
            let wl: f64 = (0..4).map(|r| w[j * 4 + r] * lambda[r]).sum();
            let g = work.s[j] - x0[j] - wl;
            let scale = if j % 2 == 0 { 1.0 } else { 3.0 };
            assert!(g.abs() <= 1e-12 * scale, "G_{j} = {g:e}");
        }
        assert!(lambda[0] > 0.0 && lambda[2] > 0.0, "{lambda:?}");
    }

    /// One step of issue 43's campaign that every stage before Lemke's failed (written by the
    /// engine at the failure: tests/data/friction_steps/*.txt, a header "points d penalty Θ
    /// law(1 Coulomb, 2 Tresca) bound cτ²", then the lines gap, w, γ, x0, the previous step's
    /// forces, W row-major): the rows only enter the solve through these, so the ops' own rows
    /// are placeholders.
    fn campaign_step(text: &str) -> (NitscheOps, FrictionLaw, f64, Vec<Vec<f64>>) {
        let mut lines = text.lines();
        let head: Vec<f64> = lines
            .next()
            .unwrap()
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .collect();
        let nq = head[0] as usize;
        let law = if head[4] == 1.0 {
            FrictionLaw::Coulomb {
                coefficient: head[5],
            }
        } else {
            FrictionLaw::Tresca { threshold: head[5] }
        };
        let ops = NitscheOps {
            k: 1,
            dofs: vec![0; nq],
            p: vec![0.0; nq],
            c: vec![0.0; nq],
            s: vec![0.0; nq],
            w: rows[1].clone(),
            gamma: rows[2].clone(),
            gap: rows[0].clone(),
            theta: head[3],
            penalty: head[2] == 1.0,
            friction: Some(FrictionOps {
                td: 1,
                ut: vec![0.0; nq],
                st: vec![0.0; nq],
                pt: vec![0.0; nq],
                ct: vec![0.0; nq],
                kt: vec![0.0; nq],
            }),
        };
        (ops, law, head[6], rows)
    }

    /// Issue 43's remaining failures, two of the six campaign steps (the block on the 18°
    /// incline, Nitsche γ0 = 1e-4, backward Euler, μ_f = 4.15, step 35; the block under
    /// Tresca s = 0.048, HHT, step 10): the Newton from the previous forces fails, and the
    /// whole solve — continuation and Gauss–Seidel failing in turn — ends with Lemke's stage,
    /// whose polish meets the primary Newton's tolerance: each row of G = x − x0 − cτ² W λ at
    /// the returned iterate within 1e-12 of its scale (as [`evaluate`] states it; Tresca at
    /// the Newton's round-off floor, below, and with its onset ramp ≤ [`NEWTON_FLOOR_TOL`] of
    /// the normal scale, the closure).
    #[test]
    fn lemke_stage_solves_the_campaign_steps() {
        // The Tresca step's polish ends at its round-off floor (a Newton step ≤ 1e-13 of the
        // iterate; measured: a normal row at 3.5e-16 = 1.2e-12 of the normal scale 2.9e-4),
        // which the Newton accepts within [`NEWTON_FLOOR_TOL`]; the Coulomb step meets 1e-12.
        for (text, tol) in [
            (
                include_str!("../../../tests/data/friction_steps/incline18_nitsche_be_mu4.15.txt"),
                NEWTON_TOL,
            ),
            (
                include_str!("../../../tests/data/friction_steps/tresca_nitsche_hht_s0.048.txt"),
                NEWTON_FLOOR_TOL,
            ),
        ] {
            let (ops, law, c_tau2, rows) = campaign_step(text);
            let (x0, w) = (&rows[3], &rows[5]);
            let nu = x0.len();
            let p = Problem {
                ops: &ops,
                w,
                c_tau2,
                x0,
            };
            let mut work = NewtonWork::frictional(nu, 2);
            let (mut lambda, mut slides) = (rows[4].clone(), vec![false; ops.len()]);
            assert!(
                newton_friction_from(&p, law, 0.0, &mut lambda, &mut slides, &mut work).is_err()
            );
            lambda.copy_from_slice(&rows[4]);
            let it = newton_friction(
                &ops,
                law,
                w,
                c_tau2,
                x0,
                &mut lambda,
                &mut slides,
                &mut work,
            )
            .unwrap();
            assert!(work.stages[5] > 0 && work.lemke_first, "{:?}", work.stages);
            assert_eq!(it, work.stages.iter().sum::<usize>());
            let sc = scales(&ops, x0, 0.0);
            let mut scale_t = sc.t0;
            for j in 0..nu {
                let row = &w[j * nu..(j + 1) * nu];
                let wl: f64 = row.iter().zip(&lambda).map(|(a, l)| a * l).sum();
                let wabs: f64 = row.iter().zip(&lambda).map(|(a, l)| (a * l).abs()).sum();
                if j % 2 == 1 {
                    scale_t = scale_t.max(work.s[j].abs()).max(c_tau2 * wabs);
                }
                work.g[j] = work.s[j] - x0[j] - c_tau2 * wl;
            }
            for j in 0..nu {
                let g = work.g[j].abs();
                if j % 2 == 0 {
                    let row = &w[j * nu..(j + 1) * nu];
                    let wabs: f64 = row.iter().zip(&lambda).map(|(a, l)| (a * l).abs()).sum();
                    assert!(g <= tol * sc.n.max(c_tau2 * wabs), "G_{j} = {g:e}");
                } else {
                    assert!(g <= tol * scale_t, "G_{j} = {g:e} ({scale_t:e})");
                }
            }
            // The forces are the law's at x (Λ(x) = λ; Tresca's ramp leaves a point within
            // the floor of its gap at most): every point within its disc, none pulling.
            for q in 0..ops.len() {
                let (ln, lt) = (lambda[2 * q], lambda[2 * q + 1]);
                let bound = match law {
                    FrictionLaw::Coulomb { coefficient } => coefficient * ln,
                    FrictionLaw::Tresca { threshold } => threshold * ops.w[q],
                    FrictionLaw::None => 0.0,
                };
                assert!(
                    ln >= 0.0 && lt.abs() <= bound * (1.0 + 1e-12),
                    "point {q}: {ln:e} {lt:e}"
                );
            }
        }
    }

    /// The step in the contact dofs' space ([`SchurNewton`]) is the dense one: two 2D points
    /// on a 4-dof body (A a dense SPD 4 × 4, rows p, c, P_t, C_t made up), W = P A⁻¹ C and
    /// S = A⁻¹ (every dof is a contact dof) computed here. First an iterate with point 0
    /// sticking and point 1 sliding (Coulomb μ_f = 0.5, its coupled block): K is factored and
    /// the step solved with it; then an iterate with both points sliding, whose step GMRES
    /// solves with the first K's LU as its preconditioner (no second factorisation). Each
    /// agrees with the dense LU's step to 1e-10 relative (LU solves of well-conditioned 4 × 4
    /// systems: round-off ~1e-15; GMRES stops at [`super::super::schur::KRYLOV_TOL`] = 1e-10
    /// of its right-hand side, and exactly after at most 4 iterations in 4 dimensions).
    #[test]
    fn schur_step_equals_the_dense_step() {
        let a_dense = [
            4.0, 1.0, 0.5, 0.2, 1.0, 5.0, 0.3, 0.4, 0.5, 0.3, 6.0, 1.0, 0.2, 0.4, 1.0, 3.0,
        ];
        let ops = NitscheOps {
            k: 2,
            dofs: vec![0, 1, 2, 3],
            p: vec![0.3, 1.0, -0.2, 1.1],
            c: vec![-0.3, -1.0, 0.1, -0.9],
            s: vec![0.0; 4],
            w: vec![0.5, 0.7],
            gamma: vec![0.1, 0.2],
            gap: vec![0.0, 0.0],
            theta: 0.0,
            penalty: false,
            friction: Some(FrictionOps {
                td: 1,
                ut: vec![1.0, 0.0, 1.0, 0.1],
                st: vec![0.0; 4],
                pt: vec![-2.0, 0.3, -1.5, 0.0],
                ct: vec![1.0, -0.1, 0.9, 0.2],
                kt: vec![2.0, 1.5],
            }),
        };
        let solve = |col: &mut [f64]| {
            let mut m = a_dense;
            lu_solve(&mut m, 4, &mut [0; 4], col).unwrap();
        };
        // W[j][r] = p_j · A⁻¹ c_r.
        let mut w = [0.0; 16];
        for r in 0..4 {
            let mut col = [0.0; 4];
            let (c, dofs) = ops.c_row(r);
            for (&g, &v) in dofs.iter().zip(c) {
                col[g] += v;
            }
            solve(&mut col);
            for j in 0..4 {
                let (p, dofs) = ops.p_row(j);
                w[j * 4 + r] = p.iter().zip(dofs).map(|(a, &g)| a * col[g]).sum();
            }
        }
        let schur = ContactSchur::new(4, &ops.dofs, |z, m| {
            z.chunks_mut(4).take(m).for_each(solve);
            Ok(())
        })
        .unwrap();
        let law = FrictionLaw::Coulomb { coefficient: 0.5 };
        let x0 = [0.4, 0.01, 0.3, 2.0];
        let sc = scales(&ops, &x0, 0.0);
        let mut work = NewtonWork::frictional_for(&ops, Some(&schur)).unwrap();
        // Point 0: x_n − g = 0.2 > 0, |x_t| = 0.05 ≤ μ_f f_n = 1 (stick); point 1: f_n = 0.5,
        // |x_t| = 1 > 0.25 (slip). Then both sliding (point 0: |x_t| = 1.6 > μ_f f_n = 1.5; point
        // 1: 0.8 > 0.375).
        for (iterate, states) in [
            ([0.2, 0.05, 0.1, 1.0], [false, true]),
            ([0.3, -1.6, 0.15, -0.8], [true, true]),
        ] {
            work.s[..4].copy_from_slice(&iterate);
            let (mut lambda, mut slides) = ([0.0; 4], [false; 2]);
            evaluate(
                &ops,
                law,
                &w,
                0.7,
                &x0,
                &sc,
                &mut lambda,
                &mut slides,
                &mut work,
            );
            assert_eq!(slides, states);
            newton_step(&ops, &w, 0.7, &mut work).unwrap();
            let dense = [work.step[0], work.step[1], work.step[2], work.step[3]];
            let r = [-work.g[0], -work.g[1], -work.g[2], -work.g[3]];
            let sn = work.schur.as_mut().unwrap();
            let mut step = [0.0; 4];
            sn.step(&work.point_active, &work.blocks, &r, 0.7, &mut step)
                .unwrap();
            let size = dense.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            for j in 0..4 {
                assert!(
                    (step[j] - dense[j]).abs() <= 1e-10 * size,
                    "{j}: schur {step:?} dense {dense:?}"
                );
            }
        }
        let (refactors, krylov) = work.schur_counts().unwrap();
        assert_eq!(refactors, 1);
        assert!((1..=4).contains(&krylov), "{krylov}");
    }

    #[test]
    fn newton_solves_a_scalar_contact() {
        // One point, w = γ = 1, gap 1, W = −2, cτ² = 1: s = s0 − 2[s − 1]_+. From s0 = 4:
        // s = 4 − 2(s − 1) → s = 2, φ = 1; from s0 = 0.5 the point is inactive, s = 0.5.
        let ops = NitscheOps {
            k: 1,
            dofs: vec![0],
            p: vec![1.0],
            c: vec![1.0],
            s: vec![0.0],
            w: vec![1.0],
            gamma: vec![1.0],
            gap: vec![1.0],
            theta: 1.0,
            penalty: false,
            friction: None,
        };
        let mut work = NewtonWork::new(1);
        let mut phi = [0.0];
        let it = newton(&ops, &[-2.0], 1.0, &[4.0], &[1.0], &mut phi, &mut work).unwrap();
        assert_eq!(phi, [1.0]);
        assert!(it <= 2, "{it}");
        newton(&ops, &[-2.0], 1.0, &[0.5], &[1.0], &mut phi, &mut work).unwrap();
        assert_eq!(phi, [0.0]);
    }
}
