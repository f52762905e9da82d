//! The discrete gradient (contract §3.2): the midpoint rule with each point's difference quotient of
//! the contact potential, condensed on the points and solved by semismooth Newton.

use super::correction::{add_columns, add_theta_term};
use super::gradient_newton::gradient_newton;
use super::run::MethodRun;
use crate::run::Stop;

impl MethodRun<'_> {
    /// The discrete gradient: the midpoint rule with the points' difference quotients D_q
    /// (penalty; Nitsche with Θ = 1). The step's total contact force.
    pub(super) fn gradient_step(&mut self, step: usize) -> Result<f64, Stop<String>> {
        let (tau, n) = (self.tau, self.u.len());
        let c = self.c.expect("implicit methods have a step matrix");
        let MethodRun {
            geo,
            fac,
            work,
            u,
            v,
            mv,
            ku,
            kd,
            sd,
            y,
            q,
            lambda,
            grad_work,
            newton_max,
            iterations,
            massless,
            force_vec,
            ..
        } = self;
        let g = &**geo;
        let massless: &[usize] = massless;
        let force_vec: &[f64] = force_vec;
        let f = fac.as_deref().expect("implicit methods have a factor");
        let nit = fac.as_ref().and_then(|f| f.nitsche.as_ref());
        let work = work.as_mut().expect("implicit methods have solve scratch");
        let ops = nit.expect("the discrete gradient has contact points");
        // b = τMvⁿ − τ²/2 K_Θuⁿ + τ²/2 F, K_Θ u = Ku − Θ Σ w γ s (s·u).
        for i in 0..n {
            y[i] = tau * mv[i] - 2.0 * c * ku[i] + 2.0 * c * force_vec[i];
        }
        add_theta_term(ops, u, 2.0 * c, y);
        sd.copy_from_slice(y);
        f.chol.solve_in_place(y, work);
        work.check()
            .map_err(|e| Stop::Solver(step, e.to_string()))?;
        for k in 0..ops.len() {
            let sn = ops.apply(&ops.p, k, u);
            grad_work.a[k] = sn - ops.gap[k];
            q[k] = sn + ops.apply(&ops.p, k, y);
        }
        let it =
            gradient_newton(ops, &f.h, 2.0 * c, q, grad_work).map_err(|e| Stop::Solver(step, e))?;
        *newton_max = (*newton_max).max(it);
        *iterations += it as i64;
        // Δu = y + τ²/2 Z D = y + c Z (2D); A Δu = b + c Σ 2D_q C_q.
        for (l, dq) in lambda.iter_mut().zip(&grad_work.d) {
            *l = 2.0 * dq;
        }
        add_columns(&f.z, lambda, c, y);
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
        g.k.matvec_into(y, kd);
        for i in 0..n {
            sd[i] -= c * kd[i];
        }
        add_theta_term(ops, y, c, sd);
        for i in 0..n {
            v[i] = 2.0 * y[i] / tau - v[i];
            mv[i] = 2.0 * sd[i] / tau - mv[i];
            u[i] += y[i];
            ku[i] += kd[i];
        }
        for &i in massless {
            v[i] = y[i] / tau;
        }
        Ok(grad_work.d.iter().sum::<f64>())
    }
}
