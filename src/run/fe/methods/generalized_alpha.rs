//! Generalized-α/HHT (contract §3.2): the equation at t^{n+1−α} with the history κ_m aⁿ, κ_f Kuⁿ,
//! κ_f fⁿ, Newmark's updates; one step with the nodal multiplier (LCP or Coulomb/Tresca), one
//! with Nitsche/penalty (the engine's semismooth Newton, ± friction). Two bodies solve for the
//! increment (M + cK)(u^{n+1} − uⁿ) = … (issue 44: round-off relative to the step, not to the
//! distance travelled; the one-body runs keep the totals and their numbers).

use super::correction::{add_columns, add_point_columns, add_rows, add_theta_term};
use super::run::MethodRun;
use crate::run::Stop;
use crate::run::fe::config::{LCP_MAX_ITER, LCP_TOL};
use crate::run::fe::nitsche::{newton, newton_friction};
use crate::time::GeneralizedAlphaParams;

impl MethodRun<'_> {
    /// Generalized-α/HHT with Nitsche/penalty: K_Θ in A, the history of the contact force from the
    /// previous step's Newton, f_c^{n+1} by the engine's (frictional) Newton with coefficient c.
    /// The step's total normal force.
    pub(super) fn alpha_nitsche_step(
        &mut self,
        step: usize,
        ga: GeneralizedAlphaParams,
    ) -> Result<f64, Stop<String>> {
        let (tau, n) = (self.tau, self.u.len());
        let c = self.c.expect("implicit methods have a step matrix");
        let t2 = tau * tau;
        let MethodRun {
            geo,
            fac,
            work,
            u,
            v,
            a,
            mu,
            mv,
            ma,
            ku,
            kd,
            sd,
            y,
            pred,
            q,
            lambda,
            lambda_prev,
            newton_work,
            nit_fric,
            newton_max,
            iterations,
            force_vec,
            ..
        } = self;
        let g = &**geo;
        let force_vec: &[f64] = force_vec;
        let f = fac.as_deref().expect("implicit methods have a factor");
        let nit = fac.as_ref().and_then(|f| f.nitsche.as_ref());
        let work = work.as_mut().expect("implicit methods have solve scratch");
        // Nitsche/penalty: K_Θ is in A, the contact force f_c(u) =
        // Σ_q φ_q(p_q·u) C_q, f_cⁿ = f_c(uⁿ) (φⁿ kept from the last step's
        // Newton, which solved φ at uⁿ), f_c^{n+1} by the engine's Newton.
        let ops = nit.expect("checked");
        let (km, kf) = ga.history_coefficients(tau);
        let kp = t2 * (0.5 - ga.beta);
        let bt2 = ga.beta * t2;
        // Two bodies step in increments (module header of `crate::run::fe::newmark`): the
        // right-hand side less A uⁿ = M uⁿ + cK_Θuⁿ, ũ − uⁿ in `pred`; not with friction,
        // whose start reads the total u.
        let incr = g.bodies.is_some() && nit_fric.is_none();
        if incr {
            for i in 0..n {
                pred[i] = tau * v[i] + kp * a[i];
                y[i] = tau * mv[i] + (kp - km) * ma[i] - (kf + c) * ku[i] + (c + kf) * force_vec[i];
            }
            add_theta_term(ops, u, kf + c, y);
        } else {
            for i in 0..n {
                pred[i] = u[i] + tau * v[i] + kp * a[i];
                y[i] =
                    mu[i] + tau * mv[i] + (kp - km) * ma[i] - kf * ku[i] + (c + kf) * force_vec[i];
            }
            add_theta_term(ops, u, kf, y);
        }
        add_point_columns(ops, lambda_prev, kf, y);
        sd.copy_from_slice(y);
        f.chol.solve_in_place(y, work);
        work.check()
            .map_err(|e| Stop::Solver(step, e.to_string()))?;
        let it = if let Some(st) = nit_fric.as_mut() {
            // Friction (nitsche.rs header, coefficient c): x0 = P y +
            // k u_tⁿ (the slip from uⁿ), λ the previous step's forces
            // (the warm start), kept for f̄_t.
            st.start_step(ops, y, u, q);
            newton_friction(ops, st.law, &f.h, c, q, lambda, &mut st.slides, newton_work)
        } else {
            for (k, qk) in q.iter_mut().enumerate() {
                *qk = if incr {
                    ops.apply(&ops.p, k, u) + ops.apply(&ops.p, k, y)
                } else {
                    ops.apply(&ops.p, k, y)
                };
            }
            newton(ops, &f.h, c, q, &ops.gap, lambda, newton_work)
        }
        .map_err(|e| Stop::Solver(step, e))?;
        *newton_max = (*newton_max).max(it);
        *iterations += it as i64;
        add_columns(&f.z, lambda, c, y);
        add_point_columns(ops, lambda, c, sd);
        lambda_prev.copy_from_slice(lambda);
        let g1 = 1.0 - ga.gamma;
        if incr {
            // MΔ = AΔ − cK_ΘΔ, one product KΔ; u, K u, M u carried.
            mass_from_step(g, ops, c, y, kd, sd);
            for i in 0..n {
                let an = (y[i] - pred[i]) / bt2;
                let man = (sd[i] - (tau * mv[i] + kp * ma[i])) / bt2;
                v[i] += tau * (g1 * a[i] + ga.gamma * an);
                mv[i] += tau * (g1 * ma[i] + ga.gamma * man);
                a[i] = an;
                ma[i] = man;
                u[i] += y[i];
                ku[i] += kd[i];
                mu[i] += sd[i];
            }
            return Ok(lambda.iter().step_by(ops.per_point()).sum::<f64>());
        }
        // M u^{n+1} = A u^{n+1} − cK_Θu^{n+1}, one product K u^{n+1}.
        std::mem::swap(u, y);
        mass_from_step(g, ops, c, u, ku, sd);
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
        Ok(lambda.iter().step_by(ops.per_point()).sum::<f64>())
    }

    /// Generalized-α/HHT with the nodal multiplier: the history κ_f Bᵀλⁿ (and the previous tangential
    /// forces), the LCP or the frictional problem on By + g. The step's total contact force.
    pub(super) fn alpha_mixed_step(
        &mut self,
        step: usize,
        ga: GeneralizedAlphaParams,
    ) -> Result<f64, Stop<String>> {
        let (tau, n) = (self.tau, self.u.len());
        let c = self.c.expect("implicit methods have a step matrix");
        let t2 = tau * tau;
        let MethodRun {
            geo,
            fac,
            work,
            u,
            v,
            a,
            mu,
            mv,
            ma,
            ku,
            kd,
            sd,
            y,
            pred,
            q,
            lambda,
            lambda_prev,
            lcp,
            fric,
            newton_max,
            iterations,
            gaps,
            force_vec,
            ..
        } = self;
        let g = &**geo;
        let gaps: &[f64] = gaps;
        let force_vec: &[f64] = force_vec;
        let f = fac.as_deref().expect("implicit methods have a factor");
        let work = work.as_mut().expect("implicit methods have solve scratch");
        let (km, kf) = ga.history_coefficients(tau);
        let kp = t2 * (0.5 - ga.beta);
        let bt2 = ga.beta * t2;
        // Two bodies step in increments, as with Nitsche/penalty above.
        let incr = g.bodies.is_some();
        if incr {
            for i in 0..n {
                pred[i] = tau * v[i] + kp * a[i];
                y[i] = tau * mv[i] + (kp - km) * ma[i] - (kf + c) * ku[i] + (c + kf) * force_vec[i];
            }
        } else {
            for i in 0..n {
                pred[i] = u[i] + tau * v[i] + kp * a[i];
                y[i] =
                    mu[i] + tau * mv[i] + (kp - km) * ma[i] - kf * ku[i] + (c + kf) * force_vec[i];
            }
        }
        add_rows(&g.rows, lambda_prev, kf, y);
        if let Some(fr) = fric.as_ref() {
            fr.add_previous_tangential(kf, y);
        }
        sd.copy_from_slice(y);
        f.chol.solve_in_place(y, work);
        work.check()
            .map_err(|e| Stop::Solver(step, e.to_string()))?;
        let it = if let Some(fr) = fric.as_mut() {
            // y is u^{n+1} without contact: slip = Ty − Tuⁿ + (TZ̄μ)c.
            if incr {
                fr.set_free(y, |_, _| 0.0, |j| g.rows.dot_sum(j, u, y) + gaps[j]);
            } else {
                fr.set_free(y, |t, j| -t.dot(j, u), |j| g.rows.dot(j, y) + gaps[j]);
            }
            let it = fr
                .solve(c, false, y, sd, lambda)
                .map_err(|e| Stop::Solver(step, e))?;
            fr.take_forces(1.0);
            it
        } else {
            for (j, (qi, gi)) in q.iter_mut().zip(gaps).enumerate() {
                *qi = if incr {
                    g.rows.dot_sum(j, u, y)
                } else {
                    g.rows.dot(j, y)
                } + gi;
            }
            let it = lcp
                .solve(q, lambda, LCP_MAX_ITER, LCP_TOL)
                .map_err(|e| Stop::Solver(step, e.to_string()))?;
            add_columns(&f.z, lambda, c, y);
            add_rows(&g.rows, lambda, c, sd);
            it
        };
        *newton_max = (*newton_max).max(it);
        *iterations += it as i64;
        lambda_prev.copy_from_slice(lambda);
        let g1 = 1.0 - ga.gamma;
        if incr {
            // One product, KΔ; MΔ = AΔ − cKΔ, M a^{n+1} = (MΔ − M(ũ − uⁿ))/(βτ²).
            g.k.matvec_into(y, kd);
            for i in 0..n {
                let an = (y[i] - pred[i]) / bt2;
                let md = sd[i] - c * kd[i];
                let man = (md - (tau * mv[i] + kp * ma[i])) / bt2;
                v[i] += tau * (g1 * a[i] + ga.gamma * an);
                mv[i] += tau * (g1 * ma[i] + ga.gamma * man);
                a[i] = an;
                ma[i] = man;
                u[i] += y[i];
                ku[i] += kd[i];
                mu[i] += md;
            }
            return Ok(lambda.iter().sum::<f64>());
        }
        // One product, K u^{n+1}; M u^{n+1} = A u^{n+1} − cKu^{n+1}, and
        // M a^{n+1} = (M u^{n+1} − M ũ)/(βτ²) from the carried products.
        std::mem::swap(u, y);
        g.k.matvec_into(u, ku);
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
        Ok(lambda.iter().sum::<f64>())
    }
}

/// M x = A x − cK_Θx from the step's A x in `sd` (in place), with the one product K x into
/// `kx` (the carried K u or K Δ).
fn mass_from_step(
    g: &crate::run::fe::geometry::Geometry,
    ops: &crate::run::fe::nitsche::NitscheOps,
    c: f64,
    x: &[f64],
    kx: &mut [f64],
    sd: &mut [f64],
) {
    g.k.matvec_into(x, kx);
    for (s, k) in sd.iter_mut().zip(kx.iter()) {
        *s -= c * k;
    }
    add_theta_term(ops, x, c, sd);
}
