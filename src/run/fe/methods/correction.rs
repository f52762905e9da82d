//! The condensed contact correction the contract §3.2 methods share: y += s Zμ over the nonzero
//! multipliers, the contact rows and Nitsche's point columns and Θ-term added to a right-hand
//! side, and the implicit correction of `kane` and contact-stabilized Newmark.

use super::friction::Friction;
use crate::contact::Lcp;
use crate::run::fe::config::{LCP_MAX_ITER, LCP_TOL};
use crate::run::fe::factor::Factored;
use crate::run::fe::nitsche::NitscheOps;
use crate::run::fe::rows::Rows;

/// y += s Σ_j μ_j Z_j over the columns with μ_j ≠ 0 (Z column-major, n rows).
/// The contact correction `kane` and `contact-stabilized-newmark` share (one step matrix
/// S = M + cK, c = τ²/4): `y` = S⁻¹b is the contact-free increment from `base` (uⁿ for
/// `kane`, u^pred for CSN) and `sd` = b. Frictional: the condensed Coulomb/Tresca problem
/// with gaps base + y + g and slips off + Ty (off = 0, or u^pred − uⁿ), its forces taken as
/// the scheme's (μ = 2λ: ½); frictionless: the LCP on the same gaps, Z's columns added to `y`
/// and the contact rows to `sd` with weight c. `q`, `lambda`: the LCP's gaps and the normal
/// multipliers (warm start in, solution out). Returns the Newton steps.
#[allow(clippy::too_many_arguments)]
pub(super) fn implicit_contact_correction(
    fric: Option<&mut Friction>,
    lcp: &mut Lcp,
    f: &Factored,
    contact: &Rows,
    gaps: &[f64],
    base: &[f64],
    off: impl Fn(&Rows, usize) -> f64,
    c: f64,
    (q, lambda): (&mut [f64], &mut [f64]),
    y: &mut [f64],
    sd: &mut [f64],
) -> Result<usize, String> {
    if let Some(fr) = fric {
        fr.set_free(y, off, |j| {
            contact.dot(j, base) + contact.dot(j, y) + gaps[j]
        });
        let it = fr.solve(c, false, y, sd, lambda)?;
        fr.take_forces(0.5);
        Ok(it)
    } else {
        for (j, (qi, gi)) in q.iter_mut().zip(gaps).enumerate() {
            *qi = contact.dot(j, base) + contact.dot(j, y) + gi;
        }
        let it = lcp
            .solve(q, lambda, LCP_MAX_ITER, LCP_TOL)
            .map_err(|e| e.to_string())?;
        add_columns(&f.z, lambda, c, y);
        add_rows(contact, lambda, c, sd);
        Ok(it)
    }
}

pub(super) fn add_columns(z: &[f64], mu: &[f64], s: f64, y: &mut [f64]) {
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
pub(super) fn add_rows(rows: &Rows, mu: &[f64], s: f64, y: &mut [f64]) {
    for (j, l) in mu.iter().enumerate() {
        rows.add(j, s * l, y);
    }
}

/// y += s Θ Σ_q w_q γ_q Σ_r (σ_r,q·x) σ_r,q: the Nitsche Θ-term of −K_Θ x = −Kx + Θ Σ w γ
/// s (s·x) (with friction also the σ_t rows' −Θ∫γ σ_t(u)·σ_t(v), as the step matrix,
/// [`NitscheOps::sigma_row`]), scaled by s (nothing for the penalty, Θ = 0).
pub(super) fn add_theta_term(ops: &NitscheOps, x: &[f64], s: f64, y: &mut [f64]) {
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
pub(super) fn add_point_columns(ops: &NitscheOps, phi: &[f64], s: f64, y: &mut [f64]) {
    for (j, p) in phi.iter().enumerate() {
        if *p != 0.0 {
            let (row, dofs) = ops.c_row(j);
            for (&gd, &ck) in dofs.iter().zip(row) {
                y[gd] += s * p * ck;
            }
        }
    }
}
