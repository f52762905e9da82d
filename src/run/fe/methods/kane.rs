//! Kane's method (contract §3.2): the trapezoidal increment on Crank–Nicolson's S = M + τ²/4 K
//! with the condensed contact correction, v^{n+1} = 2Δu/τ − vⁿ.

use super::correction::implicit_contact_correction;
use super::run::MethodRun;
use crate::run::Stop;

impl MethodRun<'_> {
    /// Kane's trapezoidal increment: S Δu = τMvⁿ − τ²/2 Kuⁿ + τ²/2 F + τ²/2 Bᵀλ, v^{n+1} = 2Δu/τ − vⁿ,
    /// the massless rows' velocity Δu/τ. The step's total contact force (μ = 2λ).
    pub(super) fn kane_step(&mut self, step: usize) -> Result<f64, Stop<String>> {
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
            lcp,
            fric,
            newton_max,
            iterations,
            gaps,
            massless,
            force_vec,
            ..
        } = self;
        let g = &**geo;
        let gaps: &[f64] = gaps;
        let massless: &[usize] = massless;
        let force_vec: &[f64] = force_vec;
        let f = fac.as_deref().expect("implicit methods have a factor");
        let work = work.as_mut().expect("implicit methods have solve scratch");
        // b = τMvⁿ − τ²/2 Kuⁿ + τ²/2 F, kept in `sd` for S Δ below.
        for i in 0..n {
            y[i] = tau * mv[i] - 2.0 * c * ku[i] + 2.0 * c * force_vec[i];
        }
        sd.copy_from_slice(y);
        f.chol.solve_in_place(y, work);
        work.check()
            .map_err(|e| Stop::Solver(step, e.to_string()))?;
        // Slip = TΔu: q_t = Ty.
        let it = implicit_contact_correction(
            fric.as_mut(),
            lcp,
            f,
            &g.rows,
            gaps,
            u,
            |_, _| 0.0,
            c,
            (q, lambda),
            y,
            sd,
        )
        .map_err(|e| Stop::Solver(step, e))?;
        *newton_max = (*newton_max).max(it);
        *iterations += it as i64;
        // One product: KΔ; then MΔ = SΔ − cKΔ (no division by c).
        g.k.matvec_into(y, kd);
        for i in 0..n {
            let md = sd[i] - c * kd[i];
            v[i] = 2.0 * y[i] / tau - v[i];
            mv[i] = 2.0 * md / tau - mv[i];
            u[i] += y[i];
            ku[i] += kd[i];
        }
        for &i in massless {
            v[i] = y[i] / tau;
        }
        // μ = 2λ: the contact force enters with τ²/2 = 2c.
        Ok(0.5 * lambda.iter().sum::<f64>())
    }
}
