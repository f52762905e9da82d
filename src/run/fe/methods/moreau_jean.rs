//! Moreau–Jean (contract §3.2): the velocity-level θ-step with impulses on the rows predicted
//! active and Newton's restitution (De Saxcé's law with friction).

use super::correction::{add_columns, add_rows};
use super::run::MethodRun;
use crate::run::Stop;
use crate::run::fe::config::{LCP_MAX_ITER, LCP_TOL};
use crate::time::MoreauJeanParams;

impl MethodRun<'_> {
    /// Moreau–Jean: (M + θ²τ²K)Δv = −τK(uⁿ + θτvⁿ) + τF + Bᵀp on the rows predicted active, Newton's
    /// impact law with restitution e (De Saxcé with friction). The step's mean force p/τ.
    pub(super) fn moreau_jean_step(
        &mut self,
        step: usize,
        mj: MoreauJeanParams,
    ) -> Result<f64, Stop<String>> {
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
            kv,
            kd,
            sd,
            y,
            q,
            lambda,
            rows,
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
        // b = −τK(uⁿ + θτvⁿ) + τF from the carried products.
        for i in 0..n {
            y[i] = -tau * (ku[i] + mj.theta * tau * kv[i]) + tau * force_vec[i];
        }
        sd.copy_from_slice(y);
        f.chol.solve_in_place(y, work);
        work.check()
            .map_err(|e| Stop::Solver(step, e.to_string()))?;
        let mut any = false;
        for (j, gi) in gaps.iter().enumerate() {
            let vj = g.rows.dot(j, v);
            let active = g.rows.dot(j, u) + gi + 0.5 * tau * vj <= 0.0;
            rows[j] = active;
            any |= active;
            q[j] = if active {
                (1.0 + mj.restitution) * vj + g.rows.dot(j, y)
            } else {
                0.0
            };
        }
        if let Some(fr) = fric.as_mut() {
            // De Saxcé on velocities over the active nodes: "gap" =
            // Bv^{n+1} + eBvⁿ (q as above), slip = v_t^{n+1} = T(vⁿ + Δv).
            if any {
                fr.set_free(y, |t, j| t.dot(j, v), |j| q[j]);
                fr.implicit
                    .as_mut()
                    .expect("attached")
                    .active
                    .copy_from_slice(rows);
                let it = fr
                    .solve(c, true, y, sd, lambda)
                    .map_err(|e| Stop::Solver(step, e))?;
                *newton_max = (*newton_max).max(it);
                *iterations += it as i64;
            } else {
                let im = fr.implicit.as_mut().expect("attached");
                im.mu.iter_mut().for_each(|x| *x = 0.0);
                lambda.iter_mut().for_each(|l| *l = 0.0);
            }
            fr.take_forces(c / tau);
        } else if any {
            let it = lcp
                .solve_on(q, lambda, rows, LCP_MAX_ITER, LCP_TOL)
                .map_err(|e| Stop::Solver(step, e.to_string()))?;
            *newton_max = (*newton_max).max(it);
            *iterations += it as i64;
            add_columns(&f.z, lambda, c, y);
            add_rows(&g.rows, lambda, c, sd);
        } else {
            lambda.iter_mut().for_each(|l| *l = 0.0);
        }
        g.k.matvec_into(y, kd);
        for i in 0..n {
            let md = sd[i] - c * kd[i];
            u[i] += tau * (v[i] + mj.theta * y[i]);
            ku[i] += tau * (kv[i] + mj.theta * kd[i]);
            v[i] += y[i];
            mv[i] += md;
            kv[i] += kd[i];
        }
        // p = cμ, reported as the mean force p/τ.
        Ok(c * lambda.iter().sum::<f64>() / tau)
    }
}
