//! The Newmark family, the θ-scheme and the hybrid midpoint scheme ([`Stepper`]): one run between
//! its set-up and its outcome, split around its one linear solve so lockstep groups
//! ([`super::lockstep`]) can share the solve and every other read of a shared operator.
//!
//! Totals or increments. The Newmark step solves A u^{n+1} = M pⁿ + cτ²(F + Cᵀf^{n+1}),
//! A = M + cτ²K. Its round-off is relative to what it solves for: a body that travels (the
//! sliding block, u ≈ V·t ≫ the step's Vτ) loses ~ε‖A‖‖uⁿ‖ of momentum per step, a random walk
//! whose steps grow with the distance travelled (contract §1.8's invariant of the block with a
//! massless Γ_C drifted 5.2e-10·mV over 736 steps; issue 42). Solved for the increment,
//!   A (u^{n+1} − uⁿ) = M(pⁿ − uⁿ) + cτ²(F − K uⁿ + Cᵀf^{n+1}),  pⁿ − uⁿ = τvⁿ + c₁τ²aⁿ,
//! the same equation in exact arithmetic, the round-off is relative to the increment (the
//! invariant then holds to 5.8e-12·mV), at one more product with K per step (K uⁿ from the
//! stored uⁿ, so no residual accumulates: the massless rows' K u^{n+1} = F + f^{n+1} is imposed
//! afresh every step). The mixed runs that start quasi-static ([`super::start`], new in issue
//! 42 with their own ids) step in increments, and so does every two-body run (issue 44, their
//! own ids: two blocks that travel lost 1e-11 of their momentum over 150 steps in totals; not
//! yet with Nitsche/penalty friction, whose tangential start x0 reads the total u) —
//! `mixed` and `penalty`, the hybrid midpoint rule included (A Δ = τMvⁿ − τ²/2 K_Θuⁿ + …), the
//! contact problems reading their gaps at uⁿ + Δ (B(uⁿ + y) + g; the penalty's P uⁿ + P y);
//! the one-body runs keep the totals and their numbers bit for bit.

use std::sync::Arc;
use std::time::Instant;

use super::bodies::{MomentumTally, patch_stress_error};
use super::config::{CLOCK_EVERY, FeConfig, LCP_MAX_ITER, LCP_TOL};
use super::factor::{Factored, FrictionFactor, factor_failure};
use super::geometry::{FeMesh, Geometry, lowest_contact, mean_velocity};
use super::load::gravity_load;
use super::nitsche::{
    FrictionState, NEWTON_MAX_ITER, NewtonWork, NitscheOps, newton, newton_friction,
};
use super::products::dot;
use super::reference::{RefMap, reference_record};
use super::refine::{Refinement, refinement};
use super::setup::{
    checked_geometry, contact_gaps, failed, free_fall, initial_metrics, initial_velocity,
    momentum_tally, observer, reference_map, shared_factor,
};
use super::start::{start_failure, start_state};
use crate::contact::friction::FrictionLaw;
use crate::contact::{FrictionalContact, Lcp};
use crate::run::friction_tally::{FrictionTally, MeanVelocity};
use crate::run::observe::{Divergence, Observer, SampledTimer, StepValues};
use crate::run::reference::ReferenceData;
use crate::run::{Metrics, Outcome, RunContext, RunOptions, Status, Stop};
use crate::space::fe::SymMatrix;
use crate::space::step_solver::StepWork;
use crate::time::Scheme;

/// One run of the engine between its setup and its outcome: the shared operators, the run's own
/// workspace, observer and counters. A step is split around its one linear solve —
/// [`Stepper::prepare`] writes the right-hand side into the member's column y of the group's
/// block, the solve replaces it by A⁻¹y, [`Stepper::contact`], [`Stepper::accelerate`] and
/// [`Stepper::end_step`] do the contact and the updates — so runs sharing A can make their
/// solves together ([`super::lockstep`]), and also their other reads of shared operators: u^{n+1} =
/// y + cτ²Zλ and the products with M and K. A run alone is a group of one.
pub(super) struct Stepper<'a> {
    pub(super) cfg: &'a FeConfig,
    pub(super) opts: &'a RunOptions,
    pub(super) geo: Arc<Geometry>,
    pub(super) fac: Arc<Factored>,
    pub(super) refmap: Option<RefMap>,
    pub(super) metrics: Metrics,
    pub(super) start: Instant,
    pub(super) loop_start: Instant,
    // The scheme: p^n = u + τv + c₁τ²a, γ, cτ²; the θ-midpoint (hybrid) has its own update.
    pub(super) tau: f64,
    pub(super) c1: f64,
    pub(super) gamma: f64,
    pub(super) c_tau2: f64,
    pub(super) hybrid: bool,
    /// f = −gravity (downward acceleration), F = M f e_d its load.
    pub(super) fall: f64,
    pub(super) force_vec: Vec<f64>,
    pub(super) vertical_mass: f64,
    pub(super) energy_scale: Option<f64>,
    /// Gap of each contact dof, and the Γ_C node nearest the plane (disc/ball).
    pub(super) gaps: Vec<f64>,
    pub(super) lowest: Option<usize>,
    // State and workspace (module header: M u, M v, M a carried along).
    pub(super) u: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) a: Vec<f64>,
    pub(super) mu: Vec<f64>,
    pub(super) mv: Vec<f64>,
    pub(super) ma: Vec<f64>,
    pub(super) pred: Vec<f64>,
    /// K u^n (hybrid and Nitsche/penalty: the midpoint's right-hand side and the energy's
    /// uᵀKu), made by the group with K read once for all members; empty otherwise.
    pub(super) ku: Vec<f64>,
    /// vᵀMv and uᵀMa of the state just made, summed by the pass that made it (Newmark/θ's
    /// [`Stepper::end_step`]) so the observation does not stream the vectors again; taken by
    /// [`Stepper::observe`].
    pub(super) sums: Option<(f64, f64)>,
    pub(super) tmp: Vec<f64>,
    pub(super) err: Vec<f64>,
    pub(super) q: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    pub(super) lcp: Lcp,
    pub(super) newton_work: NewtonWork,
    /// Friction with Nitsche/penalty (contract §2.5): u_t^n, the previous forces, the tally.
    pub(super) friction: Option<FrictionState>,
    /// Newton's kinks: the gaps (Newmark/θ), or shifted per step (hybrid).
    pub(super) kink: Vec<f64>,
    pub(super) newton_max: usize,
    pub(super) iterations: i64,
    pub(super) work: StepWork,
    pub(super) record: Option<(Vec<Option<usize>>, ReferenceData)>,
    pub(super) obs: Observer,
    pub(super) observe_timer: SampledTimer,
    /// Centre of mass against free fall until the first contact (scenes with gravity).
    pub(super) fall_error: f64,
    pub(super) touched: bool,
    pub(super) done: usize,
    /// Mixed with friction: the frictional contact problem in place of the LCP, and the
    /// friction observables. `lambda` then holds the normal forces, then the tangential ones
    /// (Z's column order, [`FrictionFactor`]).
    pub(super) fric: Option<Box<FrictionStep>>,
    /// Whether the step solves for the increment u^{n+1} − u^n (module header): the mixed runs
    /// that start quasi-static.
    pub(super) incr: bool,
    /// Two bodies: the momentum and the bodies' mean velocities (contract §5).
    pub(super) momentum: Option<MomentumTally>,
    /// Two bodies with `mixed`: the refinement of the condensed step ([`Refinement`]).
    pub(super) refine: Option<Box<Refinement>>,
}

/// A frictional mixed run's contact workspace and tally (contract §2.5, §1.8).
pub(super) struct FrictionStep {
    pub(super) solver: FrictionalContact,
    pub(super) law: FrictionLaw,
    /// Tresca's node weights w_i = ∫_ΓC φ_i.
    pub(super) weights: Vec<f64>,
    /// The free gaps and slip increments of the step, and the forces (node-major
    /// [f_n, f_t…], the solver's warm start).
    pub(super) q_n: Vec<f64>,
    pub(super) q_t: Vec<f64>,
    pub(super) forces: Vec<f64>,
    /// u_t^n at the Γ_C nodes' tangential dofs, then Δu_t.
    pub(super) ut_prev: Vec<f64>,
    pub(super) du_t: Vec<f64>,
    pub(super) tally: FrictionTally,
    /// The body's mean velocities 1ᵀMv/1ᵀM1 per axis from the carried M v.
    pub(super) mean: MeanVelocity,
    /// The last mean velocities (e_1, e_2, e_d).
    pub(super) mean_v: [f64; 3],
}

/// Friction with Nitsche/penalty (contract §2.5): the frictional state of the points, started
/// from M v⁰, with f̄_t's weight `gamma` of f_t^{n+1}; None without friction rows.
fn nitsche_friction(
    nit: Option<&NitscheOps>,
    cfg: &FeConfig,
    g: &Geometry,
    m: &SymMatrix,
    gamma: f64,
    mv: &[f64],
) -> Option<FrictionState> {
    match nit {
        Some(o) if o.friction.is_some() => {
            let mut f =
                FrictionState::new(o, cfg.friction, mean_velocity(g, m), gamma, cfg.setup.h);
            f.start(mv);
            Some(f)
        }
        _ => None,
    }
}

impl FrictionStep {
    /// The workspace of a frictional mixed run: the frictional contact problem on the
    /// factor's W, Tresca's node weights, and the tally with f̄'s weight `gamma`.
    fn new(
        g: &Geometry,
        cfg: &FeConfig,
        mass: &SymMatrix,
        ff: &FrictionFactor,
        gamma: f64,
    ) -> FrictionStep {
        let d = g.mesh.dim();
        let m = g.contact.len();
        FrictionStep {
            solver: FrictionalContact::new(m, d, ff.w.clone()),
            law: cfg.friction,
            weights: g
                .contact_weight
                .iter()
                .map(|w| w * g.contact_measure)
                .collect(),
            q_n: vec![0.0; m],
            q_t: vec![0.0; ff.tangential.len()],
            forces: vec![0.0; m * d],
            ut_prev: vec![0.0; ff.tangential.len()],
            du_t: vec![0.0; ff.tangential.len()],
            // f̄ = (1 − γ) fⁿ + γ f^{n+1}: Newmark's γ, the θ-scheme's θ.
            tally: FrictionTally::new(m, d, cfg.setup.h, gamma),
            mean: mean_velocity(g, mass),
            mean_v: [0.0; 3],
        }
    }
}

/// The contact forces of the quasi-static start ([`super::start::Start::forces`]) into the run's
/// λ (mixed: the normal forces, then with friction the tangential ones, Z's column order;
/// Nitsche/penalty: the points' unknowns as they are) and, with friction, the tallies' f_t⁰
/// (f̄_t of the first step) and the mixed solver's warm start.
fn start_forces(
    g: &Geometry,
    mixed: bool,
    forces: &[f64],
    lambda: &mut [f64],
    (fric, nitsche_friction): (Option<&mut FrictionStep>, Option<&mut FrictionState>),
) {
    let (nc, d) = (g.contact.len(), g.mesh.dim());
    if mixed {
        for i in 0..nc {
            lambda[i] = forces[i * d];
            if lambda.len() == nc * d {
                for c in 1..d {
                    lambda[nc + i * (d - 1) + c - 1] = forces[i * d + c];
                }
            }
        }
    } else {
        lambda.copy_from_slice(forces);
    }
    if let Some(fr) = fric {
        fr.forces.copy_from_slice(forces);
        fr.tally.start_forces(forces);
    }
    if let Some(fr) = nitsche_friction {
        fr.start_forces(forces);
    }
}

impl<'a> Stepper<'a> {
    /// The setup: operators and factor from the shared caches, the reference map, the workspace
    /// and the initial state. A run that cannot start is returned as its outcome.
    pub(super) fn new(
        cfg: &'a FeConfig,
        opts: &'a RunOptions,
        ctx: &RunContext,
    ) -> Result<Stepper<'a>, Box<Outcome>> {
        let start = Instant::now();
        let mut metrics = initial_metrics(cfg);
        let fail = |status, msg: String, metrics: Metrics| Box::new(failed(status, msg, metrics));
        let (c1, c, gamma) = match cfg.coefficients() {
            Ok(x) => x,
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
        };
        let tau = cfg.dt;
        let c_tau2 = c * tau * tau;
        let geo = match checked_geometry(cfg, opts, start) {
            Ok(g) => g,
            Err((status, msg)) => return Err(fail(status, msg, metrics)),
        };
        let fac = match shared_factor(&geo, cfg, c_tau2, &mut metrics) {
            Ok(f) => f,
            Err(e) => return Err(fail(factor_failure(&e), e, metrics)),
        };
        if let Some((status, msg)) = opts.setup_stop(start, "the factorisation") {
            return Err(fail(status, msg, metrics));
        }
        let refmap = match reference_map(&geo, cfg, ctx) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(m) => m,
        };
        let g = &*geo;
        let n = g.dofs.n_free();
        let nit = fac.nitsche.as_ref();
        // Contact unknowns: the Γ_C nodes' vertical dofs (mixed) or Nitsche's points.
        let nc = nit.map_or(g.contact.len(), NitscheOps::unknowns);
        metrics.contact_dofs = Some(nc as i64);
        let gaps = contact_gaps(g, cfg);
        // Workspace: every vector of the time loop, allocated once. M u, M v and M a are
        // carried along the recursions of u, v, a, so a step costs one product with M (M a^{n+1})
        // besides the solve: M p^n = Mu + τ Mv + c₁τ² Ma, and the energy needs no product at
        // all, uᵀKu = uᵀ(F + Bᵀλ − M a) by the equation at t^{n+1}.
        let mut v = vec![0.0; n];
        let mut a = vec![0.0; n];
        let mut mv = vec![0.0; n];
        let mut ma = vec![0.0; n];
        let lcp = Lcp::new_or_idle(g.contact.len(), nit.is_none().then_some(fac.h.as_slice()));
        let newton_work =
            match NewtonWork::for_run(nit.filter(|_| fac.condensed), fac.schur.as_ref()) {
                Ok(w) => w,
                Err(e) => return Err(fail(Status::SolverFailed, e, metrics)),
            };
        let kink: Vec<f64> = nit.map_or(Vec::new(), |o| o.gap.clone());
        let work: StepWork = fac.chol.work();
        initial_velocity(g, cfg, &mut v);
        fac.m.matvec_into(&v, &mut mv);
        // f̄_t's weight of f_t^{n+1}: Newmark's γ, the θ-scheme's θ.
        let mut friction = nitsche_friction(nit, cfg, g, &fac.m, gamma, &mv);
        // Gravity (contract §1.3, [`super::load::gravity_load`]): F and a⁰ with M a⁰ = F on the dofs with
        // inertia (u⁰ = 0); M a⁰ is carried as `ma`. The bars have no load (F = 0). Loaded
        // massless dofs then start quasi-static ([`super::start`]).
        let fall = free_fall(cfg);
        let (force_vec, vertical_mass, energy_scale) = match gravity_load(g, cfg, &fac.m) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(None) => (vec![0.0; n], 0.0, None),
            Ok(Some(load)) => {
                a.copy_from_slice(&load.a0);
                fac.m.matvec_into(&a, &mut ma);
                (load.force, load.vertical_mass, Some(load.energy_scale))
            }
        };
        // Frictional: the tangential forces after the normal ones (Z's columns).
        let mut lambda = vec![0.0; nc * fac.friction.as_ref().map_or(1, |_| g.mesh.dim())];
        let mut fric = fac
            .friction
            .as_ref()
            .map(|ff| Box::new(FrictionStep::new(g, cfg, &fac.m, ff, gamma)));
        let (u, mu, forces) =
            match start_state(g, cfg, &fac.m, nit, &force_vec, &gaps, &v, &mut a, &mut ma) {
                Err(e) => return Err(fail(start_failure(&e), e, metrics)),
                Ok(s) => s,
            };
        let incr =
            (forces.is_some() && nit.is_none()) || (g.bodies.is_some() && friction.is_none());
        if let Some(f) = forces {
            let fr = (fric.as_deref_mut(), friction.as_mut());
            start_forces(g, nit.is_none(), &f, &mut lambda, fr);
        }
        // The reference lattice this run records, if it is one.
        let record = match reference_record(g, cfg, ctx) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(r) => r,
        };
        if let Some((status, msg)) = opts.setup_stop(start, "the workspace") {
            return Err(fail(status, msg, metrics));
        }
        let hybrid = matches!(cfg.scheme, Scheme::Hybrid);
        let needs_ku = hybrid || nit.is_some() || incr;
        let obs = observer(cfg, opts, energy_scale);
        metrics.setup_time_s = Some(start.elapsed().as_secs_f64());
        Ok(Stepper {
            cfg,
            opts,
            refmap,
            metrics,
            start,
            loop_start: Instant::now(),
            tau,
            c1,
            gamma,
            c_tau2,
            hybrid,
            fall,
            momentum: momentum_tally(g, cfg, &fac.m, &force_vec),
            force_vec,
            vertical_mass,
            energy_scale,
            gaps,
            lowest: lowest_contact(g),
            u,
            v,
            a,
            mu,
            mv,
            ma,
            pred: vec![0.0; n],
            ku: vec![0.0; if needs_ku { n } else { 0 }],
            sums: None,
            tmp: vec![0.0; n],
            err: vec![0.0; n],
            q: vec![0.0; nc],
            lambda,
            lcp,
            newton_work,
            friction,
            kink,
            newton_max: 0,
            iterations: 0,
            work,
            record,
            obs,
            observe_timer: SampledTimer::default(),
            fall_error: 0.0,
            touched: false,
            done: 0,
            fric,
            refine: refinement(g, cfg, &fac, n, nc),
            geo,
            fac,
            incr,
        })
    }

    /// Observe step n with the current state (u, v) and contact forces λ (contract §1.3).
    pub(super) fn observe(&mut self, step: usize) -> Result<(), Divergence> {
        let Stepper {
            geo,
            fac,
            refmap,
            tau,
            fall,
            force_vec,
            vertical_mass,
            gaps,
            lowest,
            u,
            v,
            mu,
            mv,
            ma,
            ku,
            sums,
            tmp,
            err,
            lambda,
            record,
            obs,
            fall_error,
            touched,
            fric,
            momentum,
            ..
        } = self;
        let (g, nit, tau, fall) = (&**geo, fac.nitsche.as_ref(), *tau, *fall);
        // E = ½vᵀMv + ½uᵀKu − Fᵀu with Mv carried and Ku = F + Bᵀλ − Ma (module header).
        // Nitsche: the equation involves K_Θ and the nonlinear term, so uᵀKu is taken from the
        // product K u the group made for the step ([`Stepper::k_pair`]). Without a load, Fᵀu
        // is 0 and not summed.
        let carried = sums.take();
        let kinetic: f64 = carried.map_or_else(|| dot(v, mv), |c| c.0);
        // A load: gravity, or the two blocks' pressure (contract §1.10).
        let loaded = fall != 0.0 || g.bodies.as_ref().is_some_and(|b| b.pressure.is_some());
        let fu: f64 = if loaded { dot(u, force_vec) } else { 0.0 };
        let uku = if nit.is_some() {
            dot(u, ku)
        } else {
            let contact: f64 = (0..g.rows.len())
                .zip(lambda.iter())
                .map(|(i, l)| l * g.rows.dot(i, u))
                .sum();
            let uma: f64 = carried.map_or_else(|| dot(u, ma), |c| c.1);
            match (fric.as_ref(), fac.friction.as_ref()) {
                // With friction Cᵀf has tangential rows too: uᵀKu = uᵀ(F + Cᵀf − Ma).
                (Some(_), Some(ff)) => {
                    let nc = g.contact.len();
                    let tangential: f64 = (0..ff.tangential.len())
                        .zip(&lambda[nc..])
                        .map(|(j, l)| l * ff.tangential.dot(j, u))
                        .sum();
                    fu + (contact + tangential) - uma
                }
                _ => fu + contact - uma,
            }
        };
        let [kinetic, elastic, gravity] = [0.5 * kinetic, 0.5 * uku, -fu];
        let e = kinetic + elastic + gravity;
        // Penetration at the Γ_C nodes, (u_n − g)_+ with u_n = −u_d (contract §1.3 decisions): the
        // points where the mixed method enforces the constraint, and where Nitsche/penalty
        // are measured too (their quadrature points carry only a weak constraint).
        let penetration = g.rows.penetration(gaps, u);
        // Nitsche: E_Θ and the total force from u itself (contract §2.3); mixed: Σ λ.
        // Penalty: its potential is part of E^h (contract §2.4), and there is no E_Θ.
        let (e, theta_term, force) = match nit {
            Some(ops) => {
                let (pot, t, f) = ops.energy_terms_and_force(u);
                (e + pot, t, f)
            }
            // The normal forces (frictional runs hold the tangential ones after them).
            None => (e, None, lambda[..g.contact.len()].iter().sum()),
        };
        let mean = |x: &[f64]| -> f64 {
            g.contact
                .iter()
                .zip(&g.contact_weight)
                .map(|(&c, w)| w * x[c])
                .sum()
        };
        let uc = mean(u);
        if let (Some(mt), Some(two)) = (momentum.as_mut(), g.bodies.as_ref()) {
            // The series' Pⁿ and Γ^b's mean e_d displacement (u_contact's convention).
            let p = mt.observe(two, &g.vertical, mv, step as f64 * tau);
            obs.set_two_body(g.rows.second_mean(&g.contact_weight, u), p);
        }
        if let (Some(fr), Some(ff)) = (fric.as_mut(), fac.friction.as_ref()) {
            // The body's mean velocities 1ᵀMv/1ᵀM1 per axis from the carried M v; the stop
            // time and E + W_f in the tally; the series' Σf_t along e_1, the Γ_C mean of v_1
            // and W_f (contract §5).
            fr.mean.means_into(mv, &mut fr.mean_v);
            fr.tally.energy(e);
            fr.tally.velocity(step as f64 * tau, fr.mean_v[0]);
            let t = ff.tangential.len() / g.contact.len();
            let v1: f64 = g
                .contact_weight
                .iter()
                .enumerate()
                .map(|(i, w)| w * ff.tangential.dot(i * t, v))
                .sum();
            obs.set_friction(fr.tally.total_tangential()[0], v1, fr.tally.work());
        }
        if fall != 0.0 && !*touched {
            if force > 0.0 {
                *touched = true;
            } else {
                let t = step as f64 * tau;
                let com: f64 = g.vertical.iter().map(|&r| mu[r]).sum::<f64>() / *vertical_mass;
                *fall_error = fall_error.max((com - 0.5 * fall * t * t).abs());
            }
        }
        if let Some((slots, data)) = record.as_mut()
            && step.is_multiple_of(data.time_stride)
        {
            data.u.extend(slots.iter().map(|s| s.map_or(0.0, |r| u[r])));
            data.force.push(force);
            data.energy.push(e);
            data.u_contact.push(uc);
        }
        let exact = refmap.as_ref().map(|rm| rm.compare(g, step, u, err, tmp));
        obs.observe(
            StepValues {
                step,
                t: step as f64 * tau,
                u_contact: uc,
                v_contact: mean(v),
                sigma_contact: -force,
                sigma_mid: None,
                energy: e,
                energy_theta: theta_term.map(|t| e + t),
                energy_kinetic: Some(kinetic),
                energy_elastic: Some(elastic),
                energy_gravity: (fall != 0.0).then_some(gravity),
                u_lowest: lowest.map(|c| u[c]),
                penetration: Some(penetration),
            },
            exact,
        )
    }

    /// The right-hand side of step n into `y` (the member's column of the group's block, solved
    /// in place with A).
    pub(super) fn prepare(&mut self, y: &mut [f64]) {
        let n = y.len();
        let (tau, c_tau2) = (self.tau, self.c_tau2);
        if self.hybrid && self.incr {
            // Midpoint rule in increments: (M + τ²/4 K_Θ)Δ = τMv − τ²/2 K_Θ u + τ²/2 F − τ²/2 N_Φ,
            // the total form below less A uⁿ (the same equation; round-off relative to Δ).
            let kt = if self.k_theta_u() {
                &self.tmp
            } else {
                &self.ku
            };
            let (mv, f, kt) = (&self.mv[..n], &self.force_vec[..n], &kt[..n]);
            for i in 0..n {
                y[i] = tau * mv[i] - 2.0 * c_tau2 * kt[i] + 2.0 * c_tau2 * f[i];
            }
        } else if self.hybrid {
            // Midpoint rule: (M + τ²/4 K_Θ) u^{n+1} = M(u + τv) − τ²/4 K_Θ u + τ²/2 F − τ²/2 N_Φ
            // (nitsche.rs header), K_Θ u = K u − Θ Σ w γ s (s·u); K u is the group's product.
            let kt = if self.k_theta_u() {
                &self.tmp
            } else {
                &self.ku
            };
            let (mu, mv, f, kt) = (&self.mu[..n], &self.mv[..n], &self.force_vec[..n], &kt[..n]);
            for i in 0..n {
                y[i] = mu[i] + tau * mv[i] - c_tau2 * kt[i] + 2.0 * c_tau2 * f[i];
            }
        } else if self.incr {
            // The increment's right-hand side (module header): M(pⁿ − uⁿ) + cτ²(F − K_Θ uⁿ),
            // p − u = τv + c₁τ²a into `pred`, M(p − u) from the carried products, K uⁿ the
            // group's (K_Θ uⁿ with Nitsche's Θ-term, into `tmp`, which the step overwrites
            // only after the solve).
            let ct2 = self.c1 * tau * tau;
            let ku = if self.k_theta_u() {
                &self.tmp
            } else {
                &self.ku
            };
            let (v, a, mv, ma) = (&self.v[..n], &self.a[..n], &self.mv[..n], &self.ma[..n]);
            let (ku, f) = (&ku[..n], &self.force_vec[..n]);
            let (pred, mu) = (&mut self.pred[..n], &mut self.mu[..n]);
            for i in 0..n {
                pred[i] = tau * v[i] + ct2 * a[i];
                let dm = tau * mv[i] + ct2 * ma[i];
                y[i] = dm + c_tau2 * (f[i] - ku[i]);
                mu[i] += dm;
            }
        } else {
            // p^n and M p^n (the right-hand side) from the carried products. M p^n is
            // M u^{n+1} before the correction by a^{n+1}: kept in `mu`. Then + cτ²F. (Slices cut
            // to n: the loop runs without bounds checks.)
            let ct2 = self.c1 * tau * tau;
            let (u, v, a) = (&self.u[..n], &self.v[..n], &self.a[..n]);
            let (mv, ma) = (&self.mv[..n], &self.ma[..n]);
            let (pred, mu) = (&mut self.pred[..n], &mut self.mu[..n]);
            for i in 0..n {
                pred[i] = u[i] + tau * v[i] + ct2 * a[i];
                let mp = mu[i] + tau * mv[i] + ct2 * ma[i];
                y[i] = mp;
                mu[i] = mp;
            }
            // The load: gravity, or the two blocks' pressure (contract §1.10).
            let pressed = self
                .geo
                .bodies
                .as_ref()
                .is_some_and(|b| b.pressure.is_some());
            if self.fall != 0.0 || pressed {
                for (yi, fi) in y.iter_mut().zip(&self.force_vec) {
                    *yi += c_tau2 * fi;
                }
            }
        }
        if let Some(rf) = self.refine.as_mut() {
            rf.keep_rhs(y);
        }
    }

    /// K_Θ uⁿ = K uⁿ − Θ Σ w γ s (s·uⁿ) (nitsche.rs header): the group's K uⁿ itself without
    /// a Θ-term (mixed, penalty; returns false), else made in `tmp` (returns true).
    fn k_theta_u(&mut self) -> bool {
        match self.fac.nitsche.as_ref() {
            Some(ops) if ops.theta != 0.0 => {
                let tmp = &mut self.tmp;
                tmp.copy_from_slice(&self.ku);
                for k in 0..ops.len() {
                    let f = ops.theta * ops.w[k] * ops.gamma[k] * ops.apply(&ops.s, k, &self.u);
                    for (&gd, &sk) in ops.dofs[k * ops.k..(k + 1) * ops.k]
                        .iter()
                        .zip(&ops.s[k * ops.k..(k + 1) * ops.k])
                    {
                        tmp[gd] -= f * sk;
                    }
                }
                true
            }
            _ => false,
        }
    }

    /// Two bodies with `mixed`: refine u^{n+1} = `y` and λ on the full residual
    /// ([`Refinement`]; stepping in increments, `y` is u^{n+1} − uⁿ and the rows' gaps are
    /// read at uⁿ + y); nothing for the other runs.
    pub(super) fn refine(&mut self, step: usize, y: &mut [f64]) -> Result<(), Stop<String>> {
        if let Some(rf) = self.refine.as_mut() {
            let before = rf.full_iterations;
            let (g, fac) = (&*self.geo, &*self.fac);
            let lambda = &mut self.lambda;
            let base = self.incr.then_some(self.u.as_slice());
            let (c_tau2, work) = (self.c_tau2, &mut self.work);
            let full = match fac.nitsche.as_ref() {
                Some(ops) => rf.refine_penalty(g, fac, ops, c_tau2, base, lambda, y, work),
                None => rf
                    .refine(g, fac, c_tau2, &self.gaps, base, lambda, y, work)
                    .map(|()| false),
            }
            .map_err(|e| Stop::Solver(step, e))?;
            if full {
                // The condensed Newton's iterate is not this step's: the next starts cold.
                self.newton_work.restart();
                let it = rf.full_iterations - before;
                self.newton_max = self.newton_max.max(it);
                self.iterations += it as i64;
            }
        }
        Ok(())
    }

    /// The patch test's errors (contract §1.10), with `pressure`: the largest relative stress
    /// error over the Gauss points and the largest relative contact pressure error over the
    /// rows (a multiplier over its node's weight ∫φ_i; the penalty's κ[δ_i − g_i]_+; Nitsche's
    /// (1/γ^i)[P^i_γ − g]_+ at the points of every side with w_i > 0).
    fn patch_errors(&self) -> Option<(f64, f64)> {
        let (Some(two), FeMesh::Bodies { mesh, .. }) = (&self.geo.bodies, &self.geo.mesh) else {
            return None;
        };
        two.pressure.as_ref()?;
        let (g, p, u) = (&*self.geo, two.pressure_value, &self.u);
        let stress = patch_stress_error(mesh, &g.dofs, two, u, p);
        let worst =
            |it: &mut dyn Iterator<Item = f64>| it.fold(0.0f64, |m, ph| m.max((ph - p).abs() / p));
        let pressure = match self.fac.nitsche.as_ref() {
            Some(ops) => worst(
                &mut (0..ops.len())
                    .map(|q| (ops.apply(&ops.p, q, u) - ops.gap[q]).max(0.0) / ops.gamma[q]),
            ),
            None => worst(
                &mut (0..g.rows.len())
                    .map(|i| self.lambda[i] / (g.contact_weight[i] * g.contact_measure)),
            ),
        };
        Some((stress, pressure))
    }

    /// Step n's contact problem once `y` = A⁻¹(right-hand side): the forces λ (upward) from
    /// the exact LCP (mixed) or Newton (Nitsche/penalty). u^{n+1} = y + cτ² Z λ is then made by
    /// the group ([`super::lockstep`]), which reads each column of Z once for all its members.
    pub(super) fn contact(&mut self, step: usize, y: &[f64]) -> Result<(), Stop<String>> {
        let c_tau2 = self.c_tau2;
        let fac = &*self.fac;
        if let (Some(ops), Some(fr)) = (fac.nitsche.as_ref(), self.friction.as_mut()) {
            // x0 = P y (+ k u_t^n), then the frictional Newton (nitsche.rs header); λ holds the
            // previous step's forces, its warm start.
            if self.hybrid {
                return Err(Stop::Solver(
                    step,
                    "friction is not defined for the hybrid scheme".into(),
                ));
            }
            fr.start_step(ops, y, &self.u, &mut self.q);
            let it = newton_friction(
                ops,
                fr.law,
                &fac.h,
                c_tau2,
                &self.q,
                &mut self.lambda,
                &mut fr.slides,
                &mut self.newton_work,
            )
            .map_err(|e| Stop::Solver(step, e))?;
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        } else if fac.nitsche.is_some() && !fac.condensed {
            // Without W the refinement's full-system Newton solves the step from y
            // (`run::fe::full_newton`); λ is set there.
        } else if let Some(ops) = fac.nitsche.as_ref() {
            // s0 = P y, then Newton for s and φ(s) (the upward forces, into λ). Stepping in
            // increments, y is u^{n+1} − uⁿ without contact: s0 = P uⁿ + P y.
            for (k, qk) in self.q.iter_mut().enumerate() {
                *qk = if self.incr {
                    ops.apply(&ops.p, k, &self.u) + ops.apply(&ops.p, k, y)
                } else {
                    ops.apply(&ops.p, k, y)
                };
            }
            if self.hybrid {
                // Kinks g − max(P̃ⁿ, 0) from u^n (nitsche.rs header).
                for (k, kk) in self.kink.iter_mut().enumerate() {
                    let pn = ops.apply(&ops.p, k, &self.u) - ops.gap[k];
                    *kk = ops.gap[k] - pn.max(0.0);
                }
            }
            let solved = newton(
                ops,
                &fac.h,
                c_tau2,
                &self.q,
                &self.kink,
                &mut self.lambda,
                &mut self.newton_work,
            );
            let it = match solved {
                Ok(it) => it,
                // Two bodies: the refinement's full-system Newton solves the step from the
                // contact-free y (`run::fe::full_newton`), where W's lost digits stall this one.
                Err(_) if self.refine.is_some() => {
                    self.lambda.fill(0.0);
                    NEWTON_MAX_ITER
                }
                Err(e) => return Err(Stop::Solver(step, e)),
            };
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        } else if let (Some(fr), Some(ff)) = (self.fric.as_mut(), fac.friction.as_ref()) {
            // q_n = y_d + gap, q_t = y_t − u_t^n (the contact-free step's slip increment);
            // u^{n+1} = y + cτ²Z f over the normal and tangential columns ([`super::lockstep`]).
            // Stepping in increments, y is y − uⁿ: q_n = (uⁿ_d + y_d) + gap, q_t = y_t.
            let g = &*self.geo;
            let (incr, u) = (self.incr, &self.u);
            for (j, (qi, gi)) in fr.q_n.iter_mut().zip(&self.gaps).enumerate() {
                *qi = if incr {
                    g.rows.dot_sum(j, u, y)
                } else {
                    g.rows.dot(j, y)
                } + gi;
            }
            // Two bodies: the relative slip's rows ([`FrictionFactor::tangential`]).
            for (j, (qt, up)) in fr.q_t.iter_mut().zip(&mut fr.ut_prev).enumerate() {
                *up = ff.tangential.dot(j, u);
                *qt = if incr {
                    ff.tangential.dot(j, y)
                } else {
                    ff.tangential.dot(j, y) - *up
                };
            }
            let it = fr
                .solver
                .solve(
                    &fr.law,
                    &fr.weights,
                    &fr.q_n,
                    &fr.q_t,
                    None,
                    &mut fr.forces,
                    LCP_MAX_ITER,
                    LCP_TOL,
                )
                .map_err(|e| Stop::Solver(step, e.to_string()))?;
            fr.tally.add_stages(fr.solver.stages().columns());
            let (nc, d) = (g.contact.len(), g.mesh.dim());
            for i in 0..nc {
                self.lambda[i] = fr.forces[i * d];
                for c in 1..d {
                    self.lambda[nc + i * (d - 1) + c - 1] = fr.forces[i * d + c];
                }
            }
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        } else {
            let g = &*self.geo;
            let (incr, u) = (self.incr, &self.u);
            for (j, (qi, gi)) in self.q.iter_mut().zip(&self.gaps).enumerate() {
                *qi = if incr {
                    g.rows.dot_sum(j, u, y)
                } else {
                    g.rows.dot(j, y)
                } + gi;
            }
            let it = self
                .lcp
                .solve(&self.q, &mut self.lambda, LCP_MAX_ITER, LCP_TOL)
                .map_err(|e| Stop::Solver(step, e.to_string()))?;
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        }
        Ok(())
    }

    /// With `y` = u^{n+1} (or u^{n+1} − uⁿ, [`Stepper::incr`]): the acceleration a^{n+1} = (u^{n+1} − p^n)/(cτ²) into `tmp`
    /// (Newmark/θ), or v^{n+1} = 2(u^{n+1} − u^n)/τ − v^n (hybrid); then u ← u^{n+1}, in the
    /// same pass. The products with M (and K) that follow are the group's
    /// ([`Stepper::mass_pairs`], [`Stepper::k_pair`]).
    pub(super) fn accelerate(&mut self, y: &[f64]) {
        let (tau, c_tau2) = (self.tau, self.c_tau2);
        let n = y.len();
        let u = &mut self.u[..n];
        if self.hybrid && self.incr {
            let v = &mut self.v[..n];
            for i in 0..n {
                v[i] = 2.0 * y[i] / tau - v[i];
                u[i] += y[i];
            }
        } else if self.hybrid {
            let v = &mut self.v[..n];
            for i in 0..n {
                v[i] = 2.0 * (y[i] - u[i]) / tau - v[i];
                u[i] = y[i];
            }
        } else {
            // Stepping in increments, y and p are u^{n+1} − uⁿ and pⁿ − uⁿ.
            let (t, p) = (&mut self.tmp[..n], &self.pred[..n]);
            if self.incr {
                for i in 0..n {
                    t[i] = (y[i] - p[i]) / c_tau2;
                    u[i] += y[i];
                }
            } else {
                for i in 0..n {
                    t[i] = (y[i] - p[i]) / c_tau2;
                    u[i] = y[i];
                }
            }
        }
    }

    /// The products with M of this step, as (x, M x) pairs: M a^{n+1} into `pred` (Newmark/θ),
    /// or M u and M v (hybrid, whose u and v are not carried through recursions).
    pub(super) fn mass_pairs(&mut self) -> [Option<(&[f64], &mut [f64])>; 2] {
        if self.hybrid {
            [
                Some((self.u.as_slice(), self.mu.as_mut_slice())),
                Some((self.v.as_slice(), self.mv.as_mut_slice())),
            ]
        } else {
            [Some((self.tmp.as_slice(), self.pred.as_mut_slice())), None]
        }
    }

    /// The product K u with the current u, as an (x, K x) pair, for the runs that need it
    /// (hybrid: the next right-hand side; Nitsche/penalty: the energy's uᵀKu); one product
    /// serves both, where each used to make its own.
    pub(super) fn k_pair(&mut self) -> Option<(&[f64], &mut [f64])> {
        (!self.ku.is_empty()).then_some((self.u.as_slice(), self.ku.as_mut_slice()))
    }

    /// The end of step n after the products with M: v, M v, M u and a (Newmark/θ), the
    /// observation, the clock. The same pass sums vᵀMv and uᵀMa for the observation (in the
    /// order of [`dot`]: the same numbers).
    pub(super) fn end_step(&mut self, step: usize) -> Result<(), Stop<String>> {
        if !self.hybrid {
            let (tau, gamma, c_tau2) = (self.tau, self.gamma, self.c_tau2);
            let n = self.u.len();
            let (a, an, ma, man) = (&self.a[..n], &self.tmp[..n], &self.ma[..n], &self.pred[..n]);
            let (v, mv, mu) = (&mut self.v[..n], &mut self.mv[..n], &mut self.mu[..n]);
            let u = &self.u[..n];
            let (mut kinetic, mut uma) = (-0.0, -0.0);
            for i in 0..n {
                v[i] += tau * ((1.0 - gamma) * a[i] + gamma * an[i]);
                mv[i] += tau * ((1.0 - gamma) * ma[i] + gamma * man[i]);
                mu[i] += c_tau2 * man[i];
                kinetic += v[i] * mv[i];
                uma += u[i] * man[i];
            }
            self.sums = Some((kinetic, uma));
            std::mem::swap(&mut self.a, &mut self.tmp);
            std::mem::swap(&mut self.ma, &mut self.pred);
        }
        if let (Some(fr), Some(ff)) = (self.fric.as_mut(), self.fac.friction.as_ref()) {
            for (j, (du, up)) in fr.du_t.iter_mut().zip(&fr.ut_prev).enumerate() {
                *du = ff.tangential.dot(j, &self.u) - up;
            }
            fr.tally.step(&fr.forces, &fr.du_t);
        }
        if let (Some(fr), Some(ops)) = (self.friction.as_mut(), self.fac.nitsche.as_ref()) {
            let t = step as f64 * self.tau;
            let (ft, vt, wf) = fr.after_step(ops, &self.u, &self.v, &self.mv, &self.lambda, t);
            self.obs.set_friction(ft, vt, wf);
        }
        let e_prev = self.obs.last_energy();
        let mut timer = self.observe_timer;
        let r = timer.time(step, || self.observe(step));
        self.observe_timer = timer;
        r.map_err(Stop::Diverged)?;
        if let Some(fr) = self.friction.as_mut() {
            fr.balance(e_prev, self.obs.last_energy());
        }
        self.done = step;
        self.opts.step_stop(step, CLOCK_EVERY, self.start)
    }

    /// The outcome of the run, however its loop ended.
    pub(super) fn finish(mut self, stop: Result<(), Stop<String>>) -> Outcome {
        let cfg = self.cfg;
        let patch = self.patch_errors();
        let metrics = &mut self.metrics;
        metrics.steps = self.done as i64;
        metrics.iterations = self.iterations;
        metrics.iterations_max_step = Some(self.newton_max as i64);
        if !self.fac.chol.is_factored() {
            metrics.solver_iterations = Some(self.work.iterations_total() as i64);
            metrics.solver_iterations_max_step = Some(self.work.iterations_max() as i64);
        }
        metrics.stepping_time_s = Some(self.loop_start.elapsed().as_secs_f64());
        metrics.observe_time_s = self.observe_timer.estimate_s();
        let (status, message) = Stop::status(stop, self.tau, cfg.steps, self.start, metrics);
        self.obs.finish(metrics, status == Status::Ok);
        // Two bodies: the momentum's P⁰ + tF is their free-fall check (the centre of mass moves
        // with the initial velocities too).
        let falls = self.fall != 0.0 && self.geo.bodies.is_none();
        metrics.free_fall_error = falls.then_some(self.fall_error);
        // The observer's pressure columns are the total force here; there is no midpoint
        // pressure.
        metrics.err_force_l2 = metrics.err_sigma_l2.take();
        metrics.err_sigma_mid_l2 = None;
        metrics.contact_toggles = Some(metrics.contact_switches);
        metrics.energy_scale = self.energy_scale.or(metrics.energy_initial);
        if let Some(mt) = &self.momentum {
            mt.finish(metrics);
        }
        if let Some((s, p)) = patch {
            metrics.patch_stress_error = Some(s);
            metrics.patch_pressure_error = Some(p);
        }
        if let Some(fr) = self.fric.as_ref() {
            // contract §5: the e_1 component in 2D, the tangential norm in 3D.
            let vt = fr.mean.tangential(&fr.mean_v);
            let scale = metrics.energy_scale.unwrap_or(1.0);
            fr.tally.finish(metrics, scale, vt, fr.mean_v[2]);
        }
        if let Some(fr) = &self.friction {
            let scale = metrics.energy_scale.filter(|s| *s != 0.0).unwrap_or(1.0);
            fr.finish(metrics, scale, self.newton_work.stage_columns());
        }
        let reference = match self.record {
            Some((_, data)) if status == Status::Ok => Some(data),
            _ => None,
        };
        Outcome {
            status,
            message,
            metrics: self.metrics,
            series: std::mem::take(&mut self.obs.series),
            reference,
        }
    }
}
