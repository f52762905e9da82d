//! The frictional layer's engine (contract §1.7): two P1 chains on the same nodes, stepped by the
//! 1D engine's schemes, coupled only through the friction law at node 0.
//!
//! The normal chain is the flying bar of §1.4 (modulus λ + 2μ, gap g, velocity −V_n) and its
//! step is exactly the bar's ([`super::bar1d`]'s engine, unchanged: with `friction = "none"`
//! the normal chain's numbers are the flying bar's, bit for bit). The tangential chain
//! (modulus μ, velocity V_t) has no obstacle: its contact node is held by the friction law,
//! whose bound b comes from the normal chain's force of the same step. The chains are
//! decoupled in the bulk and their condensed contact rows are diagonal (w_nt = w_tn = 0), so a
//! step is the normal step, then the tangential step whose scalar problem is the law's exact
//! case analysis ([`crate::contact::friction`]) — the same local solve for every scheme. What
//! the slip is belongs to the scheme (contract §2.5): the increment u₀^{n+1} − u₀ⁿ for the
//! position-level schemes (Newmark, θ, `kane`, generalized-α/HHT,
//! `contact-stabilized-newmark`, GetFEM's choice, b from f_n^{n+1}), v₀^{n+1} with impulses for
//! `moreau-jean` (De Saxcé's take-off / stick / slide; the bound μ_f p_n, Tresca's s·τ), the
//! kinematic impulse of `central-difference` with the lumped mass, and the penalty's
//! f_t = proj_[−b,b](−κ·Δu_t) with the normal κ.
//!
//! Measured per step, besides the bar's observables on both chains (energy ½vᵀMv + ½uᵀKu of
//! both, errors of the 2-vector field against [`LayerExact`]): the frictional work
//! W_f^{n+1} = W_f^n − f̄_t·(u_t,0^{n+1} − u_t,0^n) with f̄_t the tangential force as it enters
//! the scheme's momentum equation over the step, E + W_f, stick and slip, the apparent friction
//! coefficient. Nothing is allocated in the time loop.

use std::time::Instant;

use super::bar1d::{self, Bar1dConfig, Engine, State, Tangential, Work};
use super::grid1d::Grid1d;
use super::observe::{Divergence, ExactValues, Observer, StepValues};
use super::stepping::{failed, finished, time_loop};
use super::{Metrics, Outcome, RunOptions, Status, Stop};
use crate::contact::ContactSolveError;
use crate::contact::friction::FrictionLaw;
use crate::scene::{BarParams, LayerExact, LayerParams};
use crate::space::{Bar1dSpace, ContactInit, ContactMethod, MassVariant};
use crate::time::{NewmarkParams, Scheme};

/// A validated layer1d run.
#[derive(Debug, Clone, PartialEq)]
pub struct Layer1dConfig {
    pub layer: LayerParams,
    /// Both chains' mesh, step and methods (the tangential chain takes the mixed method).
    pub grid: Grid1d,
    /// Ensemble member: relative amplitude of a uniform perturbation of the initial velocities
    /// and its seed (the layer starts unstrained: its displacement is zero).
    pub perturbation: Option<(f64, u64)>,
}

impl Layer1dConfig {
    /// A run of the layer on `grid` — the entry point of tests and benches.
    pub fn new(layer: LayerParams, grid: Grid1d) -> Self {
        Self {
            layer,
            grid,
            perturbation: None,
        }
    }

    /// The normal chain: §1.4's flying bar with the P-wave modulus.
    pub fn normal_chain(&self) -> Bar1dConfig {
        let l = &self.layer;
        self.chain(
            BarParams {
                length: l.height,
                young: l.p_modulus(),
                density: l.density,
                amplitude: 0.0,
                gap: l.gap,
                free_end: true,
                velocity: l.velocity,
            },
            self.grid.method,
        )
    }

    /// The tangential chain: a free bar with the shear modulus whose node 0 is held by
    /// friction (its space is the mixed method's, p = e₀, q = −e₀, no gap: the engine's
    /// scalar s is then u_t,0 itself).
    pub fn tangential_chain(&self) -> Bar1dConfig {
        let l = &self.layer;
        self.chain(
            BarParams {
                length: l.height,
                young: l.lame_mu,
                density: l.density,
                amplitude: 0.0,
                gap: 0.0,
                free_end: true,
                velocity: l.velocity_tangential,
            },
            ContactMethod::Mixed,
        )
    }

    fn chain(&self, bar: BarParams, method: ContactMethod) -> Bar1dConfig {
        Bar1dConfig {
            bar,
            grid: Grid1d {
                method,
                ..self.grid.clone()
            },
            contact_init: ContactInit::Consistent,
            perturbation: self.perturbation,
        }
    }

    /// The largest stable dt of an explicit scheme: the normal chain's (c_p > c_s, and its
    /// contact stiffness is the only one).
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        self.normal_chain().explicit_dt_limit()
    }
}

/// What a frictional run measured besides the bar's metrics (contract §5's friction columns, and
/// the step-wise extremes the property tests look at).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrictionStats {
    /// W_f(T) / energy_scale.
    pub friction_work: f64,
    /// (E^N + W_f^N − E⁰)/energy_scale.
    pub energy_balance_drift: f64,
    /// max_n of the one-step rise of E + W_f, over energy_scale.
    pub energy_balance_max_increase: f64,
    /// Contact node-steps in stick (|Δu_t,0| ≤ 1e-12·h) and in slip.
    pub stick_steps: i64,
    pub slip_steps: i64,
    /// max over the contact steps of |f_t|/f_n.
    pub friction_ratio_max: Option<f64>,
    /// The chains' mean velocities 1ᵀMv/1ᵀM1 at T.
    pub tangential_velocity_final: f64,
    pub normal_velocity_final: f64,
    /// min over the steps of the tangential work −f_t^{n+1}·Δu_t,0, over energy_scale (≥ 0
    /// for the position-level methods, contract §2.5).
    pub tangential_work_min: f64,
    /// l2(τ) error of σ_t at the base, and |v̄_t(T) − exact|.
    pub err_sigma_t_l2: Option<f64>,
    pub err_vt_final: Option<f64>,
}

/// How the tangential force enters the scheme's momentum equation over a step: f̄ = (1 − c)fⁿ
/// + c f^{n+1} (contract §2.5's W_f).
fn work_weight(cfg: &Layer1dConfig) -> f64 {
    match cfg.grid.scheme {
        Scheme::Newmark(NewmarkParams { gamma, .. }) if !is_kinematic(cfg) => gamma,
        Scheme::Theta(th) => th.theta,
        Scheme::GeneralizedAlpha(ga) => 1.0 - ga.alpha_f,
        // kane, contact-stabilized-newmark, moreau-jean, kinematic central difference: the
        // force of the step itself.
        _ => 1.0,
    }
}

/// Central difference with `mixed` and the lumped mass: kinematic contact and friction, an
/// impulse on the half-step velocity (contract §3.2); with the penalty it is a Newmark scheme.
fn is_kinematic(cfg: &Layer1dConfig) -> bool {
    cfg.grid.scheme == Scheme::Newmark(NewmarkParams::central_difference())
        && cfg.grid.method == ContactMethod::Mixed
        && cfg.grid.mass == MassVariant::Lumped
}

/// One chain: its engine, state and work vectors.
struct Chain {
    eng: Engine,
    st: State,
    wk: Work,
}

impl Chain {
    fn new(cfg: &Bar1dConfig, tangential: Option<Tangential>) -> Result<(Chain, f64), String> {
        let sp = Bar1dSpace::new(cfg.bar, cfg.grid.elements, &cfg.grid.mass, cfg.grid.method)
            .map_err(|e| e.to_string())?;
        let mut eng = Engine::new(sp, cfg.grid.scheme, cfg.grid.dt)?;
        eng.tangential = tangential;
        let (st, sigma0) =
            bar1d::initial_state(&eng, cfg).map_err(|e| format!("initial state (t = 0): {e}"))?;
        let m = eng.space().m;
        Ok((
            Chain {
                eng,
                st,
                wk: Work {
                    b: vec![0.0; m],
                    y: vec![0.0; m],
                    pred: vec![0.0; m],
                },
            },
            sigma0,
        ))
    }

    fn energy(&self) -> f64 {
        self.eng.space().energies(&self.st.u, &self.st.v).0
    }
}

/// How often the wall clock is read (as the bar's loop).
const CLOCK_EVERY: usize = 64;

/// Run one layer1d simulation.
pub fn simulate(cfg: &Layer1dConfig, opts: &RunOptions) -> Outcome {
    simulate_with_stats(cfg, opts).0
}

/// Run one layer1d simulation and return its friction measurements too.
pub fn simulate_with_stats(cfg: &Layer1dConfig, opts: &RunOptions) -> (Outcome, FrictionStats) {
    let start = Instant::now();
    let mut metrics = Metrics {
        dofs: 2 * cfg.grid.elements as i64,
        length_scale: Some(cfg.layer.height),
        ..Metrics::default()
    };
    let law = cfg.layer.friction;
    let tau = cfg.grid.dt;
    let (mut normal, sigma0, mut tang) = match chains(cfg) {
        Ok(c) => c,
        Err(e) => {
            return (
                failed(Status::SolverFailed, e, metrics),
                FrictionStats::default(),
            );
        }
    };
    metrics.mass_total = normal.eng.space().mass_total.into();
    metrics.factorizations = 4;
    if let Some((status, msg)) = opts.setup_stop(start, "the operators") {
        return (failed(status, msg, metrics), FrictionStats::default());
    }
    let view = View {
        exact: cfg.layer.exact(),
        tau,
        h: normal.eng.space().h,
        gap: cfg.layer.gap,
    };
    let mut obs = Observer::new(tau, opts.series_every, cfg.grid.steps);
    let e0 = normal.energy() + tang.energy();
    let scale = e0;
    obs = obs.with_energy_scale(scale);
    let mut acc = Account::new(cfg, &view, e0);
    let end = time_loop(
        opts,
        start,
        (CLOCK_EVERY, tau, cfg.grid.steps),
        &mut metrics,
        |clock, metrics| {
            obs.set_friction(0.0, tang.st.v[0], 0.0);
            view.record(&mut obs, 0, &normal, &tang, sigma0)
                .map_err(Stop::Diverged)?;
            for n in 1..=cfg.grid.steps {
                let (sigma_n, sigma_t) = acc.step(n, &mut normal, &mut tang, &view)?;
                metrics.iterations += 1;
                obs.set_friction(sigma_t, tang.st.v[0], acc.work);
                clock.observe(n, || view.record(&mut obs, n, &normal, &tang, sigma_n))?;
                let balance = normal.energy() + tang.energy() + acc.work;
                acc.max_inc = acc.max_inc.max((balance - acc.balance_prev) / scale);
                acc.balance_prev = balance;
                clock.completed(n)?;
            }
            Ok(())
        },
    );
    metrics.iterations += normal.eng.extra_iterations() + tang.eng.extra_iterations();
    obs.finish(&mut metrics, end.status == Status::Ok);
    metrics.energy_scale = Some(scale);
    let stats = acc.stats(end.done, &normal, &tang, &view);
    metrics.exit_velocity = Some(stats.normal_velocity_final);
    metrics.tangential_velocity_final = Some(stats.tangential_velocity_final);
    metrics.normal_velocity_final = Some(stats.normal_velocity_final);
    if end.status == Status::Ok {
        metrics.err_sigma_t_l2 = stats.err_sigma_t_l2;
        metrics.err_vt_final = stats.err_vt_final;
    }
    // The friction columns belong to a friction law (null for `none`, contract §5).
    if !law.is_none() {
        metrics.friction_work = Some(stats.friction_work);
        metrics.energy_balance_drift = Some(stats.energy_balance_drift);
        metrics.energy_balance_max_increase = Some(stats.energy_balance_max_increase);
        metrics.stick_steps = Some(stats.stick_steps);
        metrics.slip_steps = Some(stats.slip_steps);
        metrics.friction_ratio_max = stats.friction_ratio_max;
    }
    (finished(end.status, end.message, metrics, &mut obs), stats)
}

/// The two chains (the normal one with its σ_C⁰): the tangential chain's contact node held by
/// the friction law, with the penalty's tangential stiffness κ = (λ + 2μ)γ0/h.
fn chains(cfg: &Layer1dConfig) -> Result<(Chain, f64, Chain), String> {
    let kappa = match cfg.grid.method {
        ContactMethod::Penalty { gamma0 } => {
            Some(cfg.layer.p_modulus() * gamma0 * cfg.grid.elements as f64 / cfg.layer.height)
        }
        _ => None,
    };
    let normal_cfg = cfg.normal_chain();
    let (normal, sigma0) = Chain::new(&normal_cfg, None)?;
    let tangential_cfg = cfg.tangential_chain();
    let hook = Tangential {
        kappa,
        ..Tangential::default()
    };
    let (tang, _) = Chain::new(&tangential_cfg, Some(hook))?;
    Ok((normal, sigma0, tang))
}

/// What the observation of a step needs besides the chains: the exact solution, τ, h, g.
struct View {
    exact: Option<LayerExact>,
    tau: f64,
    h: f64,
    gap: f64,
}

impl View {
    /// Observe step `step`: the normal chain's contact node and σ_C, the energy of both
    /// chains, the errors of the 2-vector field.
    fn record(
        &self,
        obs: &mut Observer,
        step: usize,
        n: &Chain,
        t: &Chain,
        sigma: f64,
    ) -> Result<(), Divergence> {
        let time = step as f64 * self.tau;
        let energy = n.energy() + t.energy();
        let ex = self.exact.map(|ex| {
            let (l2_sq, h1_semi_sq) = ex.error_sq(&n.st.u, &t.st.u, self.h, time);
            ExactValues {
                u_contact: ex.w(0.0, time),
                sigma_contact: ex.base_sigma_n(time),
                sigma_contact_mid: None,
                energy: ex.energy(time),
                l2_sq,
                h1_semi_sq,
            }
        });
        obs.observe(
            StepValues {
                step,
                t: time,
                u_contact: n.st.u[0],
                v_contact: n.st.v[0],
                sigma_contact: sigma,
                sigma_mid: None,
                energy,
                energy_theta: None,
                energy_kinetic: None,
                energy_elastic: None,
                energy_gravity: None,
                u_lowest: None,
                penetration: Some((-n.st.u[0] - self.gap).max(0.0)),
            },
            ex,
        )
    }
}

/// The frictional accounts of the loop: the tangential force of the state (a force, impulses
/// over τ), W_f, E + W_f and its largest rise, stick and slip, |f_t|/f_n, the σ_t error sum.
struct Account {
    law: FrictionLaw,
    moreau: bool,
    restitution: f64,
    weight: f64,
    scale: f64,
    e0: f64,
    f_t_prev: f64,
    work: f64,
    balance_prev: f64,
    max_inc: f64,
    min_tw: f64,
    sum_st: f64,
    ratio_max: Option<f64>,
    stick_steps: i64,
    slip_steps: i64,
}

impl Account {
    fn new(cfg: &Layer1dConfig, view: &View, e0: f64) -> Account {
        let mut sum_st = 0.0;
        if let Some(ex) = &view.exact {
            // The layer starts with no tangential force: σ_t,h⁰ = 0.
            let d = ex.base_sigma_t(0.0);
            sum_st += d * d;
        }
        Account {
            law: cfg.layer.friction,
            moreau: matches!(cfg.grid.scheme, Scheme::MoreauJean(_)),
            restitution: match cfg.grid.scheme {
                Scheme::MoreauJean(p) => p.restitution,
                _ => 0.0,
            },
            weight: work_weight(cfg),
            scale: e0,
            e0,
            f_t_prev: 0.0,
            work: 0.0,
            balance_prev: e0,
            max_inc: f64::NEG_INFINITY,
            min_tw: f64::INFINITY,
            sum_st,
            ratio_max: None,
            stick_steps: 0,
            slip_steps: 0,
        }
    }

    /// Step `n`: the normal chain, then the tangential chain under the bound of the normal
    /// force of the same step, and the step's friction accounts. Returns (σ_n, σ_t).
    fn step(
        &mut self,
        n: usize,
        normal: &mut Chain,
        tang: &mut Chain,
        view: &View,
    ) -> Result<(f64, f64), Stop<ContactSolveError>> {
        let (tau, h) = (view.tau, view.h);
        let phi_n = normal
            .eng
            .step(&mut normal.st, &mut normal.wk)
            .map_err(|e| Stop::Solver(n, e))?;
        // The normal force on the body (φ q with q = −e₀: f_n = −φ), an impulse for
        // Moreau–Jean; the bound in the same unit (Tresca's s·τ for an impulse).
        let f_n = -phi_n;
        let in_contact = f_n > 0.0;
        let b = if in_contact {
            self.law.bound(f_n, if self.moreau { tau } else { 1.0 })
        } else {
            0.0
        };
        let hook = tang.eng.tangential.as_ref().expect("the tangential chain");
        hook.bound.set(b);
        let u_prev = tang.st.u[0];
        hook.s_ref.set(if self.moreau {
            self.restitution * tang.st.v[0]
        } else {
            u_prev
        });
        let phi_t = tang
            .eng
            .step(&mut tang.st, &mut tang.wk)
            .map_err(|e| Stop::Solver(n, e))?;
        let (f_t, f_n_force) = if self.moreau {
            (-phi_t / tau, f_n / tau)
        } else {
            (-phi_t, f_n)
        };
        let du = tang.st.u[0] - u_prev;
        let fbar = (1.0 - self.weight) * self.f_t_prev + self.weight * f_t;
        self.work -= fbar * du;
        self.f_t_prev = f_t;
        self.min_tw = self.min_tw.min(-f_t * du / self.scale);
        if in_contact {
            if du.abs() <= 1e-12 * h {
                self.stick_steps += 1;
            } else {
                self.slip_steps += 1;
            }
            let r = f_t.abs() / f_n_force;
            self.ratio_max = Some(self.ratio_max.map_or(r, |x: f64| x.max(r)));
        }
        let sigma_n = normal.eng.sigma(&normal.st.u, phi_n);
        let sigma_t = tang.eng.sigma(&tang.st.u, phi_t);
        let time = n as f64 * tau;
        if let Some(ex) = &view.exact {
            let d = sigma_t - ex.base_sigma_t(time);
            self.sum_st += d * d;
        }
        Ok((sigma_n, sigma_t))
    }

    /// The run's friction measurements after `done` steps.
    fn stats(&self, done: usize, normal: &Chain, tang: &Chain, view: &View) -> FrictionStats {
        let tau = view.tau;
        let scale = self.scale;
        let t_end = done as f64 * tau;
        let mut stats = FrictionStats {
            stick_steps: self.stick_steps,
            slip_steps: self.slip_steps,
            ..FrictionStats::default()
        };
        stats.friction_work = self.work / scale;
        stats.energy_balance_drift = (self.balance_prev - self.e0) / scale;
        stats.energy_balance_max_increase = if done > 0 { self.max_inc } else { 0.0 };
        stats.friction_ratio_max = self.ratio_max;
        stats.tangential_velocity_final = tang.eng.space().mean_velocity(&tang.st.v);
        stats.normal_velocity_final = normal.eng.space().mean_velocity(&normal.st.v);
        stats.tangential_work_min = if done > 0 { self.min_tw } else { 0.0 };
        if let Some(ex) = &view.exact {
            stats.err_sigma_t_l2 = Some((tau * self.sum_st).sqrt());
            stats.err_vt_final =
                Some((stats.tangential_velocity_final - ex.mean_tangential_velocity(t_end)).abs());
        }
        stats
    }
}
