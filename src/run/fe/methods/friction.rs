//! Friction with the nodal multiplier in the contract §3.2 methods (module header of
//! [`super`]): the tangential rows of each Γ_C node (one body: its unit tangential dofs; two
//! bodies: the relative slip e_{a,i,t} − e_{b,π(i),t}, contract §2.6), the step's forces, the
//! condensed Coulomb/Tresca problem and the run's [`FrictionTally`].

use std::sync::Arc;

use crate::contact::FrictionalContact;
use crate::contact::friction::FrictionLaw;
use crate::run::Metrics;
use crate::run::fe::config::{FeConfig, LCP_MAX_ITER, LCP_TOL};
use crate::run::fe::factor::Factored;
use crate::run::fe::geometry::{Geometry, mean_velocity, tangential_rows};
use crate::run::fe::rows::Rows;
use crate::run::friction_tally::{FrictionTally, MeanVelocity};
use crate::space::fe::SymMatrix;

/// The frictional part of a run (module header): the law, the tangential dofs of each Γ_C node,
/// the step's forces and the run's [`FrictionTally`]. Allocated once per run.
pub(super) struct Friction {
    pub(super) law: FrictionLaw,
    /// Tangential directions per node (d − 1).
    pub(super) nt: usize,
    /// Direction k of contact node j's tangential row: row j·nt + k (a unit row on one body).
    pub(super) trows: Rows,
    /// The nodes' trapezoidal weights (sum 1): Γ_C means.
    pub(super) mean_weight: Vec<f64>,
    /// Tresca's weights w_j = ∫_ΓC φ_j of the nodes.
    pub(super) weight: Vec<f64>,
    /// The step's forces on the body, node-major [f_n, f_t…] (forces also where the method's
    /// unknowns are impulses). Until the step's solve, the previous step's: generalized-α's
    /// f_tⁿ of the right-hand side.
    pub(super) forces: Vec<f64>,
    /// u_tⁿ at the tangential dofs (the slip's reference), then Δu_t.
    pub(super) u_t_prev: Vec<f64>,
    pub(super) du_t: Vec<f64>,
    /// The implicit methods' contact problem (None: kinematic central difference).
    pub(super) implicit: Option<Implicit>,
    pub(super) tally: FrictionTally,
    /// The body's mean velocities 1ᵀMv/1ᵀM1 per axis from the carried Mv.
    pub(super) mean: MeanVelocity,
}

/// The implicit methods' frictional contact problem over the step matrix's frictional
/// condensation ([`Factored::friction`]: Z's normal columns, then the tangential ones; W over
/// the rows C node-major, normal then e_1 (, e_2) per node).
pub(super) struct Implicit {
    pub(super) fac: Arc<Factored>,
    /// C's rows and Z's columns in the node-major order of μ.
    pub(super) rows: Rows,
    pub(super) cols: Vec<usize>,
    pub(super) solver: FrictionalContact,
    /// The free gaps and slips of the step, the active mask (Moreau–Jean), the unknowns μ
    /// (node-major, the next step's warm start) and Tresca's weights in μ's unit.
    pub(super) q_n: Vec<f64>,
    pub(super) q_t: Vec<f64>,
    pub(super) active: Vec<bool>,
    pub(super) mu: Vec<f64>,
    pub(super) weights: Vec<f64>,
}

impl Friction {
    /// `weight_new` is f̄_t's weight of f_t^{n+1} (contract §2.5).
    pub(super) fn new(
        g: &Geometry,
        cfg: &FeConfig,
        m: &SymMatrix,
        weight_new: f64,
    ) -> Result<Friction, String> {
        let d = cfg.setup.dim;
        let nt = d - 1;
        let nc = g.contact.len();
        let trows = tangential_rows(g)?;
        let weight = g
            .contact_weight
            .iter()
            .map(|w| w * g.contact_measure)
            .collect();
        Ok(Friction {
            law: cfg.friction,
            nt,
            trows,
            mean_weight: g.contact_weight.clone(),
            weight,
            forces: vec![0.0; nc * d],
            u_t_prev: vec![0.0; nc * nt],
            du_t: vec![0.0; nc * nt],
            implicit: None,
            tally: FrictionTally::new(nc, d, cfg.setup.h, weight_new),
            mean: mean_velocity(g, m),
        })
    }

    /// Attach the implicit methods' contact problem on the factor `fac` (made with the
    /// frictional columns) and the scale of μ: f = `force_per_mu`·μ, so Tresca's bound s·w_j
    /// on the force is s·w_j/`force_per_mu` on μ.
    pub(super) fn attach(
        &mut self,
        g: &Geometry,
        fac: &Arc<Factored>,
        force_per_mu: f64,
    ) -> Result<(), String> {
        let ff = fac
            .friction
            .as_ref()
            .ok_or("the step factor has no frictional columns")?;
        let (nt, nc) = (self.nt, g.contact.len());
        let d = nt + 1;
        // μ's unknown j·d + a: node j's normal row (a = 0) or its tangential row a − 1.
        let rows = Rows::gather(nc * d, |k| {
            let (j, a) = (k / d, k % d);
            if a == 0 {
                (&g.rows, j)
            } else {
                (&ff.tangential, j * nt + a - 1)
            }
        });
        let cols = (0..nc * d)
            .map(|k| {
                let (j, a) = (k / d, k % d);
                if a == 0 { j } else { nc + j * nt + a - 1 }
            })
            .collect();
        self.implicit = Some(Implicit {
            fac: Arc::clone(fac),
            rows,
            cols,
            solver: FrictionalContact::new(nc, d, ff.w.clone()),
            q_n: vec![0.0; nc],
            q_t: vec![0.0; nc * nt],
            active: vec![true; nc],
            mu: vec![0.0; nc * d],
            weights: self.weight.iter().map(|w| w / force_per_mu).collect(),
        });
        Ok(())
    }

    /// Keep u_tⁿ before a step.
    pub(super) fn begin(&mut self, u: &[f64]) {
        for (j, p) in self.u_t_prev.iter_mut().enumerate() {
            *p = self.trows.dot(j, u);
        }
    }

    /// The free gaps q_n and slips q_t = Ty + `off` (T the tangential rows; `off(T, j)` the
    /// method's slip reference at row j, module header) into the problem; `gap(j)` is node j's.
    pub(super) fn set_free(
        &mut self,
        y: &[f64],
        off: impl Fn(&Rows, usize) -> f64,
        gap: impl Fn(usize) -> f64,
    ) {
        let im = self.implicit.as_mut().expect("an implicit method");
        for (j, q) in im.q_n.iter_mut().enumerate() {
            *q = gap(j);
        }
        for (j, q) in im.q_t.iter_mut().enumerate() {
            *q = self.trows.dot(j, y) + off(&self.trows, j);
        }
    }

    /// Solve the step's problem (over the active nodes if `masked`), then y += cZ̄μ and
    /// sd += cCᵀμ; the normal unknowns into `normal` (the frictionless code's λ). Returns the
    /// Newton steps.
    pub(super) fn solve(
        &mut self,
        c: f64,
        masked: bool,
        y: &mut [f64],
        sd: &mut [f64],
        normal: &mut [f64],
    ) -> Result<usize, String> {
        let d = self.nt + 1;
        let im = self.implicit.as_mut().expect("an implicit method");
        let it = im
            .solver
            .solve(
                &self.law,
                &im.weights,
                &im.q_n,
                &im.q_t,
                masked.then_some(&im.active[..]),
                &mut im.mu,
                LCP_MAX_ITER,
                LCP_TOL,
            )
            .map_err(|e| e.to_string())?;
        self.tally.add_stages(im.solver.stages().columns());
        let n = y.len();
        for (k, (&mk, &col)) in im.mu.iter().zip(&im.cols).enumerate() {
            if mk != 0.0 {
                let f = c * mk;
                for (yi, zi) in y.iter_mut().zip(&im.fac.z[col * n..(col + 1) * n]) {
                    *yi += f * zi;
                }
                im.rows.add(k, f, sd);
            }
        }
        for (l, m) in normal.iter_mut().zip(im.mu.iter().step_by(d)) {
            *l = *m;
        }
        Ok(it)
    }

    /// The step's forces f = `s`·μ (s: μ's force, module header).
    pub(super) fn take_forces(&mut self, s: f64) {
        let im = self.implicit.as_ref().expect("an implicit method");
        for (f, m) in self.forces.iter_mut().zip(&im.mu) {
            *f = s * m;
        }
    }

    /// y += s·f_tⁿ at the tangential rows (generalized-α's history term κ_f Cᵀrⁿ, whose
    /// normal part the frictionless code adds); `forces` still holds the previous step's.
    pub(super) fn add_previous_tangential(&self, s: f64, y: &mut [f64]) {
        let d = self.nt + 1;
        for (j, f) in self.forces.chunks_exact(d).enumerate() {
            for (k, fk) in f[1..].iter().enumerate() {
                self.trows.add(j * self.nt + k, s * fk, y);
            }
        }
    }

    /// Kinematic friction (module header): with the normal impulses' forces in `forces`, the
    /// tangential force of each node that stops its slip increment, projected onto the disc
    /// of radius b, applied to u_t and v_t^{n+½}. `diag` is the lumped mass. One body's unit
    /// rows only (central difference is refused between two bodies at plan time): each row's
    /// dof is its tangential dof.
    pub(super) fn kinematic(&mut self, u: &mut [f64], v: &mut [f64], diag: &[f64], tau: f64) {
        let (nt, d) = (self.nt, self.nt + 1);
        let t2 = tau * tau;
        debug_assert!(self.trows.is_unit());
        let (tdofs, _) = self.trows.all();
        for (j, f) in self.forces.chunks_exact_mut(d).enumerate() {
            let ts = &tdofs[j * nt..(j + 1) * nt];
            let prev = &self.u_t_prev[j * nt..(j + 1) * nt];
            let (fn_j, ft) = f.split_first_mut().expect("d ≥ 2");
            if *fn_j <= 0.0 {
                ft.iter_mut().for_each(|x| *x = 0.0);
                continue;
            }
            let b = self.law.bound(*fn_j, self.weight[j]);
            let mut norm2 = 0.0;
            for ((fk, &r), p) in ft.iter_mut().zip(ts).zip(prev) {
                *fk = -diag[r] * (u[r] - p) / t2;
                norm2 += *fk * *fk;
            }
            let norm = norm2.sqrt();
            // Stick inside the disc (the slip increment is cancelled exactly: u_t = u_tⁿ),
            // slide on its boundary along the stick force.
            let stick = norm <= b;
            for ((fk, &r), p) in ft.iter_mut().zip(ts).zip(prev) {
                if stick {
                    u[r] = *p;
                } else {
                    *fk *= b / norm;
                    u[r] += t2 * *fk / diag[r];
                }
                v[r] += tau * *fk / diag[r];
            }
        }
    }

    /// The step's bookkeeping once u^{n+1} and the forces are known (the tally: W_f, stick
    /// and slip, the apparent friction coefficient, the step's tangential work).
    pub(super) fn end(&mut self, u: &[f64]) {
        for (j, (du, p)) in self.du_t.iter_mut().zip(&self.u_t_prev).enumerate() {
            *du = self.trows.dot(j, u) - p;
        }
        self.tally.step(&self.forces, &self.du_t);
    }

    /// The series' friction values: the total e_1 contact force, the Γ_C mean of v_1 (the
    /// nodes' trapezoidal weights), W_f.
    pub(super) fn series(&self, v: &[f64]) -> [f64; 3] {
        let v_t = (0..self.trows.len())
            .step_by(self.nt)
            .zip(&self.mean_weight)
            .map(|(j, w)| w * self.trows.dot(j, v))
            .sum();
        [self.tally.total_tangential()[0], v_t, self.tally.work()]
    }

    /// After observing step `step` with energy E: E + W_f and the mean e_1 velocity (the
    /// stop time) into the tally.
    pub(super) fn observed(&mut self, step: usize, tau: f64, energy: f64, mv: &[f64]) {
        self.tally.energy(energy);
        let mut means = [0.0; 3];
        self.mean.means_into(mv, &mut means);
        self.tally.velocity(step as f64 * tau, means[0]);
    }

    /// The friction columns of contract §5 (energies over `scale`): the tally's, and the mean
    /// velocities at T (3D: the tangential norm).
    pub(super) fn report(&self, metrics: &mut Metrics, mv: &[f64], scale: f64) {
        let mut means = [0.0; 3];
        self.mean.means_into(mv, &mut means);
        self.tally
            .finish(metrics, scale, self.mean.tangential(&means), means[2]);
    }
}
