//! Nitsche's contact term in the sparse engine (SPEC §2.3, §4; 003 §2): the operators of one
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
//! The hybrid scheme (003 (10)–(11), SPEC §3) is the midpoint rule with the contact term
//! (1/γ)Φ P_Θγ(v), Φ = H(P̃ⁿ)[(P̃ⁿ + P̃ⁿ⁺¹)/2]_+ + H(−P̃ⁿ)([P̃ⁿ]_+ + [P̃ⁿ⁺¹]_+)/2, P̃ = P_γ − g.
//! Its step matrix is Crank–Nicolson's (c = ¼), and since P̃ⁿ is known, Φ = ½[P̃ⁿ⁺¹ − k]_+ with
//! the kink k = −max(P̃ⁿ, 0) (H(0) = ½ gives the same value as P̃ⁿ < 0): the same Newton with
//! per-step kinks g − max(P̃ⁿ, 0), the factor ½ absorbed by τ²/2·½ = cτ².
//!
//! The penalty (SPEC §2.4) is the same operator with P = P_Θγ = u_n (Θ = 0, no σ_n term) and
//! 1/γ_q = κ_q = E·γ0/h_K: the force φ_q = w_q κ_q [u_n − g_q]_+, its potential
//! ½Σ w κ [u_n − g]_+² added to E^h ([`NitscheOps::penalty`]).

use crate::space::fe::nitsche::ContactPoint;

/// Semismooth Newton: relative tolerance and iteration cap (SPEC §4).
pub(crate) const NEWTON_TOL: f64 = 1e-12;
pub(crate) const NEWTON_MAX_ITER: usize = 100;

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
    /// Penalty (SPEC §2.4) instead of Nitsche: P = u_n, 1/γ_q = κ_q, and the penalty
    /// potential ½Σ w κ [u_n − g]_+² belongs to E^h.
    pub penalty: bool,
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

    /// The penalty of SPEC §2.4 as the same operators: κ_q = E·γ0/h_K with E Young's modulus
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

    pub fn len(&self) -> usize {
        self.w.len()
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
    /// Nitsche: (0, E_Θ − E^h = −(Θ/2)(Σ w γ σ_n² − Σ (w/γ)[P_γ − g]_+²), force) (SPEC §2.3);
    /// penalty: (½ Σ w κ [u_n − g]_+², the part of E^h, no E_Θ, force) (SPEC §2.4).
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
        }
    }
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
