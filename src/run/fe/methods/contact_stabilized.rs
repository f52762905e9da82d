//! Contact-stabilized Newmark (contract §3.2): an M-projected predictor (an LCP on W_M = BM⁻¹Bᵀ),
//! then kane's trapezoidal corrector from it.

use super::correction::{add_columns, implicit_contact_correction};
use super::run::MethodRun;
use crate::run::Stop;
use crate::run::fe::config::{LCP_MAX_ITER, LCP_TOL};

impl MethodRun<'_> {
    /// Contact-stabilized Newmark: the frictionless M-projected predictor (an LCP on BM⁻¹Bᵀ), then
    /// kane's corrector from it. The step's total contact force.
    pub(super) fn csn_step(&mut self, step: usize) -> Result<f64, Stop<String>> {
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
            pred,
            tmp,
            q,
            lambda,
            nu,
            lcp,
            lcp_pred,
            fric,
            newton_max,
            iterations,
            gaps,
            force_vec,
            minv,
            ..
        } = self;
        let g = &**geo;
        let gaps: &[f64] = gaps;
        let force_vec: &[f64] = force_vec;
        let f = fac.as_deref().expect("implicit methods have a factor");
        let work = work.as_mut().expect("implicit methods have solve scratch");
        let mi = minv.as_ref().expect("CSN has M⁻¹Bᵀ");
        let lp = lcp_pred.as_mut().expect("CSN has its predictor LCP");
        for i in 0..n {
            pred[i] = u[i] + tau * v[i];
        }
        for (j, (qi, gi)) in q.iter_mut().zip(gaps).enumerate() {
            *qi = g.rows.dot(j, pred) + gi;
        }
        let it = lp
            .solve(q, nu, LCP_MAX_ITER, LCP_TOL)
            .map_err(|e| Stop::Solver(step, format!("predictor: {e}")))?;
        *iterations += it as i64;
        add_columns(&mi.zm, nu, 1.0, pred);
        // K u^pred = Kuⁿ + τKvⁿ + (KM⁻¹Bᵀ)ν, from the carried products.
        for i in 0..n {
            tmp[i] = ku[i] + tau * kv[i];
        }
        add_columns(&mi.kzm, nu, 1.0, tmp);
        for i in 0..n {
            y[i] = -c * (ku[i] + tmp[i]) + 2.0 * c * force_vec[i];
        }
        sd.copy_from_slice(y);
        f.chol.solve_in_place(y, work);
        work.check()
            .map_err(|e| Stop::Solver(step, e.to_string()))?;
        // Slip = u_t^{n+1} − u_tⁿ = T(u^pred − uⁿ) + TΔ.
        let it2 = implicit_contact_correction(
            fric.as_mut(),
            lcp,
            f,
            &g.rows,
            gaps,
            pred,
            |t, j| t.dot(j, pred) - t.dot(j, u),
            c,
            (q, lambda),
            y,
            sd,
        )
        .map_err(|e| Stop::Solver(step, e))?;
        *newton_max = (*newton_max).max(it + it2);
        *iterations += it2 as i64;
        g.k.matvec_into(y, kd);
        for i in 0..n {
            let md = sd[i] - c * kd[i];
            v[i] += 2.0 * y[i] / tau;
            mv[i] += 2.0 * md / tau;
            u[i] = pred[i] + y[i];
            ku[i] = tmp[i] + kd[i];
            kv[i] += 2.0 * kd[i] / tau;
        }
        Ok(0.5 * lambda.iter().sum::<f64>())
    }
}
