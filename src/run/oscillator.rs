//! The oscillator's engine (contract §1.5): one mass m, one spring k, a constant force f and an
//! obstacle x ≥ −g, integrated by the schemes of contract §3 that apply to one constrained dof.
//!
//! The conventions are the 1D bar's at its contact node (contract §2.1, §2.4), so the same contact
//! solve serves: the contact force enters as φ·q with q = −1 (pushing the mass up for φ < 0);
//! `mixed`: s = x + g, 0 ≤ s ⊥ φ ≤ 0 (φ the multiplier); `penalty`: s = −x − g,
//! φ = −κ[s]₊ with κ = `penalty_gamma0`·k (contract §1.5). A step is the scalar version of the 1D
//! engine's: A x = b + c·f + c_f φ q with A = m + c k, then the exact branch solve of
//! s = s_free + w φ(s) ([`crate::contact::solve`]).
//!
//! Schemes (parameters as data, [`crate::time::Scheme`]):
//! - Newmark(β, γ) and θ: equation at t^{n+1}, A = m + βτ²k (θ²τ²k), c = c_f = βτ² (θ²τ²);
//! - hybrid (penalty only): the midpoint rule on Δx with 003's switched contact term;
//! - Paoli–Schatzman(β, e): two-step, A = m + βτ²k, contact on (x^{n+1} + e x^{n−1})/(1+e) + g,
//!   x¹ from Newmark(β, ½), v^n = (x^{n+1} − x^{n−1})/(2τ) (as the bar).
//!
//! The methods of contract §3.2 with B = 1, M = m, K = k (the scalar versions of the 1D engine's
//! steps, [`crate::run::bar1d`]):
//! - `kane` (`mixed`): S Δx = τ m vⁿ − τ²/2 k xⁿ + τ²/2 f + τ²/2 φ q, S = m + τ²/4 k,
//!   complementarity on xⁿ + Δx + g, v^{n+1} = 2Δx/τ − vⁿ; the force does φq·Δx ≤ 0 of work
//!   over the step, so E^h never increases;
//! - `contact-stabilized-newmark` (`mixed`): the M-projection of xⁿ + τvⁿ onto x ≥ −g is, for
//!   one dof, the clamp x^pred = max(xⁿ + τvⁿ, −g); then kane from x^pred,
//!   S Δ = −τ²/4 k (xⁿ + x^pred) + τ²/2 f + τ²/2 φ q, v^{n+1} = vⁿ + (2/τ)Δ. A step whose
//!   predictor is clamped is in contact (contract §1.5); its reported force is the kane step's φ;
//! - `generalized-alpha`/`hht`: (m + ck)x^{n+1} = m(x̃ − κ_m aⁿ) − κ_f k xⁿ + κ_f φⁿ q +
//!   c φ^{n+1} q + c f/(1−α_f), c = (1−α_f)βτ²/(1−α_m), κ_{m,f} = α_{m,f}βτ²/(1−α_m),
//!   x̃ = xⁿ + τvⁿ + τ²(½ − β)aⁿ; `mixed` (multiplier) or `penalty` (φ(x^{n+1}));
//! - `moreau-jean` (`mixed`): (m + θ²τ²k)Δv = −τk(xⁿ + θτvⁿ) + τf + p q; active when
//!   xⁿ + g + ½τvⁿ ≤ 0, then 0 ≤ p ⊥ v^{n+1} + e vⁿ ≥ 0 (the contact argument on Δv with offset
//!   (1 + e)vⁿ); x^{n+1} = xⁿ + τ(vⁿ + θΔv). Reported force p/τ. θ = ½: E^{n+1} − Eⁿ =
//!   p(v^{n+1} + vⁿ)/2, zero for e = 1 by complementarity, ≤ 0 for e < 1;
//! - `discrete-gradient` (`penalty`): kane's step with φ = −D(sⁿ, s^{n+1}), D the difference
//!   quotient of κ/2[s]₊² ([`crate::contact::gradient`]): E^h + Φ conserved to round-off.
//!
//! Adding a scheme: an arm in [`Coefficients::of`] (its A, c, c_f and the load's coefficient)
//! and one in [`Osc::step`] (predictor and update), and its family in `Scene::supports`
//! (`scene::oscillator`); a velocity-level scheme reports its impulse / τ as φ, and a scheme
//! whose contact is decided by a predictor returns `true` for `active` when it is constrained
//! — `err_impact_time` counts a contact start where a step is active after one that was not
//! (contract §1.5). The observables, the exact solution and the error columns need nothing more.
//!
//! Errors against the exact solution (event by event, [`OscillatorExact`]): err_u_l2l2 =
//! (τΣ|x^n − x(t^n)|²)^½, err_u_linfl2 = max|x^n − x(t^n)|, err_v_l2 = (τΣ|v^n − v(t^n)|²)^½,
//! err_energy_l2 = (τΣ(E^n − E(t^n))²)^½ (E^n with the penalty potential), err_impact_time =
//! max over the exact impacts in [0, T] of the distance to the nearest discrete contact start
//! (T itself if no step was ever in contact). The bar's H1 and pressure columns do not apply
//! (null): the exact contact force is an impulse.

use std::time::Instant;

use super::observe::{Divergence, ExactValues, Observer, StepValues};
use super::stepping::{Clock, LoopEnd, finished, time_loop};
use super::{Metrics, Outcome, RunOptions, Status, Stop};
use crate::contact::friction::{PointState, solve_tangential};
use crate::contact::{self, ContactLaw, ContactSolveError, gradient};
use crate::scene::{DryFrictionExact, OscillatorExact, OscillatorParams};
use crate::space::ContactMethod;
use crate::time::{
    GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, PaoliSchatzmanParams, Scheme,
};

/// A validated oscillator run.
#[derive(Debug, Clone, PartialEq)]
pub struct OscillatorConfig {
    pub params: OscillatorParams,
    pub method: ContactMethod,
    pub scheme: Scheme,
    pub dt: f64,
    pub steps: usize,
    /// Ensemble member: relative amplitude of a perturbation of x⁰ and its seed.
    pub perturbation: Option<(f64, u64)>,
}

impl OscillatorConfig {
    /// A run with step `dt` up to `t_final` (rounded up to a whole number of steps).
    pub fn new(
        params: OscillatorParams,
        dt: f64,
        t_final: f64,
        method: ContactMethod,
        scheme: Scheme,
    ) -> Self {
        Self {
            params,
            method,
            scheme,
            dt,
            steps: (t_final / dt - 1e-9).ceil() as usize,
            perturbation: None,
        }
    }

    /// Penalty stiffness κ = `penalty_gamma0`·k (0 for the mixed method).
    fn kappa(&self) -> f64 {
        match self.method {
            ContactMethod::Penalty { gamma0 } => gamma0 * self.params.stiffness,
            _ => 0.0,
        }
    }

    /// The largest stable dt of an explicit scheme: τ·ω_max ≤ the scheme's bound with
    /// ω_max² = (k + κ)/m, the penalty spring active.
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        let Some(bound) = self.scheme.explicit_stability_limit() else {
            return Ok(None);
        };
        if self.method == ContactMethod::Mixed {
            return Err((
                "scheme",
                "an explicit scheme cannot enforce the multiplier constraint on the oscillator's mass (use space = penalty)".into(),
            ));
        }
        let w2 = (self.params.stiffness + self.kappa()) / self.params.mass;
        Ok(Some(bound / w2.sqrt()))
    }
}

/// The step's constants: A = m + c k, the coefficient c of k and f, c_f of the contact force.
#[derive(Debug, Clone, Copy)]
struct Coefficients {
    a: f64,
    c: f64,
    cf: f64,
}

impl Coefficients {
    fn of(scheme: Scheme, p: &OscillatorParams, tau: f64) -> Self {
        let (c, cf) = scheme.coefficients(tau);
        // The load enters where the stiffness does: Newmark/θ at t^{n+1} (c = βτ², θ²τ²),
        // Paoli–Schatzman with τ² (its equation at t^n), the incremental midpoint/trapezoidal
        // steps (hybrid, kane, CSN, discrete gradient) with τ²/2 (τ²/4 (Fⁿ + F^{n+1})),
        // Moreau–Jean's velocity step with τ (τF^{n+θ}), generalized-α's equation at
        // t^{n+1−α_f} times βτ²/(1−α_m) with c/(1−α_f).
        let c_load = match scheme {
            Scheme::PaoliSchatzman(_)
            | Scheme::Hybrid
            | Scheme::Kane
            | Scheme::ContactStabilizedNewmark
            | Scheme::DiscreteGradient => cf,
            Scheme::MoreauJean(_) => tau,
            Scheme::GeneralizedAlpha(ga) => c / (1.0 - ga.alpha_f),
            _ => c,
        };
        Self {
            a: p.mass + c * p.stiffness,
            c: c_load,
            cf,
        }
    }
}

/// The run's constant part.
struct Osc {
    p: OscillatorParams,
    scheme: Scheme,
    tau: f64,
    k: Coefficients,
    /// Contact argument s = p_x·x + p0 of the state, and the state's contact law.
    px: f64,
    p0: f64,
    law: ContactLaw,
    kappa: f64,
    /// z = c_f q / A and w = p_x z: the contact condensed (q = −1).
    z: f64,
    w: f64,
    /// Dry friction (contract §1.5): the relay's bound on the force as it enters the step (F, or
    /// the impulse τF for Moreau–Jean), 0 without friction; the step's slip is
    /// (x − slip_ref)·slip_scale of the solved unknown x (module header).
    bound: f64,
    slip_scale: f64,
    /// Weight of f_t^{n+1} in the force that does the step's work, f̄ = ω f^{n+1} + (1 − ω) fⁿ
    /// (contract §2.5: γ for Newmark, θ for the θ-scheme, 1 − α_f for generalized-α, 1 else).
    work_weight: f64,
}

#[derive(Debug, Clone, Copy)]
struct State {
    x: f64,
    v: f64,
    a: f64,
    s_prev: f64,
    /// φⁿ, the contact force of the previous step (generalized-α carries α_f of it).
    phi_prev: f64,
    /// The friction force f_tⁿ as it entered the previous step (impulse / τ for Moreau–Jean):
    /// generalized-α carries α_f of it, and the work weighs it by 1 − ω.
    ft_prev: f64,
}

/// Direction of the contact force: up (q = −1 with φ ≤ 0).
const Q: f64 = -1.0;

impl Osc {
    fn new(cfg: &OscillatorConfig, scheme: Scheme) -> Self {
        let p = cfg.params;
        let tau = cfg.dt;
        let k = Coefficients::of(scheme, &p, tau);
        let kappa = cfg.kappa();
        let (px, p0, law) = match (cfg.method, scheme) {
            (_, Scheme::PaoliSchatzman(ps)) => (
                1.0 / (1.0 + ps.restitution),
                p.gap,
                ContactLaw::Complementarity,
            ),
            (ContactMethod::Penalty { .. }, _) => {
                (-1.0, -p.gap, ContactLaw::PositivePart { k: -kappa })
            }
            _ => (1.0, p.gap, ContactLaw::Complementarity),
        };
        let z = k.cf * Q / k.a;
        let (bound, slip_scale) = match scheme {
            // The relay on v^{n+1} with the impulse p_t ∈ −τF·Sign(v^{n+1}).
            Scheme::MoreauJean(_) => (tau * p.friction, 1.0),
            // The relay on the increment (x^{n+1} − xⁿ)/τ with the force f_t ∈ −F·Sign(·).
            _ => (p.friction, 1.0 / tau),
        };
        let work_weight = match scheme {
            Scheme::Newmark(NewmarkParams { gamma, .. }) => gamma,
            Scheme::Theta(th) => th.theta,
            Scheme::GeneralizedAlpha(ga) => 1.0 - ga.alpha_f,
            _ => 1.0,
        };
        Self {
            p,
            scheme,
            tau,
            k,
            px,
            p0,
            law,
            kappa,
            z,
            w: px * z,
            bound,
            slip_scale,
            work_weight,
        }
    }

    /// The friction force at the start, at rest or moving: −F·sign(v⁰) while moving; at rest
    /// the force that holds the mass against the net force N = f − k x⁰ + φ⁰q, within ±F
    /// (the schemes that carry an acceleration start from the equation at t⁰).
    fn initial_friction(&self, x: f64, v: f64, phi: f64) -> f64 {
        let f = self.p.friction;
        if f == 0.0 {
            0.0
        } else if v != 0.0 {
            -f * v.signum()
        } else {
            (-(self.p.force - self.p.stiffness * x + phi * Q)).clamp(-f, f)
        }
    }

    /// The step's solve with dry friction (contract §1.5): A x = b + c_f(φq + f_t), the contact
    /// law on p_x x + p0 and the relay f_t ∈ −bound·Sign(slip), slip = (x − x_ref)·scale,
    /// both on the one dof. Returns (x, s, φ, f_t). The problem is the minimum of a strictly
    /// convex function of x (the quadratic, the relay's bound·|slip|, the contact's
    /// potential), so it has one x, found exactly by its cases:
    /// 1. the relay with the contact open — [`solve_tangential`], the law's own local solver
    ///    with the fixed bound — kept if the contact then exerts no force (always, far from
    ///    the obstacle);
    /// 2. otherwise the contact active with the mass slipping forward or backward
    ///    (f_t = ∓bound, the contact solved exactly by [`contact::solve`]), kept if the slip
    ///    has that sign;
    /// 3. otherwise stick, x = x_ref, the friction taking what the contact does not, within
    ///    its bound (on the obstacle the split is not unique: the friction takes the most).
    ///
    /// Without friction this is [`Osc::solve`] itself (the frictionless runs bit for bit).
    fn solve_dry(
        &self,
        b: f64,
        law: &ContactLaw,
        p0: f64,
        x_ref: f64,
    ) -> Result<(f64, f64, f64, f64), ContactSolveError> {
        if self.bound == 0.0 {
            let (x, s, phi) = self.solve(b, law, p0)?;
            return Ok((x, s, phi, 0.0));
        }
        // x per unit friction force: c_f/A (the friction pushes along +x, the contact along q).
        let zt = self.k.cf / self.k.a;
        let y = b / self.k.a;
        let sc = self.slip_scale;
        let (ft, _, state) = solve_tangential((y - x_ref) * sc, zt * sc, self.bound);
        // Stick holds the mass exactly where it was (the relay's slip is 0 exactly).
        let x1 = if state == PointState::Stick {
            x_ref
        } else {
            y + zt * ft
        };
        let open = contact::solve(law, self.px * x1 + p0, self.w)?;
        if open.phi == 0.0 {
            return Ok((x1, open.s, 0.0, ft));
        }
        for ft in [-self.bound, self.bound] {
            let yy = y + zt * ft;
            let sol = contact::solve(law, self.px * yy + p0, self.w)?;
            let x = yy + sol.phi * self.z;
            // f_t = −bound goes with a forward slip, +bound with a backward one.
            if -ft * (x - x_ref) > 0.0 {
                return Ok((x, sol.s, sol.phi, ft));
            }
        }
        // Stick in contact: the total force φq + f_t = (x_ref − y)/z_t.
        let s = self.px * x_ref + p0;
        let total = (x_ref - y) / zt;
        let phi = match *law {
            ContactLaw::PositivePart { k } => k * s.max(0.0),
            _ if s > 0.0 => 0.0,
            _ => (total - total.clamp(-self.bound, self.bound)) / Q,
        };
        Ok((x_ref, s, phi, total - phi * Q))
    }

    /// The state's contact force φ(x) (penalty), 0 for a multiplier not yet known.
    fn state_force(&self, x: f64) -> f64 {
        match self.law {
            ContactLaw::PositivePart { k } => k * (self.px * x + self.p0).max(0.0),
            _ => 0.0,
        }
    }

    /// Acceleration from the equation at a state with contact force φ.
    fn accel(&self, x: f64, phi: f64) -> f64 {
        (self.p.force - self.p.stiffness * x + phi * Q) / self.p.mass
    }

    /// E^h = ½mv² + ½kx² − fx, plus the penalty potential κ/2[−x − g]₊².
    fn energy(&self, x: f64, v: f64) -> f64 {
        let pen = (-x - self.p.gap).max(0.0);
        self.p.energy(x, v) + 0.5 * self.kappa * pen * pen
    }

    /// Solve A y = b, then the scalar contact problem with the argument's offset p0: returns
    /// (x, s, φ) with x = y + φ z.
    fn solve(
        &self,
        b: f64,
        law: &ContactLaw,
        p0: f64,
    ) -> Result<(f64, f64, f64), ContactSolveError> {
        let y = b / self.k.a;
        let sol = contact::solve(law, self.px * y + p0, self.w)?;
        Ok((y + sol.phi * self.z, sol.s, sol.phi))
    }

    /// One step of a one-step scheme; returns φ of the step, the friction force f_t^{n+1}
    /// (impulse / τ for Moreau–Jean) and whether its contact is active.
    fn step(&self, st: &mut State) -> Result<(f64, f64, bool), ContactSolveError> {
        let (tau, m, f) = (self.tau, self.p.mass, self.p.force);
        let load = self.k.c * f;
        let (phi, ft, x_new) = match self.scheme {
            Scheme::Newmark(NewmarkParams { beta, gamma }) => {
                let pred = st.x + tau * st.v + tau * tau / 2.0 * (1.0 - 2.0 * beta) * st.a;
                let (x, s, phi, ft) = self.solve_dry(m * pred + load, &self.law, self.p0, st.x)?;
                // Explicit with friction is refused by the scene: there f_t = 0.
                let a = if beta > 0.0 {
                    (x - pred) / (beta * tau * tau)
                } else {
                    self.accel(x, phi)
                };
                st.v += tau * ((1.0 - gamma) * st.a + gamma * a);
                st.a = a;
                st.s_prev = s;
                (phi, ft, x)
            }
            Scheme::Theta(th) => {
                let t = th.theta;
                let pred = st.x + tau * st.v + tau * tau * t * (1.0 - t) * st.a;
                let (x, s, phi, ft) = self.solve_dry(m * pred + load, &self.law, self.p0, st.x)?;
                let it = 1.0 / (tau * t);
                let v = (x - st.x - tau * (1.0 - t) * st.v) * it;
                st.a = (v - st.v - tau * (1.0 - t) * st.a) * it;
                st.v = v;
                st.s_prev = s;
                (phi, ft, x)
            }
            Scheme::Hybrid => {
                // Δx from A Δx = τ m v − (τ²/2)(k x − f) + c_f φ q, the contact switched on the
                // sign of the argument at t^n (003 (11)).
                let ContactLaw::PositivePart { k } = self.law else {
                    unreachable!("the planner gives the hybrid scheme the penalty method only")
                };
                let b = tau * m * st.v - tau * tau / 2.0 * self.p.stiffness * st.x + load;
                let law = ContactLaw::HybridNitsche {
                    k,
                    s_prev: st.s_prev,
                };
                let (dx, s, phi) = self.solve(b, &law, self.p0 + self.px * st.x)?;
                st.v = 2.0 * dx / tau - st.v;
                st.s_prev = s;
                (phi, 0.0, st.x + dx)
            }
            Scheme::Kane => {
                // S Δx = τ m vⁿ − τ²/2 k xⁿ + τ²/2 f + τ²/2 φ q, complementarity on
                // xⁿ + Δx + g; v^{n+1} = 2Δx/τ − vⁿ. No force is carried to the next step.
                // The unknown is Δx: the slip Δx/τ is relative to 0.
                let b = tau * m * st.v - tau * tau / 2.0 * self.p.stiffness * st.x + load;
                let (dx, s, phi, ft) =
                    self.solve_dry(b, &self.law, self.p0 + self.px * st.x, 0.0)?;
                st.v = 2.0 * dx / tau - st.v;
                st.s_prev = s;
                (phi, ft, st.x + dx)
            }
            Scheme::ContactStabilizedNewmark => {
                // Predictor: the M-projection of xⁿ + τvⁿ onto x ≥ −g — for one dof the
                // clamp (W = 1/m > 0, so the LCP's solution is the projection).
                let free = st.x + tau * st.v;
                let pred = free.max(-self.p.gap);
                let constrained = pred != free;
                // kane from x^pred: S Δ = −τ²/4 k (xⁿ + x^pred) + τ²/2 f + τ²/2 φ q,
                // Δ = x^{n+1} − x^pred; v^{n+1} = vⁿ + (2/τ) Δ.
                // The unknown is Δ = x^{n+1} − x^pred: the slip (x^pred + Δ − xⁿ)/τ.
                let b = -tau * tau / 4.0 * self.p.stiffness * (st.x + pred) + load;
                let (dx, s, phi, ft) =
                    self.solve_dry(b, &self.law, self.p0 + self.px * pred, st.x - pred)?;
                st.v += 2.0 * dx / tau;
                st.a = 0.0;
                st.s_prev = s;
                st.x = pred + dx;
                st.ft_prev = ft;
                // contract §1.5: a step whose predictor is constrained is in contact.
                return Ok((phi, ft, constrained || phi != 0.0));
            }
            Scheme::GeneralizedAlpha(ga @ GeneralizedAlphaParams { beta, gamma, .. }) => {
                // x̃ = xⁿ + τvⁿ + τ²(½ − β)aⁿ, a^{n+1} = (x^{n+1} − x̃)/(βτ²); the equation at
                // t^{n+1−α} times βτ²/(1−α_m):
                // (m + ck)x^{n+1} = m(x̃ − κ_m aⁿ) − κ_f k xⁿ + κ_f φⁿ q + c φ^{n+1} q + c_F f.
                let bt2 = beta * tau * tau;
                let (km, kf) = ga.history_coefficients(tau);
                let pred = st.x + tau * st.v + tau * tau * (0.5 - beta) * st.a;
                // The friction force is carried as the contact force is: κ_f f_tⁿ.
                let b = m * (pred - km * st.a) - kf * self.p.stiffness * st.x
                    + kf * st.phi_prev * Q
                    + kf * st.ft_prev
                    + load;
                let (x, s, phi, ft) = self.solve_dry(b, &self.law, self.p0, st.x)?;
                let a = (x - pred) / bt2;
                st.v += tau * ((1.0 - gamma) * st.a + gamma * a);
                st.a = a;
                st.s_prev = s;
                (phi, ft, x)
            }
            Scheme::MoreauJean(MoreauJeanParams { theta, restitution }) => {
                // (m + θ²τ²k)Δv = −τk(xⁿ + θτvⁿ) + τf + p q; active when the predicted gap
                // xⁿ + g + ½τvⁿ closes, then 0 ≤ p ⊥ v^{n+1} + e vⁿ ≥ 0 (the argument on Δv:
                // p_x = 1, offset (1 + e)vⁿ), else p = 0.
                let b = -tau * self.p.stiffness * (st.x + theta * tau * st.v) + load;
                let law = if st.x + self.p.gap + 0.5 * tau * st.v <= 0.0 {
                    ContactLaw::Complementarity
                } else {
                    ContactLaw::PositivePart { k: 0.0 }
                };
                // Dry friction: the relay p_t ∈ −τF·Sign(v^{n+1}), v^{n+1} = vⁿ + Δv, combined
                // with the normal impulse on the same dof (`solve_dry`).
                let (dv, _, impulse, pt) =
                    self.solve_dry(b, &law, (1.0 + restitution) * st.v, -st.v)?;
                let x = st.x + tau * (st.v + theta * dv);
                st.v += dv;
                st.a = dv / tau;
                st.s_prev = x + self.p.gap;
                // Reported forces: the impulses over the step (contract §3.2).
                (impulse / tau, pt / tau, x)
            }
            Scheme::DiscreteGradient => {
                // The midpoint rule with the force the difference quotient D of the penalty
                // potential κ/2[s]₊² (s = −x − g): S Δx = τ m vⁿ − τ²/2 k xⁿ + τ²/2 f + τ²/2 φ q
                // with φ = −D(sⁿ, s^{n+1}), so E^h + Φ is conserved to round-off.
                let ContactLaw::PositivePart { k } = self.law else {
                    unreachable!("the scene gives the discrete gradient the penalty method only")
                };
                let b = tau * m * st.v - tau * tau / 2.0 * self.p.stiffness * st.x + load;
                let y = b / self.k.a;
                let s_n = self.px * st.x + self.p0;
                let sol = gradient::solve(-k, s_n, s_n + self.px * y, self.w)?;
                let phi = -sol.d;
                let dx = y + phi * self.z;
                st.v = 2.0 * dx / tau - st.v;
                st.s_prev = sol.s;
                (phi, 0.0, st.x + dx)
            }
            // Paoli–Schatzman is two-step (its loop is in `simulate`); a family the scene does
            // not list in `supports` never reaches the engine.
            _ => unreachable!("not a one-step scheme of the oscillator"),
        };
        st.x = x_new;
        st.phi_prev = phi;
        st.ft_prev = ft;
        Ok((phi, ft, phi != 0.0))
    }
}

/// The exact solution the run is measured against: the frictionless one event by event, or
/// with dry friction on the mass its turning points, impacts and rest ([`DryFrictionExact`]).
enum Exact {
    Free(OscillatorExact),
    Dry(DryFrictionExact),
}

impl Exact {
    fn state(&self, t: f64, cursor: &mut usize) -> (f64, f64) {
        match self {
            Exact::Free(e) => e.state(t, cursor),
            Exact::Dry(e) => e.state(t),
        }
    }
    fn impacts(&self) -> &[f64] {
        match self {
            Exact::Free(e) => e.impacts(),
            Exact::Dry(e) => e.impacts(),
        }
    }
}

/// When the mass stops for good (contract §1.5 `stop_time`): the time of the last step that moved
/// it by more than `tol` — after it the mass never moves again. `None` while it still moves
/// at the last step.
struct StopWatch {
    tol: f64,
    last_move: Option<usize>,
    last_step: usize,
}

impl StopWatch {
    fn observe(&mut self, n: usize, dx: f64) {
        if dx.abs() > self.tol {
            self.last_move = Some(n);
        }
        self.last_step = n;
    }
    fn stop_time(&self, tau: f64) -> Option<f64> {
        match self.last_move {
            Some(n) if n == self.last_step => None,
            Some(n) => Some(n as f64 * tau),
            None => Some(0.0),
        }
    }
}

/// Error sums against the exact solution, and the discrete contact starts.
struct Errors<'a> {
    exact: &'a Exact,
    cursor: usize,
    sum_v: f64,
    was_active: bool,
    /// Times of the steps whose contact is active after one that was not (capacity for
    /// every step: no allocation in the loop).
    starts: Vec<f64>,
}

/// How often the clock is read for the timeout.
const CLOCK_EVERY: usize = 256;

/// Run one oscillator simulation.
pub fn simulate(cfg: &OscillatorConfig, opts: &RunOptions) -> Outcome {
    let start = Instant::now();
    let p = cfg.params;
    let tau = cfg.dt;
    let t_final = cfg.steps as f64 * tau;
    let mut metrics = Metrics {
        dofs: 1,
        factorizations: 0,
        ..Metrics::default()
    };
    let dry = p.friction > 0.0;
    let exact = if dry {
        Exact::Dry(DryFrictionExact::new(p, p.friction, t_final))
    } else {
        Exact::Free(p.exact(t_final))
    };
    let eng = Osc::new(cfg, cfg.scheme);
    let (st, phi0, ft0) = initial_state(cfg, &eng);
    let x0 = st.x;
    let mut run = OscRun {
        cfg,
        eng: &eng,
        st,
        dry,
        // E + W_f after the last step and its largest one-step rise (contract §2.5's balance).
        acc: DryAccount {
            work: 0.0,
            balance: eng.energy(x0, p.v0),
            balance_rise: f64::NEG_INFINITY,
            stick: 0,
            slip: 0,
            watch: StopWatch {
                tol: 1e-12 * x0.abs().max(p.gap),
                last_move: None,
                last_step: 0,
            },
        },
        rec: Recorder {
            eng: &eng,
            obs: Observer::new(tau, opts.series_every, cfg.steps),
            err: Errors {
                exact: &exact,
                cursor: 0,
                sum_v: 0.0,
                was_active: phi0 != 0.0,
                starts: Vec::with_capacity(cfg.steps + 1),
            },
        },
    };
    let end = time_loop(
        opts,
        start,
        (CLOCK_EVERY, tau, cfg.steps),
        &mut metrics,
        |clock, metrics| match cfg.scheme {
            Scheme::PaoliSchatzman(ps) => run.paoli_schatzman(ps, phi0, clock, metrics),
            _ => {
                let friction = dry.then_some((ft0, 0.0));
                run.rec
                    .record(0, run.st.x, run.st.v, phi0, phi0 != 0.0, friction)
                    .map_err(Stop::Diverged)?;
                run.one_step(clock, metrics)
            }
        },
    );
    let complete = end.status == Status::Ok;
    run.rec.obs.finish(&mut metrics, complete);
    // The bar's H1 and pressure columns have no meaning for a point mass.
    metrics.err_u_l2h1 = None;
    metrics.err_sigma_l2 = None;
    metrics.err_sigma_mid_l2 = None;
    if complete && dry {
        run.acc.columns(&mut metrics, &eng, x0, tau, &exact);
    }
    if complete {
        metrics.err_v_l2 = Some((tau * run.rec.err.sum_v).sqrt());
        metrics.err_impact_time = (!exact.impacts().is_empty()).then(|| {
            exact
                .impacts()
                .iter()
                .map(|ti| {
                    run.rec
                        .err
                        .starts
                        .iter()
                        .map(|s| (s - ti).abs())
                        .fold(t_final, f64::min)
                })
                .fold(0.0, f64::max)
        });
    }
    finished(end.status, end.message, metrics, &mut run.rec.obs)
}

/// The initial state (x⁰ perturbed for ensembles), its contact force φ⁰ and friction f_t⁰.
fn initial_state(cfg: &OscillatorConfig, eng: &Osc) -> (State, f64, f64) {
    let p = cfg.params;
    let dry = p.friction > 0.0;
    let mut x0 = p.x0;
    if let Some((delta, seed)) = cfg.perturbation {
        let mut rng = fastrand::Rng::with_seed(seed);
        x0 += delta * (2.0 * rng.f64() - 1.0) * x0.abs().max(p.gap);
    }
    let phi0 = eng.state_force(x0);
    let ft0 = eng.initial_friction(x0, p.v0, phi0);
    let st = State {
        x: x0,
        v: p.v0,
        // The equation at t⁰, the friction included where there is one.
        a: if dry {
            eng.accel(x0, phi0) + ft0 / p.mass
        } else {
            eng.accel(x0, phi0)
        },
        s_prev: eng.px * x0 + eng.p0,
        phi_prev: phi0,
        ft_prev: ft0,
    };
    (st, phi0, ft0)
}

/// Dry friction's accounts (contract §1.5): the work W_f = −Σ f̄_t (x^{n+1} − xⁿ), E + W_f after
/// the last step and its largest one-step rise, the steps in stick and in slip, and the stop.
/// The friction acts on the mass at every step (it does not wait for the obstacle), so every
/// step counts: in stick when it moves the mass by at most the stop watch's tolerance
/// 1e-12·max(|x⁰|, g) — the FE tally's increment rule, 1e-12·h, on the one dof — else in slip.
struct DryAccount {
    work: f64,
    balance: f64,
    balance_rise: f64,
    stick: i64,
    slip: i64,
    watch: StopWatch,
}

impl DryAccount {
    /// Step `n` moved the mass from `x_old` to `st.x` under the friction forces `ft_old`, `ft`:
    /// returns what the friction series shows (f_t, W_f so far).
    fn step(
        &mut self,
        eng: &Osc,
        n: usize,
        st: &State,
        x_old: f64,
        ft: f64,
        ft_old: f64,
    ) -> (f64, f64) {
        let dx = st.x - x_old;
        let w = eng.work_weight;
        self.work -= (w * ft + (1.0 - w) * ft_old) * dx;
        if dx.abs() > self.watch.tol {
            self.slip += 1;
        } else {
            self.stick += 1;
        }
        self.watch.observe(n, dx);
        // E + W_f: what the normal contact (and the scheme) did in the step.
        let b = eng.energy(st.x, st.v) + self.work;
        self.balance_rise = self.balance_rise.max(b - self.balance);
        self.balance = b;
        (ft, self.work)
    }

    /// The frictional columns of a complete run started at `x0`.
    fn columns(&self, metrics: &mut Metrics, eng: &Osc, x0: f64, tau: f64, exact: &Exact) {
        let p = eng.p;
        let done = metrics.steps;
        let scale = p.energy(x0, p.v0).abs().max(f64::MIN_POSITIVE);
        metrics.friction_work = Some(self.work / scale);
        // The frictional summaries judge E + W_f (contract §2.5), as on the layer and the FE
        // scenes: its drift from E⁰ and its largest one-step rise, over the same scale.
        metrics.energy_balance_drift = Some((self.balance - eng.energy(x0, p.v0)) / scale);
        metrics.energy_balance_max_increase = Some(if done > 0 {
            self.balance_rise / scale
        } else {
            0.0
        });
        metrics.stick_steps = Some(self.stick);
        metrics.slip_steps = Some(self.slip);
        metrics.stop_time = self.watch.stop_time(tau);
        if let Exact::Dry(e) = exact {
            metrics.stop_time_exact = e.stop().map(|(t, _)| t);
        }
    }
}

/// Records a step: the observer and the error sums against the exact solution.
struct Recorder<'a> {
    eng: &'a Osc,
    obs: Observer,
    err: Errors<'a>,
}

impl Recorder<'_> {
    /// Observe step `n` (x, v, the reported force φ, whether the contact is active, and with
    /// dry friction the friction series: f_t as it entered the step, W_f so far).
    fn record(
        &mut self,
        n: usize,
        x: f64,
        v: f64,
        phi: f64,
        active: bool,
        friction: Option<(f64, f64)>,
    ) -> Result<(), Divergence> {
        let (eng, obs, err) = (self.eng, &mut self.obs, &mut self.err);
        let p = eng.p;
        let t = n as f64 * eng.tau;
        // With dry friction, the friction series: f_t as it entered the step, the mass's
        // velocity (its slip), W_f so far.
        if let Some((ft, w)) = friction {
            obs.set_friction(ft, v, w);
        }
        let (xe, ve) = err.exact.state(t, &mut err.cursor);
        let dv = v - ve;
        err.sum_v += dv * dv;
        if active && !err.was_active && n > 0 {
            err.starts.push(t);
        }
        err.was_active = active;
        let dx = x - xe;
        obs.observe(
            StepValues {
                step: n,
                t,
                u_contact: x,
                v_contact: v,
                sigma_contact: phi,
                sigma_mid: None,
                energy: eng.energy(x, v),
                energy_theta: None,
                energy_kinetic: None,
                energy_elastic: None,
                energy_gravity: None,
                u_lowest: None,
                penetration: Some((-x - p.gap).max(0.0)),
            },
            Some(ExactValues {
                u_contact: xe,
                // The exact contact force is an impulse at impacts; at rest on the obstacle it
                // holds the net force, φ = f + k g (< 0).
                sigma_contact: if xe == -p.gap && ve == 0.0 {
                    (p.force + p.stiffness * p.gap).min(0.0)
                } else {
                    0.0
                },
                sigma_contact_mid: None,
                energy: p.energy(xe, ve),
                l2_sq: dx * dx,
                h1_semi_sq: 0.0,
            }),
        )
    }
}

/// A run in its time loop: the engine, the state, the recorder and the friction accounts.
struct OscRun<'a> {
    cfg: &'a OscillatorConfig,
    eng: &'a Osc,
    st: State,
    dry: bool,
    acc: DryAccount,
    rec: Recorder<'a>,
}

impl OscRun<'_> {
    /// Steps 1…N of a one-step scheme (step 0 recorded).
    fn one_step(&mut self, clock: &mut Clock, metrics: &mut Metrics) -> LoopEnd {
        let eng = self.eng;
        for n in 1..=self.cfg.steps {
            let (x_old, ft_old) = (self.st.x, self.st.ft_prev);
            let (phi, ft, active) = eng.step(&mut self.st).map_err(|e| Stop::Solver(n, e))?;
            metrics.iterations += 1;
            let friction = if self.dry {
                Some(self.acc.step(eng, n, &self.st, x_old, ft, ft_old))
            } else {
                None
            };
            let st = self.st;
            self.rec
                .record(n, st.x, st.v, phi, active, friction)
                .map_err(Stop::Diverged)?;
            clock.completed(n)?;
        }
        Ok(())
    }

    /// Paoli–Schatzman: x¹ from Newmark(β, ½); then x^{n+1} from (x^n, x^{n−1}), v^n centred:
    /// step n is recorded once x^{n+1} is known, with the multiplier λ^n of its equation.
    fn paoli_schatzman(
        &mut self,
        ps: PaoliSchatzmanParams,
        phi0: f64,
        clock: &mut Clock,
        metrics: &mut Metrics,
    ) -> LoopEnd {
        let (cfg, eng) = (self.cfg, self.eng);
        let (p, tau) = (cfg.params, cfg.dt);
        let st = &mut self.st;
        let starter = Osc::new(
            cfg,
            Scheme::Newmark(NewmarkParams {
                beta: ps.beta,
                gamma: 0.5,
            }),
        );
        self.rec
            .record(0, st.x, st.v, phi0, phi0 != 0.0, None)
            .map_err(Stop::Diverged)?;
        let mut prev = st.x;
        starter.step(st).map_err(|e| Stop::Solver(1, e))?;
        metrics.iterations += 1;
        let (e, beta) = (ps.restitution, ps.beta);
        let (k, m) = (p.stiffness, p.mass);
        for n in 1..=cfg.steps {
            let b = m * (2.0 * st.x - prev)
                - tau * tau * k * ((1.0 - 2.0 * beta) * st.x + beta * prev)
                + eng.k.c * p.force;
            let p0 = e * prev / (1.0 + e) + p.gap;
            let (next, _, lambda) = eng
                .solve(b, &ContactLaw::Complementarity, p0)
                .map_err(|err| Stop::Solver(n, err))?;
            metrics.iterations += 1;
            let v = (next - prev) / (2.0 * tau);
            self.rec
                .record(n, st.x, v, lambda, lambda != 0.0, None)
                .map_err(Stop::Diverged)?;
            prev = st.x;
            st.x = next;
            clock.completed(n)?;
        }
        Ok(())
    }
}
