//! Iterative refinement of the condensed `mixed` step on the full residual (contract §4, §1.10).
//!
//! The condensed step u = y + cτ²Zλ, y = A⁻¹b, solves A u = b + cτ²Bᵀλ with the LCP on the rows.
//! A body held by contact alone at a step τ far above its periods (the patch test: one
//! backward-Euler step, τ = 1e6) makes A = M + cτ²K nearly singular along its rigid modes
//! (M/τ² ≈ 1e-12 of K), W = B A⁻¹ Bᵀ is dominated by them and the condensed solve loses about
//! 12 digits. With the LCP's active set I fixed, the step is the linear system
//! A u = b + cτ²B_Iᵀλ_I, B_I u + g_I = 0, and its residual (r, d) can be corrected:
//! s = A⁻¹r, H_II δ = −(B_I(u + s) + g_I) with H = cτ²BZ, u ← u + s + cτ²Z_I δ, λ_I ← λ_I + δ,
//! a few times until r meets the tolerance — the classic refinement, each sweep a step solve,
//! two products and a dense solve on the active rows. A step whose residual already meets the
//! tolerance (every ordinary dynamic step) costs the two products only.

use super::config::FeConfig;
use super::factor::Factored;
use super::full_newton::{FullNewton, full_capable};
use super::geometry::Geometry;
use super::nitsche::NitscheOps;
use crate::space::step_solver::StepWork;

/// At most this many correction sweeps per step (the contract's 2–3, with one to spare).
const SWEEPS: usize = 4;
/// The same for the rows of a projecting pairing (node-to-segment, mortar; issue 45): the
/// standard mortar basis couples each row to its neighbours' nodes and its sweeps contract
/// more slowly (the blocks3d patch test at n_a = 6: 1.3e-8 after 4 sweeps, 6e-13 within 12).
/// The node-to-node rows keep their cap, and their numbers.
const GENERAL_SWEEPS: usize = 12;
/// The penalty's sweeps: each contracts the error by about 1e-2 on the patch test (its
/// condensed Jacobian carries the same lost digits as W), so more of them.
const PENALTY_SWEEPS: usize = 12;
/// The penalty's sweeps on a projecting pairing's rows (issue 45), as [`GENERAL_SWEEPS`].
const GENERAL_PENALTY_SWEEPS: usize = 40;
/// The relative residual ‖r‖∞ ≤ TOL·(‖b‖∞ + ‖Au‖∞ + cτ²‖Bᵀλ‖∞) that ends the sweeps.
const TOL: f64 = 1e-14;
/// The full-system Newton ([`FullNewton`]): iterations per step, step halvings per iteration,
/// and the residual it accepts where round-off stalls it above [`TOL`] (1e-12 of the scale:
/// forces and displacements to ~1e-12 relative, far inside the patch test's 1e-8).
const FULL_MAX: usize = 50;
const HALVINGS: usize = 10;
const FLOOR: f64 = 1e-12;

/// The refinement of a Newmark/θ run (None: not refined): two bodies with `mixed`, or with
/// the penalty's rows or Nitsche's points outside the hybrid scheme (whose kinks move the law,
/// nitsche.rs header), frictionless; one body against the obstacle keeps its numbers.
pub(super) fn refinement(
    g: &Geometry,
    cfg: &FeConfig,
    fac: &Factored,
    n: usize,
    nc: usize,
) -> Option<Box<Refinement>> {
    let two = g.bodies.is_some();
    let refinable = match fac.nitsche.as_ref() {
        None => fac.friction.is_none(),
        Some(o) => full_capable(two, cfg, o),
    };
    // Without W (full-system runs) no dense block of the active rows is ever made.
    let dense = if fac.condensed { nc } else { 0 };
    (two && refinable).then(|| Box::new(Refinement::new(n, nc, dense)))
}

/// A run's refinement workspace (allocated once).
#[derive(Debug)]
pub(super) struct Refinement {
    /// The step's right-hand side b (kept before the solve overwrites it).
    rhs: Vec<f64>,
    r: Vec<f64>,
    mk: Vec<f64>,
    active: Vec<usize>,
    h: Vec<f64>,
    d: Vec<f64>,
    /// Correction sweeps made over the run.
    pub(super) sweeps: usize,
    /// Nitsche's points and the penalty's rows: the full-system Newton, made at its first use
    /// (a step the condensed sweeps do not resolve), its step, and its iterations over the run.
    full: Option<Box<FullNewton>>,
    step: Vec<f64>,
    pub(super) full_iterations: usize,
}

impl Refinement {
    /// For n dofs and nc contact rows (or penalty points), `dense` of them in the condensed
    /// sweeps' dense blocks (nc, or 0 without W).
    pub(super) fn new(n: usize, nc: usize, dense: usize) -> Refinement {
        Refinement {
            rhs: vec![0.0; n],
            r: vec![0.0; n],
            mk: vec![0.0; n],
            active: Vec::with_capacity(nc),
            h: vec![0.0; dense * dense],
            d: vec![0.0; dense],
            sweeps: 0,
            full: None,
            step: Vec::new(),
            full_iterations: 0,
        }
    }

    /// Keep the step's right-hand side b.
    pub(super) fn keep_rhs(&mut self, b: &[f64]) {
        self.rhs.copy_from_slice(b);
    }

    /// Refine u (= y + cτ²Zλ on entry) and λ: sweeps on the active rows of λ, then the rows
    /// that violate the contact conditions at the refined state (an inactive row penetrating,
    /// an active one pulling) change sides and the sweeps resume — an active-set method on the
    /// exact step problem started from the LCP's answer, which the ill-conditioned W can get
    /// wrong (the patch test: 2 of 5 rows). Stepping in increments (`base` = uⁿ), `u` is the
    /// increment and the rows read B(uⁿ + u) + g. Returns the sweeps made.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn refine(
        &mut self,
        g: &Geometry,
        fac: &Factored,
        c_tau2: f64,
        gaps: &[f64],
        base: Option<&[f64]>,
        lambda: &mut [f64],
        u: &mut [f64],
        work: &mut StepWork,
    ) -> Result<(), String> {
        let nc = g.rows.len();
        if lambda.iter().all(|&l| l == 0.0) {
            return Ok(());
        }
        for _ in 0..(10 + 2 * nc) {
            self.active.clear();
            self.active.extend((0..nc).filter(|&i| lambda[i] != 0.0));
            if !self.active.is_empty() {
                self.sweeps(g, fac, c_tau2, (gaps, base), lambda, u, work)?;
            }
            // The sides: 1e-10 of the state's scale, far above the sweeps' round-off and far
            // below any physical penetration or pull.
            let scale = gaps
                .iter()
                .chain(u.iter())
                .chain(base.unwrap_or(&[]))
                .fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
            let fscale = lambda.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
            let mut changed = false;
            for i in 0..nc {
                if lambda[i] == 0.0 && row_gap(g, i, base, u) + gaps[i] < -1e-10 * scale {
                    // A tiny seed: the sweeps then find its force.
                    lambda[i] = f64::MIN_POSITIVE;
                    changed = true;
                } else if lambda[i] < -1e-10 * fscale {
                    // Drop the row: its force leaves the residual, the sweeps correct u.
                    lambda[i] = 0.0;
                    changed = true;
                }
            }
            if !changed {
                return Ok(());
            }
        }
        Err("iterative refinement: the contact set did not settle".into())
    }

    /// The bodies' part of the residual, r = b − (M + cτ²K)u, into `r`; returns the scale
    /// max(‖b‖∞, ‖(M + cτ²K)u‖∞) the tolerance is relative to.
    fn body_residual(&mut self, g: &Geometry, fac: &Factored, c_tau2: f64, u: &[f64]) -> f64 {
        fac.m.matvec_into(u, &mut self.r);
        g.k.matvec_into(u, &mut self.mk);
        let mut scale = 0.0f64;
        for ((r, mk), b) in self.r.iter_mut().zip(&self.mk).zip(&self.rhs) {
            let au = *r + c_tau2 * mk;
            scale = scale.max(b.abs()).max(au.abs());
            *r = b - au;
        }
        scale
    }

    /// Correction sweeps on the rows `active` until the residual meets the tolerance (`base`:
    /// [`Refinement::refine`]).
    #[allow(clippy::too_many_arguments)]
    fn sweeps(
        &mut self,
        g: &Geometry,
        fac: &Factored,
        c_tau2: f64,
        (gaps, base): (&[f64], Option<&[f64]>),
        lambda: &mut [f64],
        u: &mut [f64],
        work: &mut StepWork,
    ) -> Result<(), String> {
        let (n, nc) = (u.len(), g.rows.len());
        let cap = if g.rows.is_general() {
            GENERAL_SWEEPS
        } else {
            SWEEPS
        };
        for _ in 0..cap {
            // r = b + cτ²Bᵀλ − (M + cτ²K)u.
            let mut scale = self.body_residual(g, fac, c_tau2, u);
            for &i in &self.active {
                g.rows.add(i, c_tau2 * lambda[i], &mut self.r);
                scale = scale.max((c_tau2 * lambda[i]).abs());
            }
            let res = self.r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let defect = self.active.iter().fold(0.0f64, |m, &i| {
                m.max((row_gap(g, i, base, u) + gaps[i]).abs())
            });
            // The defect's round-off is relative to the total uⁿ + u.
            let uscale = u
                .iter()
                .chain(base.unwrap_or(&[]))
                .fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
            if res <= TOL * scale && defect <= TOL * uscale {
                break;
            }
            self.sweeps += 1;
            fac.chol.solve_in_place(&mut self.r, work);
            work.check().map_err(|e| e.to_string())?;
            // u + s, and the active rows' defects −(B_I(u + s) + g_I).
            for (ui, si) in u.iter_mut().zip(&self.r) {
                *ui += si;
            }
            let k = self.active.len();
            for (a, &i) in self.active.iter().enumerate() {
                self.d[a] = -(row_gap(g, i, base, u) + gaps[i]);
                for (b, &j) in self.active.iter().enumerate() {
                    self.h[a * k + b] = fac.h[i * nc + j];
                }
            }
            solve_dense(&mut self.h[..k * k], &mut self.d[..k], k)?;
            for (a, &i) in self.active.iter().enumerate() {
                let delta = self.d[a];
                lambda[i] += delta;
                let zi = &fac.z[i * n..(i + 1) * n];
                for (ui, zv) in u.iter_mut().zip(zi) {
                    *ui += c_tau2 * delta * zv;
                }
            }
        }
        Ok(())
    }
}

impl Refinement {
    /// The penalty's rows and Nitsche's points (contract §2.6; nitsche.rs header):
    /// A u + cτ² Σ_q φ_q(p_q·u) t_q = b, A = M + cτ²(K − Θ Σ_q w_q γ_q s_q s_qᵀ), φ_q(s) =
    /// (w_q/γ_q)[s − g_q]_+, t_q = −c_q (the penalty: Θ = 0, t_q = p_q, 1/γ_q = κ_q). On the
    /// active points I (s_q > g_q) the correction δu of the residual r solves
    /// (A + cτ² Σ_I (w/γ) t pᵀ) δu = r: with s = A⁻¹r and Z_q = A⁻¹c_q, δu = s + cτ² Z_I D e
    /// with (I − cτ² W_II D) e = P_I s, D = diag(w/γ) — the Newton's own Jacobian — then the
    /// points change sides and the sweeps resume. λ = φ(P u) at the end (the forces the energy
    /// and the next Newton start from). The penalty's numbers are those of its own form
    /// (c_q = −p_q exactly, and no Θ-term).
    /// Stepping in increments (`base` = uⁿ), `u` is the increment and the points read
    /// P uⁿ + P u. Where the sweeps end above the tolerance (W's lost digits: a body held by
    /// contact alone, module header) the full-system Newton finishes the step
    /// ([`Self::full_newton`]); returns whether it did.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn refine_penalty(
        &mut self,
        g: &Geometry,
        fac: &Factored,
        ops: &NitscheOps,
        c_tau2: f64,
        base: Option<&[f64]>,
        lambda: &mut [f64],
        u: &mut [f64],
        work: &mut StepWork,
    ) -> Result<bool, String> {
        let st = PenaltyStep {
            g,
            fac,
            ops,
            c_tau2,
            base,
        };
        let (n, nq) = (u.len(), ops.len());
        let cap = if g.rows.is_general() {
            GENERAL_PENALTY_SWEEPS
        } else {
            PENALTY_SWEEPS
        };
        let mut converged = false;
        // Without W (`full_only`) the full-system Newton alone solves the step.
        let cap = if fac.condensed { cap } else { 0 };
        for _ in 0..cap {
            let (res, scale) = self.penalty_residual(st, u);
            if res <= TOL * scale || self.active.is_empty() {
                converged = res <= TOL * scale;
                break;
            }
            self.sweeps += 1;
            fac.chol.solve_in_place(&mut self.r, work);
            work.check().map_err(|e| e.to_string())?;
            let m = self.active.len();
            for (a, &q) in self.active.iter().enumerate() {
                self.d[a] = ops.apply(&ops.p, q, &self.r);
                let dq = |j: usize| ops.w[j] / ops.gamma[j];
                for (b, &j) in self.active.iter().enumerate() {
                    let id = if a == b { 1.0 } else { 0.0 };
                    self.h[a * m + b] = id - c_tau2 * fac.h[q * nq + j] * dq(j);
                }
            }
            solve_dense(&mut self.h[..m * m], &mut self.d[..m], m)?;
            for (ui, si) in u.iter_mut().zip(&self.r) {
                *ui += si;
            }
            for (a, &q) in self.active.iter().enumerate() {
                let f = c_tau2 * ops.w[q] / ops.gamma[q] * self.d[a];
                for (ui, zv) in u.iter_mut().zip(&fac.z[q * n..(q + 1) * n]) {
                    *ui += f * zv;
                }
            }
        }
        if !converged {
            // The last check before the cap, or a state with no active point that does not
            // solve the step: the condensed sweeps did not reach the tolerance.
            let (res, scale) = self.penalty_residual(st, u);
            converged = res <= TOL * scale;
        }
        let full = !converged;
        if full {
            self.full_newton(st, u)?;
        }
        for (q, l) in lambda.iter_mut().enumerate().take(nq) {
            *l = point_force(ops, base, q, u);
        }
        Ok(full)
    }

    /// The residual r = b − A u + cτ² Σ_q φ_q c_q of the penalty's rows and Nitsche's points
    /// into `r` (A with its Θ-term), the points with φ_q > 0 into `active`; returns ‖r‖∞ and
    /// the scale the tolerance is relative to.
    fn penalty_residual(&mut self, st: PenaltyStep, u: &[f64]) -> (f64, f64) {
        let PenaltyStep {
            g,
            fac,
            ops,
            c_tau2,
            base,
        } = st;
        let (nq, k) = (ops.len(), ops.k);
        let mut scale = self.body_residual(g, fac, c_tau2, u);
        if ops.theta != 0.0 {
            // A's Θ-term: r += cτ²Θ Σ_q w_q γ_q s_q (s_q·u).
            for q in 0..nq {
                let f = c_tau2 * ops.theta * ops.w[q] * ops.gamma[q] * ops.apply(&ops.s, q, u);
                let (coef, dofs) = (&ops.s[q * k..(q + 1) * k], &ops.dofs[q * k..(q + 1) * k]);
                for (c, &d) in coef.iter().zip(dofs) {
                    self.r[d] += f * c;
                }
            }
        }
        self.active.clear();
        for q in 0..nq {
            let f = point_force(ops, base, q, u);
            if f > 0.0 {
                self.active.push(q);
                let (coef, dofs) = (&ops.c[q * k..(q + 1) * k], &ops.dofs[q * k..(q + 1) * k]);
                for (c, &d) in coef.iter().zip(dofs) {
                    self.r[d] += c_tau2 * f * c;
                }
                scale = scale.max((c_tau2 * f).abs());
            }
        }
        (self.r.iter().fold(0.0f64, |m, x| m.max(x.abs())), scale)
    }

    /// Semismooth Newton on the full step system ([`FullNewton`]) from `u`, where the
    /// condensed sweeps did not reach the tolerance: each iteration factors J on the active
    /// points and steps along J⁻¹r, halving the step while ‖r‖∞ does not decrease (the
    /// piecewise-linear residual's merit; at most [`HALVINGS`] times, then the shortest step
    /// is taken). Ends at the tolerance, or at the round-off floor: a step that no longer
    /// halves the residual with the active set unchanged, below [`FLOOR`] of the scale.
    fn full_newton(&mut self, st: PenaltyStep, u: &mut [f64]) -> Result<(), String> {
        let (g, fac, ops, c_tau2) = (st.g, st.fac, st.ops, st.c_tau2);
        if self.full.is_none() {
            self.full = Some(Box::new(FullNewton::new(&fac.m, &g.k, ops, c_tau2)?));
            self.step = vec![0.0; u.len()];
        }
        let (mut res, mut scale) = self.penalty_residual(st, u);
        for _ in 0..FULL_MAX {
            if res <= TOL * scale {
                return Ok(());
            }
            self.full_iterations += 1;
            self.step.copy_from_slice(&self.r);
            let active_before = self.active.len();
            let full = self.full.as_mut().expect("made above");
            full.solve(ops, c_tau2, &self.active, &mut self.step)?;
            let mut alpha = 1.0;
            for (ui, si) in u.iter_mut().zip(&self.step) {
                *ui += si;
            }
            let (mut trial, mut trial_scale) = self.penalty_residual(st, u);
            for _ in 0..HALVINGS {
                if trial < res {
                    break;
                }
                alpha *= 0.5;
                for (ui, si) in u.iter_mut().zip(&self.step) {
                    *ui -= alpha * si;
                }
                (trial, trial_scale) = self.penalty_residual(st, u);
            }
            let stalled = trial > 0.5 * res && self.active.len() == active_before;
            (res, scale) = (trial, trial_scale);
            if stalled && res <= FLOOR * scale {
                return Ok(());
            }
        }
        if res <= FLOOR * scale {
            return Ok(());
        }
        Err(format!(
            "full-system Newton did not converge in {FULL_MAX} iterations (residual {res:.3e}, scale {scale:.3e})"
        ))
    }
}

/// One step's data for the penalty's and Nitsche's residual ([`Refinement::refine_penalty`]).
#[derive(Clone, Copy)]
struct PenaltyStep<'a> {
    g: &'a Geometry,
    fac: &'a Factored,
    ops: &'a NitscheOps,
    c_tau2: f64,
    base: Option<&'a [f64]>,
}

/// Point q's force φ_q = (w_q/γ_q)[p_q·u − g_q]_+, reading p_q·(uⁿ + u) when stepping in
/// increments (`base` = uⁿ).
fn point_force(ops: &NitscheOps, base: Option<&[f64]>, q: usize, u: &[f64]) -> f64 {
    let s = match base {
        Some(b) => ops.apply(&ops.p, q, b) + ops.apply(&ops.p, q, u),
        None => ops.apply(&ops.p, q, u),
    };
    ops.w[q] / ops.gamma[q] * (s - ops.gap[q]).max(0.0)
}

/// B_i·(uⁿ + u) stepping in increments (`base` = uⁿ; each entry's sum first, as the step's
/// contact problem reads it), else B_i·u.
fn row_gap(g: &Geometry, i: usize, base: Option<&[f64]>, u: &[f64]) -> f64 {
    match base {
        Some(b) => g.rows.dot_sum(i, b, u),
        None => g.rows.dot(i, u),
    }
}

/// x with H x = d in place of d (H row-major k × k, destroyed): Gaussian elimination with
/// partial pivoting.
fn solve_dense(h: &mut [f64], d: &mut [f64], k: usize) -> Result<(), String> {
    for c in 0..k {
        let p = (c..k)
            .max_by(|&a, &b| h[a * k + c].abs().total_cmp(&h[b * k + c].abs()))
            .expect("a pivot row");
        if h[p * k + c] == 0.0 {
            return Err("iterative refinement: the active rows' W is singular".into());
        }
        if p != c {
            for j in 0..k {
                h.swap(p * k + j, c * k + j);
            }
            d.swap(p, c);
        }
        for r in c + 1..k {
            let f = h[r * k + c] / h[c * k + c];
            for j in c..k {
                h[r * k + j] -= f * h[c * k + j];
            }
            d[r] -= f * d[c];
        }
    }
    for c in (0..k).rev() {
        let s: f64 = (c + 1..k).map(|j| h[c * k + j] * d[j]).sum();
        d[c] = (d[c] - s) / h[c * k + c];
    }
    Ok(())
}
