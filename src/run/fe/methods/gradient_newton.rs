//! The discrete gradient's contact law on the points (contract §3.2): semismooth Newton on
//! s = s⁰ + cW D(s) with each point's difference quotient D_q of the penalty/Nitsche potential
//! and its slope ([`crate::contact::gradient`]), the Jacobian restricted to the points with
//! D_q or D'_q ≠ 0.

use crate::contact::gradient::{difference_quotient, difference_quotient_slope};
use crate::run::fe::nitsche::{NEWTON_MAX_ITER, NEWTON_TOL, NitscheOps, lu_solve};

/// The discrete gradient's Newton scratch (allocated once per run).
pub(super) struct GradientWork {
    pub(super) s: Vec<f64>,
    /// sⁿ − g per point (the difference quotient's left end).
    pub(super) a: Vec<f64>,
    pub(super) d: Vec<f64>,
    pub(super) slope: Vec<f64>,
    pub(super) g: Vec<f64>,
    pub(super) delta: Vec<f64>,
    pub(super) active: Vec<usize>,
    pub(super) jac: Vec<f64>,
    pub(super) perm: Vec<usize>,
}

impl GradientWork {
    pub(super) fn new(nq: usize) -> GradientWork {
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
/// that stops decreasing below contract §4's 1e-12 (relative) is accepted as converged.
pub(super) fn gradient_newton(
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
