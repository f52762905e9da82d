//! One run of a contract §3.2 method between its set-up and its outcome ([`MethodRun`]): the
//! shared operators (the step factor of M + cK, or the explicit step's lumped M alone; the
//! predictor's M⁻¹Bᵀ), the state (u, v, a) with the carried products Mu, Mv, Ma, Ku, Kv, the
//! contact and friction workspaces, the observer. Each method's step is its own file of this
//! folder, on this state; the loop is [`super::driver`].

use std::sync::Arc;
use std::time::Instant;

use super::friction::Friction;
use super::gradient_newton::GradientWork;
use super::mass_inverse::{MASS_INVERSES, MassInverse, mass_inverse};
use super::state::{Method, REFRESH, method, step_coefficient};
use crate::contact::Lcp;
use crate::run::fe::bodies::MomentumTally;
use crate::run::fe::cache::geometry_key;
use crate::run::fe::cfl::kinematic_dt_limit;
use crate::run::fe::config::{FeConfig, frictional};
use crate::run::fe::factor::{Factored, factor_failure};
use crate::run::fe::geometry::{Geometry, lowest_contact, mean_velocity};
use crate::run::fe::load::gravity_load;
use crate::run::fe::mass::mass_matrix;
use crate::run::fe::nitsche::{FrictionState, NewtonWork, NitscheOps};
use crate::run::fe::reference::{RefMap, reference_record};
use crate::run::fe::setup::{
    checked_geometry, contact_gaps, failed, free_fall, initial_metrics, initial_velocity,
    momentum_tally, observer, reference_map, shared_factor,
};
use crate::run::fe::start::{start_failure, start_state};
use crate::run::observe::{Divergence, Observer, SampledTimer, StepValues};
use crate::run::reference::ReferenceData;
use crate::run::{Metrics, Outcome, RunContext, RunOptions, Status, Stop};
use crate::space::fe::SymMatrix;
use crate::space::step_solver::StepWork;

/// The operators of a run: geometry, the step factor (None: the explicit step) or the lumped
/// mass the explicit step owns, and contact-stabilized Newmark's M⁻¹Bᵀ.
type Operators = (
    Arc<Geometry>,
    Option<Arc<Factored>>,
    Option<SymMatrix>,
    Option<Arc<MassInverse>>,
);

/// A run of a contract §3.2 method: its operators, state, carried products, workspace and
/// observer (module header). Nothing is allocated in the time loop.
pub(super) struct MethodRun<'a> {
    pub(super) cfg: &'a FeConfig,
    pub(super) opts: &'a RunOptions,
    pub(super) meth: Method,
    pub(super) tau: f64,
    /// c of the step matrix M + cK (None: the explicit kinematic step has none).
    pub(super) c: Option<f64>,
    pub(super) geo: Arc<Geometry>,
    pub(super) fac: Option<Arc<Factored>>,
    /// The explicit step's lumped M (the factor keeps M otherwise).
    pub(super) own_mass: Option<SymMatrix>,
    pub(super) minv: Option<Arc<MassInverse>>,
    pub(super) refmap: Option<RefMap>,
    pub(super) metrics: Metrics,
    pub(super) start: Instant,
    pub(super) loop_start: Instant,
    pub(super) gaps: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) a: Vec<f64>,
    pub(super) mu: Vec<f64>,
    pub(super) mv: Vec<f64>,
    pub(super) ma: Vec<f64>,
    pub(super) ku: Vec<f64>,
    /// K v (CSN, Moreau–Jean), K Δ, and the step's right-hand side A Δ (or A u^{n+1}): the
    /// products a step carries instead of recomputing them (module header).
    pub(super) kv: Vec<f64>,
    pub(super) kd: Vec<f64>,
    pub(super) sd: Vec<f64>,
    pub(super) y: Vec<f64>,
    pub(super) pred: Vec<f64>,
    pub(super) tmp: Vec<f64>,
    pub(super) err: Vec<f64>,
    pub(super) q: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    pub(super) lambda_prev: Vec<f64>,
    pub(super) nu: Vec<f64>,
    pub(super) rows: Vec<bool>,
    pub(super) lcp: Lcp,
    pub(super) lcp_pred: Option<Lcp>,
    pub(super) grad_work: GradientWork,
    pub(super) newton_work: NewtonWork,
    pub(super) work: Option<StepWork>,
    pub(super) diag: Vec<f64>,
    /// Friction with Nitsche/penalty (generalized-α/HHT only; module header): the engine's
    /// frictional state, f̄_t's weight of f_t^{n+1} 1 − α_f.
    pub(super) nit_fric: Option<FrictionState>,
    /// Friction with the nodal multiplier (module header).
    pub(super) fric: Option<Friction>,
    /// Dofs without inertia (mod1/…/zero-contact with kane): their velocity is Δu/τ.
    pub(super) massless: Vec<usize>,
    pub(super) fall: f64,
    pub(super) force_vec: Vec<f64>,
    pub(super) m_ed: Vec<f64>,
    pub(super) vertical_mass: f64,
    pub(super) energy_scale: Option<f64>,
    pub(super) record: Option<(Vec<Option<usize>>, ReferenceData)>,
    pub(super) obs: Observer,
    pub(super) lowest: Option<usize>,
    pub(super) fall_error: f64,
    pub(super) touched: bool,
    pub(super) done: usize,
    pub(super) iterations: i64,
    pub(super) newton_max: usize,
    pub(super) observe_timer: SampledTimer,
    /// E of the last observed step (the frictional Nitsche/penalty run's E + W_f balance).
    pub(super) e_last: f64,
    /// Two bodies: the momentum and the bodies' mean velocities (contract §5).
    pub(super) momentum: Option<MomentumTally>,
}

/// The initial motion of a run: v⁰ (and M v⁰), and under gravity a⁰ with M a⁰ = F on the dofs
/// with inertia (and M a⁰) with the load (F, M e_d, the vertical mass, the energy scale).
struct Motion {
    v: Vec<f64>,
    a: Vec<f64>,
    mv: Vec<f64>,
    ma: Vec<f64>,
    load: (Vec<f64>, Vec<f64>, f64, Option<f64>),
}

/// Gravity as in the engine ([`crate::run::fe::load::gravity_load`]): F, and a⁰ with
/// M a⁰ = F − Ku⁰ on the dofs with inertia (u⁰ = 0, no contact at t = 0), the start of
/// generalized-α and of central difference; loaded massless dofs are then started
/// quasi-static by the caller.
fn initial_motion(g: &Geometry, cfg: &FeConfig, m: &SymMatrix) -> Result<Motion, String> {
    let n = g.dofs.n_free();
    let mut v = vec![0.0; n];
    let mut a = vec![0.0; n];
    let mut mv = vec![0.0; n];
    let mut ma = vec![0.0; n];
    initial_velocity(g, cfg, &mut v);
    let load = match gravity_load(g, cfg, m)? {
        None => (vec![0.0; n], vec![0.0; n], 0.0, None),
        Some(load) => {
            a.copy_from_slice(&load.a0);
            m.matvec_into(&a, &mut ma);
            let scale = Some(load.energy_scale);
            (load.force, load.m_ed, load.vertical_mass, scale)
        }
    };
    m.matvec_into(&v, &mut mv);
    Ok(Motion { v, a, mv, ma, load })
}

impl<'a> MethodRun<'a> {
    /// The set-up: operators and factor from the shared caches, the reference map, the
    /// workspace and the initial state. A run that cannot start is returned as its outcome.
    pub(super) fn new(
        cfg: &'a FeConfig,
        opts: &'a RunOptions,
        ctx: &RunContext,
    ) -> Result<MethodRun<'a>, Box<Outcome>> {
        let start = Instant::now();
        let mut metrics = initial_metrics(cfg);
        let fail = |status, msg: String, metrics: Metrics| Box::new(failed(status, msg, metrics));
        let meth = match method(cfg) {
            Ok(m) => m,
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
        };
        let tau = cfg.dt;
        let c = step_coefficient(meth, tau);
        let (geo, fac, own_mass, minv) = match operators(cfg, opts, start, meth, &mut metrics) {
            Ok(x) => x,
            Err((status, msg)) => return Err(fail(status, msg, metrics)),
        };
        let refmap = match reference_map(&geo, cfg, ctx) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(m) => m,
        };
        let g = &*geo;
        // The factor keeps M; the explicit step owns its lumped M.
        let m: &SymMatrix = match (&fac, &own_mass) {
            (Some(f), _) => &f.m,
            (None, Some(m)) => m,
            (None, None) => unreachable!("one of the two is built above"),
        };
        let n = g.dofs.n_free();
        let nit = fac.as_ref().and_then(|f| f.nitsche.as_ref());
        // Contact unknowns: the Γ_C nodes (mixed) or the points' values (d per point with
        // friction).
        let nc = nit.map_or(g.rows.len(), NitscheOps::unknowns);
        metrics.contact_dofs = Some(nc as i64);
        let gaps = contact_gaps(g, cfg);
        let mixed_h = fac
            .as_ref()
            .filter(|_| nit.is_none())
            .map(|f| f.h.as_slice());
        let lcp = Lcp::new_or_idle(g.rows.len(), mixed_h);
        let lcp_pred = minv
            .as_ref()
            .map(|mi| Lcp::new(g.rows.len(), mi.wm.clone()));
        let schur = fac.as_ref().and_then(|f| f.schur.as_ref());
        let newton_work = match NewtonWork::for_run(nit, schur) {
            Ok(w) => w,
            Err(e) => return Err(fail(Status::SolverFailed, e, metrics)),
        };
        let diag = m.diagonal();
        let (nit_fric, fric) = match friction_parts(cfg, meth, g, fac.as_ref(), m, c) {
            Ok(x) => x,
            Err((status, msg)) => return Err(fail(status, msg, metrics)),
        };
        let fall = free_fall(cfg);
        let Motion {
            v,
            mut a,
            mv,
            mut ma,
            load,
        } = match initial_motion(g, cfg, m) {
            Ok(x) => x,
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
        };
        let (force_vec, m_ed, vertical_mass, energy_scale) = load;
        // Loaded massless dofs (kane, discrete-gradient with mod1/…/zero-contact) start
        // quasi-static ([`crate::run::fe::start`]); λ holds the nodal normal forces of that
        // start (the force observed at t = 0).
        let mut lambda = vec![0.0; nc];
        let (u, mu) = match start_state(g, cfg, m, nit, &force_vec, &gaps, &v, &mut a, &mut ma) {
            Err(e) => return Err(fail(start_failure(&e), e, metrics)),
            Ok((u, mu, forces)) => {
                if let (Some(f), None) = (forces, nit) {
                    let normal = f.iter().step_by(g.mesh.dim());
                    lambda.iter_mut().zip(normal).for_each(|(l, x)| *l = *x);
                }
                (u, mu)
            }
        };
        let record = match reference_record(g, cfg, ctx) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(r) => r,
        };
        if let Some((status, msg)) = opts.setup_stop(start, "the workspace") {
            return Err(fail(status, msg, metrics));
        }
        let momentum = momentum_tally(g, cfg, m, &force_vec);
        metrics.setup_time_s = Some(start.elapsed().as_secs_f64());
        Ok(MethodRun {
            cfg,
            opts,
            meth,
            tau,
            c,
            refmap,
            metrics,
            start,
            loop_start: Instant::now(),
            gaps,
            u,
            v,
            a,
            mu,
            mv,
            ma,
            ku: vec![0.0; n],
            kv: vec![0.0; n],
            kd: vec![0.0; n],
            sd: vec![0.0; n],
            y: vec![0.0; n],
            pred: vec![0.0; n],
            tmp: vec![0.0; n],
            err: vec![0.0; n],
            q: vec![0.0; nc],
            lambda,
            lambda_prev: vec![0.0; nc],
            nu: vec![0.0; g.contact.len()],
            rows: vec![false; g.contact.len()],
            lcp,
            lcp_pred,
            grad_work: GradientWork::new(nit.map_or(0, NitscheOps::len)),
            newton_work,
            work: fac.as_ref().map(|f| f.chol.work()),
            massless: (0..n).filter(|&i| diag[i] == 0.0).collect(),
            diag,
            nit_fric,
            fric,
            fall,
            force_vec,
            m_ed,
            vertical_mass,
            energy_scale,
            record,
            obs: observer(cfg, opts, energy_scale),
            lowest: lowest_contact(g),
            fall_error: 0.0,
            touched: false,
            done: 0,
            iterations: 0,
            newton_max: 0,
            observe_timer: SampledTimer::default(),
            e_last: 0.0,
            momentum,
            own_mass,
            minv,
            fac,
            geo,
        })
    }

    /// Observe step n: state (u, v) with the products Mv, Ku and the step's total contact
    /// force; the energy E of the step.
    pub(super) fn observe(
        &mut self,
        step: usize,
        force: f64,
        friction: Option<[f64; 3]>,
    ) -> Result<f64, Divergence> {
        let MethodRun {
            tau,
            geo,
            fac,
            refmap,
            gaps,
            u,
            v,
            mv,
            ku,
            tmp,
            err,
            fall,
            force_vec,
            m_ed,
            vertical_mass,
            record,
            obs,
            lowest,
            fall_error,
            touched,
            momentum,
            ..
        } = self;
        let (tau, fall, vertical_mass) = (*tau, *fall, *vertical_mass);
        let g = &**geo;
        let nit = fac.as_ref().and_then(|f| f.nitsche.as_ref());
        let (u, v): (&[f64], &[f64]) = (u, v);
        let kinetic = 0.5 * v.iter().zip(mv.iter()).map(|(x, y)| x * y).sum::<f64>();
        let elastic = 0.5 * u.iter().zip(ku.iter()).map(|(x, y)| x * y).sum::<f64>();
        let gravity = -u
            .iter()
            .zip(force_vec.iter())
            .map(|(x, y)| x * y)
            .sum::<f64>();
        let penetration = g.rows.penetration(gaps, u);
        let (e, theta_term) = match nit {
            Some(ops) => {
                let (pot, t, _) = ops.energy_terms_and_force(u);
                (kinetic + elastic + gravity + pot, t)
            }
            None => (kinetic + elastic + gravity, None),
        };
        let uc = contact_mean(g, u);
        if let (Some(mt), Some(two)) = (momentum.as_mut(), g.bodies.as_ref()) {
            // The series' Pⁿ and Γ^b's mean e_d displacement, as the Newmark/θ loop writes them.
            let p = mt.observe(two, &g.vertical, mv, step as f64 * tau);
            obs.set_two_body(g.rows.second_mean(&g.contact_weight, u), p);
        }
        if fall != 0.0 && !*touched {
            if force > 0.0 {
                *touched = true;
            } else {
                let t = step as f64 * tau;
                // e_dᵀ M u / e_dᵀ M e_d.
                let com: f64 =
                    m_ed.iter().zip(u.iter()).map(|(x, y)| x * y).sum::<f64>() / vertical_mass;
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
        if let Some([sigma_t, v_t, work]) = friction {
            obs.set_friction(sigma_t, v_t, work);
        }
        obs.observe(
            StepValues {
                step,
                t: step as f64 * tau,
                u_contact: uc,
                v_contact: contact_mean(g, v),
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
        .map(|()| e)
    }

    /// The carried products drift by round-off (and would hide a step that does not solve its
    /// equation): every REFRESH steps they are recomputed from the state, so a discrepancy
    /// shows as an energy jump the per-step energy checks see.
    pub(super) fn refresh(&mut self, step: usize) {
        if step.is_multiple_of(REFRESH) && !matches!(self.meth, Method::Kinematic) {
            let MethodRun {
                geo,
                fac,
                own_mass,
                meth,
                u,
                v,
                mu,
                mv,
                ku,
                kv,
                ..
            } = self;
            let m: &SymMatrix = match (&*fac, &*own_mass) {
                (Some(f), _) => &f.m,
                (None, Some(m)) => m,
                (None, None) => unreachable!("one of the two is built at set-up"),
            };
            let g = &**geo;
            m.matvec_into(v, mv);
            g.k.matvec_into(u, ku);
            match meth {
                Method::Csn | Method::MoreauJean(_) => g.k.matvec_into(v, kv),
                Method::Alpha(_) => m.matvec_into(u, mu),
                _ => {}
            }
        }
    }

    /// The outcome: the loop's counters, status and message, the observer's and the
    /// friction's metrics, the recorded reference of a finished run.
    pub(super) fn finish(mut self, stop: Result<(), Stop<String>>) -> Outcome {
        let MethodRun {
            cfg,
            tau,
            metrics,
            fac,
            work,
            start,
            loop_start,
            obs,
            fall,
            fall_error,
            energy_scale,
            fric,
            nit_fric,
            mv,
            record,
            done,
            iterations,
            newton_max,
            observe_timer,
            momentum,
            newton_work,
            ..
        } = &mut self;
        metrics.steps = *done as i64;
        metrics.iterations = *iterations;
        metrics.iterations_max_step = Some(*newton_max as i64);
        if let (Some(f), Some(w)) = (&*fac, &*work)
            && !f.chol.is_factored()
        {
            metrics.solver_iterations = Some(w.iterations_total() as i64);
            metrics.solver_iterations_max_step = Some(w.iterations_max() as i64);
        }
        metrics.stepping_time_s = Some(loop_start.elapsed().as_secs_f64());
        metrics.observe_time_s = observe_timer.estimate_s();
        let (status, message) = Stop::status(stop, *tau, cfg.steps, *start, metrics);
        obs.finish(metrics, status == Status::Ok);
        // Two bodies: P⁰ + tF is their free-fall check (newmark.rs's).
        let falls = *fall != 0.0 && momentum.is_none();
        metrics.free_fall_error = falls.then_some(*fall_error);
        metrics.err_force_l2 = metrics.err_sigma_l2.take();
        metrics.err_sigma_mid_l2 = None;
        metrics.contact_toggles = Some(metrics.contact_switches);
        metrics.energy_scale = energy_scale.or(metrics.energy_initial);
        if let Some(mt) = &*momentum {
            mt.finish(metrics);
        }
        if let (Some(fr), Some(scale)) = (&*fric, metrics.energy_scale) {
            fr.report(metrics, mv, scale);
        }
        if let Some(st) = &*nit_fric {
            // As the engine's frictional Nitsche/penalty runs ([`crate::run::fe::newmark`]).
            let scale = metrics.energy_scale.filter(|s| *s != 0.0).unwrap_or(1.0);
            st.finish(metrics, scale, newton_work.stage_columns());
        }
        let reference = match record.take() {
            Some((_, data)) if status == Status::Ok => Some(data),
            _ => None,
        };
        Outcome {
            status,
            message,
            metrics: std::mem::take(metrics),
            series: std::mem::take(&mut obs.series),
            reference,
        }
    }
}

/// The Γ_C mean of a nodal field (trapezoidal weights of the nodes' vertical dofs).
fn contact_mean(g: &Geometry, x: &[f64]) -> f64 {
    g.contact
        .iter()
        .zip(&g.contact_weight)
        .map(|(&c, w)| w * x[c])
        .sum()
}

/// The geometry, the step factor (the engine's cache, the engine's key) or, for the explicit
/// step, the lumped mass alone, and contact-stabilized Newmark's M⁻¹Bᵀ; the set-up
/// checkpoints after the mesh and after the factorisation.
fn operators(
    cfg: &FeConfig,
    opts: &RunOptions,
    start: Instant,
    meth: Method,
    metrics: &mut Metrics,
) -> Result<Operators, (Status, String)> {
    let tau = cfg.dt;
    let geo = checked_geometry(cfg, opts, start)?;
    let g = &*geo;
    let c = step_coefficient(meth, tau);
    let (fac, own_mass): (Option<Arc<Factored>>, Option<SymMatrix>) = match c {
        // The engine's key: with friction the factor carries the tangential columns (not the
        // frictionless entry), and the solver is part of it (a `cg` entry holds A itself, not
        // its factor: a direct and a cg run must not share it).
        Some(c) => match shared_factor(g, cfg, c, metrics) {
            Ok(f) => (Some(f), None),
            Err(e) => return Err((factor_failure(&e), e)),
        },
        // The kinematic impulses act row by row: exact when no dof is in two rows (the
        // node-to-node rows of a matching interface; other pairings share Γ^b's nodes).
        // Friction on two bodies' relative slip has no kinematic step yet.
        None if !g.rows.is_unit() && (!g.rows.disjoint() || frictional(cfg)) => {
            return Err((
                Status::Invalid,
                "kinematic central difference on two bodies takes frictionless node-to-node rows on a matching interface (rows sharing a node, and friction, have no kinematic impulse yet)".into(),
            ));
        }
        None => match kinematic_dt_limit(cfg) {
            Err((_, e)) => return Err((Status::Invalid, e)),
            Ok(limit) if tau > limit * (1.0 + 1e-12) => {
                return Err((
                    Status::Invalid,
                    format!(
                        "dt = {tau:.6e} is above the CFL limit {limit:.6e} of kinematic central difference"
                    ),
                ));
            }
            Ok(_) => match mass_matrix(g, &cfg.setup, &cfg.mass) {
                Ok((m, total)) => {
                    metrics.mass_total = Some(total);
                    metrics.factorizations = 0;
                    (None, Some(m))
                }
                Err(e) => return Err((Status::Invalid, e)),
            },
        },
    };
    let m: &SymMatrix = match (&fac, &own_mass) {
        (Some(f), _) => &f.m,
        (None, Some(m)) => m,
        (None, None) => unreachable!("one of the two is built above"),
    };
    let minv = match meth {
        Method::Csn => {
            let key = format!("{}|{:?}|mass-inverse", geometry_key(&cfg.setup), cfg.mass);
            let (mi, hit) = MASS_INVERSES.get(key, || mass_inverse(g, m));
            // The Cholesky of M counts as a factorisation of this run when it built it.
            metrics.factorizations += i64::from(!hit);
            match mi {
                Ok(x) => Some(x),
                Err(e) => return Err((Status::SolverFailed, e)),
            }
        }
        _ => None,
    };
    if let Some(stop) = opts.setup_stop(start, "the factorisation") {
        return Err(stop);
    }
    Ok((geo, fac, own_mass, minv))
}

/// The run's friction (module header): with Nitsche/penalty generalized-α's frictional state
/// (f̄_t's weight of f_t^{n+1} 1 − α_f; the other methods have no frictional version there),
/// with the nodal multiplier the condensed frictional problem with the method's force per
/// unknown (f̄_t's weight: generalized-α's 1 − α_f, the other methods' force of the step
/// itself).
fn friction_parts(
    cfg: &FeConfig,
    meth: Method,
    g: &Geometry,
    fac: Option<&Arc<Factored>>,
    m: &SymMatrix,
    c: Option<f64>,
) -> Result<(Option<FrictionState>, Option<Friction>), (Status, String)> {
    let tau = cfg.dt;
    let nit = fac.and_then(|f| f.nitsche.as_ref());
    let nit_fric = match (nit, meth) {
        (Some(o), Method::Alpha(p)) if o.friction.is_some() => Some(FrictionState::new(
            o,
            cfg.friction,
            mean_velocity(g, m),
            1.0 - p.alpha_f,
            cfg.setup.h,
        )),
        (Some(o), _) if o.friction.is_some() => {
            return Err((
                Status::Invalid,
                format!(
                    "scheme {} has no frictional version with space = {} (contract §2.5)",
                    cfg.scheme.label(),
                    cfg.method.name()
                ),
            ));
        }
        _ => None,
    };
    if !(frictional(cfg) && nit.is_none()) {
        return Ok((nit_fric, None));
    }
    let weight_new = match meth {
        Method::Alpha(p) => 1.0 - p.alpha_f,
        _ => 1.0,
    };
    // μ's unit: the force enters the right-hand side as c_f·Cᵀr and the solution is
    // y + cZ̄μ, so r = (c/c_f)μ (module header); Moreau–Jean's impulse p = cμ is the force
    // p/τ.
    let force_per_mu = match (meth, c) {
        (Method::Kinematic, _) => None,
        (Method::Kane | Method::Csn, Some(_)) => Some(0.5),
        (Method::Alpha(_), Some(_)) => Some(1.0),
        (Method::MoreauJean(_), Some(c)) => Some(c / tau),
        _ => {
            return Err((
                Status::Invalid,
                format!(
                    "scheme {} has no frictional version (contract §2.5)",
                    cfg.scheme.label()
                ),
            ));
        }
    };
    let mut fr = Friction::new(g, cfg, m, weight_new).map_err(|e| (Status::Invalid, e))?;
    if let (Some(s), Some(f)) = (force_per_mu, fac)
        && let Err(e) = fr.attach(g, f, s)
    {
        return Err((Status::SolverFailed, e));
    }
    Ok((nit_fric, Some(fr)))
}
