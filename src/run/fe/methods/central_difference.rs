//! Kinematic central difference with the lumped mass (contract §3.2, module header of [`super`]):
//! explicit, no solve; a contact dof below the obstacle is put on it by a local impulse (two
//! bodies: a node pair that would interpenetrate is put in contact by an impulse on both nodes,
//! action = reaction), and with friction each node's tangential force is projected onto its
//! disc.

use super::run::MethodRun;
use crate::run::Stop;

impl MethodRun<'_> {
    /// Kinematic central difference (lumped M): v^{n+½} = vⁿ + τ/2 aⁿ, u^{n+1} = uⁿ + τv^{n+½}, a contact
    /// dof below the obstacle put on it by a local impulse (its friction projected per node),
    /// a^{n+1} = M⁻¹(F − Ku^{n+1}), v^{n+1} = v^{n+½} + τ/2 a^{n+1}: no solve. The step's
    /// total contact force.
    pub(super) fn kinematic_step(&mut self, _step: usize) -> Result<f64, Stop<String>> {
        let (tau, n) = (self.tau, self.u.len());
        let MethodRun {
            geo,
            u,
            v,
            a,
            mv,
            ku,
            fric,
            gaps,
            diag,
            force_vec,
            ..
        } = self;
        let g = &**geo;
        let gaps: &[f64] = gaps;
        let diag: &[f64] = diag;
        let force_vec: &[f64] = force_vec;
        for i in 0..n {
            v[i] += 0.5 * tau * a[i];
            u[i] += tau * v[i];
        }
        let mut force = 0.0;
        if !g.rows.is_unit() {
            // Two bodies (contract §3.2, §2.6): each row's impulse on its relative position,
            // its two nodes' masses sharing it (the rows are disjoint and frictionless:
            // checked at set-up).
            for (j, gi) in gaps.iter().enumerate() {
                force += g.rows.impulse(j, *gi, diag, tau, u, v);
            }
        }
        let obstacle = if g.rows.is_unit() { g.contact.len() } else { 0 };
        for (j, (&ci, gi)) in g.contact.iter().zip(gaps).enumerate().take(obstacle) {
            let (uc, dv, l) = crate::time::kinematic_impulse(u[ci], -gi, diag[ci], tau);
            u[ci] = uc;
            v[ci] += dv;
            force += l;
            if let Some(fr) = fric.as_mut() {
                fr.forces[j * (fr.nt + 1)] = l;
            }
        }
        if let Some(fr) = fric.as_mut() {
            fr.kinematic(u, v, diag, tau);
        }
        g.k.matvec_into(u, ku);
        for i in 0..n {
            a[i] = (force_vec[i] - ku[i]) / diag[i];
            v[i] += 0.5 * tau * a[i];
            mv[i] = diag[i] * v[i];
        }
        Ok(force)
    }
}
