//! The 1D engine: every contact treatment × mass variant × time scheme on the bar (contract §2–§4).
//!
//! Setup (once per run): assemble M, K, K_lin (tridiagonal), form A = M + c K_lin, factor it,
//! and precompute z = A⁻¹q̃ and w = pᵀz — the contact condensed onto the contact node. A step is
//! then one O(m) tridiagonal solve y = A⁻¹b, the exact scalar solve of
//! s = pᵀy + p₀ + w φ(s) ([`crate::contact`]), and u^{n+1} = y + φ z. No allocation happens in
//! the time loop: all vectors live in the [`Work`] and state buffers built at setup.
//!
//! A contact node without inertia (zero mass row) is quasi-static: its row of the step system
//! is c·(K_lin u)₀ = c_f φ q₀ — the equation of the node at the scheme's evaluation time — and
//! at t = 0 its value is given by the same equation (contract §2.2). With the explicit Newmark
//! (c = 0) that row is replaced by K_lin row 0 itself.
//!
//! `contact_init = interpolant` ([`ContactInit`]) starts that node at the interpolant u0(0)
//! instead: E⁰ is then the exact energy and a⁰ is taken from that state. Every scheme whose node
//! row holds at t^{n+1} (Newmark, θ, the reduced hybrid, which sets u₀ = max(−g, u₁)) moves the
//! node to its quasi-static value at the first step and loses energy there once (the contact
//! element's excess strain, h/8 for the default bar, and more: 1.5 % of E⁰ with CN at h = 0.01,
//! τ = 0.015). The hybrid scheme with Nitsche or penalty enforces that row at the midpoint
//! t^{n+½}: there the start's defect never dies out, the node alternates about its
//! quasi-static value by ±(a − u₀^qs) from step to step and keeps the excess energy (E_Θ still
//! never increases).
//!
//! The hybrid scheme with the mixed method is 000 §5's scheme on the reduced system: node 0 is
//! eliminated (u₀ = max(−g, u₁)), the contact element's energy (E/2h)[−(u₁+g)]₊² is split into
//! its quadratic part (kept in K*, node 0 clamped at −g) and −(E/2h)[u₁+g]₊², whose force
//! (E/h)[u₁+g]₊ e₁ is switched between midpoint and Crank–Nicolson on the sign of u₁^n + g.
//!
//! The methods of contract §3.2 ([`Engine::step_comparison`]) use the same constant matrix and the
//! same condensation: `kane`, `discrete-gradient` step the increment Δu with S = M + τ²/4 K
//! (one scalar solve; the discrete gradient's is a Newton iteration on the contact point's
//! difference quotient, [`crate::contact::gradient`]); `contact-stabilized-newmark` adds the
//! M-projection of the free flight (a second scalar solve, with M⁻¹q computed at setup);
//! `generalized-alpha`/`hht` step u^{n+1} with M + cK, c = (1−α_f)βτ²/(1−α_m), carrying the
//! previous contact force φⁿ; `moreau-jean` steps Δv with M + θ²τ²K and an impulse on the
//! contact node when its predicted gap closes. `central-difference` with `mixed` and the lumped
//! mass enforces contact kinematically ([`crate::time::kinematic_impulse`]): no solve at all.

use std::time::Instant;

use super::grid1d::Grid1d;
use super::observe::{Divergence, ExactValues, Observer, StepValues};
use super::stepping::{Clock, LoopEnd, failed, finished, time_loop};
use super::{Metrics, Outcome, RunOptions, Status, Stop};
use crate::contact::friction;
use crate::contact::{self, ContactLaw, ContactSolveError, gradient};
use crate::scene::{BarExact, BarParams};
use crate::space::bar1d::Pair;
use crate::space::{Bar1dSpace, ContactInit, ContactMethod, Tridiag, TridiagLu};
use crate::time::{GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, Scheme};

/// A validated bar1d run.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar1dConfig {
    pub bar: BarParams,
    pub grid: Grid1d,
    /// Initial value of a massless contact node (ignored when the contact node has mass).
    pub contact_init: ContactInit,
    /// Ensemble member: relative amplitude of a uniform perturbation of u⁰ and its seed.
    pub perturbation: Option<(f64, u64)>,
}

impl Bar1dConfig {
    /// A run of the bar on `grid`, its massless contact node (if any) started consistently —
    /// the entry point of tests, benches and examples.
    pub fn new(bar: BarParams, grid: Grid1d) -> Self {
        Self {
            bar,
            grid,
            contact_init: ContactInit::Consistent,
            perturbation: None,
        }
    }

    /// The same run with the massless contact node started by `init` (contract §2.2).
    pub fn with_contact_init(mut self, init: ContactInit) -> Self {
        self.contact_init = init;
        self
    }
}

impl Bar1dConfig {
    /// The largest stable dt of an explicit scheme (None for implicit ones): τ ω_max ≤ the
    /// scheme's bound, ω_max from the assembled operators with the contact stiffness inactive
    /// and active.
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        let Some(bound) = self.grid.scheme.explicit_stability_limit() else {
            return Ok(None);
        };
        let sp = Bar1dSpace::new(
            self.bar,
            self.grid.elements,
            &self.grid.mass,
            self.grid.method,
        )
        .map_err(|e| ("mass", e.to_string()))?;
        Ok(Some(bound / max_frequency_sq(&sp).sqrt()))
    }
}

/// ω²_max of the linear part, with and without the contact stiffness active.
fn max_frequency_sq(sp: &Bar1dSpace) -> f64 {
    let free = sp.stiffness_lin.max_generalized_eigenvalue(&sp.mass);
    let mut active: Tridiag = sp.stiffness_lin.clone();
    match sp.method {
        ContactMethod::Mixed => {
            // u₀ = −g held: node 0 clamped.
            active.set_row(0, (0.0, 1.0, 0.0));
            active.lower[0] = 0.0;
        }
        ContactMethod::Nitsche { gamma0, .. } => {
            let k = 1.0 / (gamma0 * sp.h);
            let p = sp.p.0;
            active.add_element(
                0,
                [
                    [k * p[0] * p[0], k * p[0] * p[1]],
                    [k * p[0] * p[1], k * p[1] * p[1]],
                ],
            );
        }
        ContactMethod::Penalty { gamma0 } => active.diag[0] += sp.penalty_stiffness(gamma0),
    }
    free.max(active.max_generalized_eigenvalue(&sp.mass))
}

/// The contact node of a tangential chain (the layer's S-wave chain, contract §1.7): held by the
/// friction law instead of the obstacle. Before each step the layer's driver
/// (the layer1d engine) sets the bound b of the step (from the normal chain's force of the same
/// step) and the slip's reference value: the step's scalar s is then u₀^{n+1} (position-level
/// schemes, s_ref = u₀ⁿ) or v₀^{n+1} + e v₀ⁿ (Moreau–Jean, s_ref = e v₀ⁿ), and the slip is
/// s − s_ref. `kappa` is the penalty's tangential stiffness (f_t = proj_[−b,b](−κ·slip)).
#[derive(Debug, Default)]
pub(super) struct Tangential {
    pub bound: std::cell::Cell<f64>,
    pub s_ref: std::cell::Cell<f64>,
    pub kappa: Option<f64>,
}

/// The per-run constant part: operators, factorisations, condensed contact.
pub(super) struct Engine {
    sp: Bar1dSpace,
    scheme: Scheme,
    tau: f64,
    reduced: bool,
    /// Stiffness of the linear part in the right-hand side (K* on the reduced system).
    klin: Tridiag,
    a_lu: TridiagLu,
    mass_lu: TridiagLu,
    z: Vec<f64>,
    w: f64,
    /// The contact argument of the step (reduced: u₁ + g; Paoli–Schatzman: u₀/(1+e) + …).
    p: Pair,
    p0: f64,
    factorizations: i64,
    /// Contact-stabilized Newmark's predictor: z_M = M⁻¹q and w_M = pᵀz_M (empty otherwise).
    zm: Vec<f64>,
    wm: f64,
    /// Central difference with `mixed` and a diagonal mass: kinematic contact.
    kinematic: bool,
    /// Contact-solver iterations beyond one per step (the discrete gradient's Newton
    /// iterations, the contact-stabilized predictor's second solve), for `iterations`.
    extra_iterations: std::cell::Cell<i64>,
    /// A tangential chain's friction (None: the obstacle's contact, every bar1d run).
    pub(super) tangential: Option<Tangential>,
}

/// Vectors reused by every step.
pub(super) struct Work {
    pub b: Vec<f64>,
    pub y: Vec<f64>,
    pub pred: Vec<f64>,
}

pub(super) struct State {
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    a: Vec<f64>,
    /// Contact argument at t^n (hybrid switches).
    s_prev: f64,
    /// Contact force factor φⁿ of the last step (generalized-α carries α_f φⁿ).
    phi_prev: f64,
}

/// The Newmark/θ predictor uⁿ + τvⁿ + k aⁿ into `pred` (slices zipped: the step's hot loop).
fn predict_into(pred: &mut [f64], st: &State, tau: f64, k: f64) {
    for (((p, u), v), a) in pred.iter_mut().zip(&st.u).zip(&st.v).zip(&st.a) {
        *p = u + tau * v + k * a;
    }
}

/// Generalized-α's right-hand side M(ũ − κ_m aⁿ) − κ_f K uⁿ, with ũ = uⁿ + τvⁿ + k_p aⁿ into
/// `pred` and ũ − κ_m aⁿ into the scratch `w`: two passes (the vector, then both tridiagonal
/// products and their difference at once) where two products and their sum as separate loops
/// read and write the m-vectors twice as often. The sums are formed in the same order, so the
/// result is bit for bit that of the separate products.
fn gen_alpha_rhs_into(
    mass: &Tridiag,
    k: &Tridiag,
    st: &State,
    (tau, kp, km, kf): (f64, f64, f64, f64),
    (pred, w, b): (&mut [f64], &mut [f64], &mut [f64]),
) {
    let n = st.u.len();
    let (u, v, a) = (&st.u[..n], &st.v[..n], &st.a[..n]);
    let (pred, w, b) = (&mut pred[..n], &mut w[..n], &mut b[..n]);
    for ((((p, w), u), v), a) in pred.iter_mut().zip(w.iter_mut()).zip(u).zip(v).zip(a) {
        *p = u + tau * v + kp * a;
        *w = *p - km * a;
    }
    if n == 1 {
        b[0] = mass.diag[0] * w[0] - kf * (k.diag[0] * u[0]);
        return;
    }
    let (ml, md, mu) = (&mass.lower[..n - 1], &mass.diag[..n], &mass.upper[..n - 1]);
    let (kl, kd, ku) = (&k.lower[..n - 1], &k.diag[..n], &k.upper[..n - 1]);
    b[0] = (md[0] * w[0] + mu[0] * w[1]) - kf * (kd[0] * u[0] + ku[0] * u[1]);
    for i in 1..n - 1 {
        let mw = ml[i - 1] * w[i - 1] + md[i] * w[i] + mu[i] * w[i + 1];
        let kuv = kl[i - 1] * u[i - 1] + kd[i] * u[i] + ku[i] * u[i + 1];
        b[i] = mw - kf * kuv;
    }
    b[n - 1] = (ml[n - 2] * w[n - 2] + md[n - 1] * w[n - 1])
        - kf * (kl[n - 2] * u[n - 2] + kd[n - 1] * u[n - 1]);
}

impl Engine {
    pub(super) fn new(sp: Bar1dSpace, scheme: Scheme, tau: f64) -> Result<Self, String> {
        let m = sp.m;
        let (c, cf) = scheme.coefficients(tau);
        let reduced = matches!(scheme, Scheme::Hybrid) && sp.method == ContactMethod::Mixed;
        if reduced && !sp.massless_contact {
            return Err(
                "the hybrid scheme with the mixed method needs a massless contact node (000 §5)"
                    .into(),
            );
        }
        let mut klin = sp.stiffness_lin.clone();
        if reduced {
            klin.clear_row_col(0);
        }
        let mut a = sp.mass.axpy(c, &klin);
        let mut qt = [cf * sp.q.0[0], cf * sp.q.0[1]];
        if sp.massless_contact
            && !matches!(
                scheme,
                Scheme::Hybrid | Scheme::DiscreteGradient | Scheme::Kane
            )
        {
            // Quasi-static contact row at t^{n+1}: c (K u)₀ = c φ q₀ (or K row 0 itself if c = 0).
            qt[0] = if c == 0.0 { sp.q.0[0] } else { c * sp.q.0[0] };
            if c == 0.0 {
                a.set_row(0, sp.stiffness_lin.row(0));
            }
        }
        let (p, p0) = if reduced {
            a.set_row(0, (0.0, 1.0, 0.0));
            qt = [0.0, cf];
            (Pair([0.0, 1.0]), sp.bar.gap)
        } else if let Scheme::PaoliSchatzman(ps) = scheme {
            (Pair([1.0 / (1.0 + ps.restitution), 0.0]), sp.bar.gap)
        } else {
            (sp.p, sp.p0)
        };
        let a_lu = a
            .factor()
            .ok_or("the iteration matrix M + cK is singular")?;
        let mut mfree = sp.mass.clone();
        if sp.massless_contact {
            mfree.set_row(0, (0.0, 1.0, 0.0));
        }
        let mass_lu = mfree
            .factor()
            .ok_or("the mass matrix of the free nodes is singular")?;
        let mut z = vec![0.0; m];
        z[0] = qt[0];
        z[1] = qt[1];
        a_lu.solve_in_place(&mut z);
        let w = p.dot(&z);
        let kinematic = scheme == Scheme::Newmark(NewmarkParams::central_difference())
            && sp.method == ContactMethod::Mixed
            && !sp.massless_contact;
        if kinematic && sp.mass.upper.iter().any(|&x| x != 0.0) {
            return Err(
                "kinematic contact (central difference with the mixed method) needs a diagonal mass (`lumped`)"
                    .into(),
            );
        }
        if scheme == Scheme::DiscreteGradient
            && !match sp.method {
                ContactMethod::Penalty { .. } => true,
                ContactMethod::Nitsche { theta, .. } => theta == 1.0,
                ContactMethod::Mixed => false,
            }
        {
            return Err(
                "discrete-gradient needs a contact potential: penalty, or nitsche with Θ = 1"
                    .into(),
            );
        }
        if scheme.needs_contact_mass() && sp.massless_contact {
            return Err(format!(
                "{} needs inertia on the contact node (contract §3.2)",
                scheme.family()
            ));
        }
        let (zm, wm) = if scheme == Scheme::ContactStabilizedNewmark {
            // The M-projection onto B u + g ≥ 0: u = ũ + φ M⁻¹q, once per run.
            let mut zm = vec![0.0; m];
            zm[0] = sp.q.0[0];
            zm[1] = sp.q.0[1];
            mass_lu.solve_in_place(&mut zm);
            let wm = p.dot(&zm);
            (zm, wm)
        } else {
            (Vec::new(), 0.0)
        };
        Ok(Self {
            sp,
            scheme,
            tau,
            reduced,
            klin,
            a_lu,
            mass_lu,
            z,
            w,
            p,
            p0,
            factorizations: 2,
            zm,
            wm,
            kinematic,
            extra_iterations: std::cell::Cell::new(0),
            tangential: None,
        })
    }

    /// The space of the chain.
    pub(super) fn space(&self) -> &Bar1dSpace {
        &self.sp
    }

    /// Iterations beyond one per step (see the field).
    pub(super) fn extra_iterations(&self) -> i64 {
        self.extra_iterations.get()
    }

    /// The tangential chain's friction solve of s = s_free + w φ (the force on the node is
    /// φ q = −φ e₀, so f_t = −φ and slip = (s_free − s_ref) + (−w) f_t): the law's exact
    /// case analysis ([`friction`]). Returns (s, φ).
    fn tangential_solve(&self, t: &Tangential, s_free: f64) -> (f64, f64) {
        let s_ref = t.s_ref.get();
        let (f_t, slip, _) = match t.kappa {
            None => friction::solve_tangential(s_free - s_ref, -self.w, t.bound.get()),
            Some(kappa) => {
                friction::solve_tangential_penalized(s_free - s_ref, -self.w, kappa, t.bound.get())
            }
        };
        (s_ref + slip, -f_t)
    }

    /// φ(s) of the state (not the step): σ_C for Nitsche and penalty, the multiplier graph for
    /// the mixed method.
    fn state_law(&self) -> ContactLaw {
        match self.sp.method {
            ContactMethod::Mixed => ContactLaw::Complementarity,
            ContactMethod::Nitsche { gamma0, .. } => ContactLaw::PositivePart {
                k: -1.0 / (gamma0 * self.sp.h),
            },
            ContactMethod::Penalty { gamma0 } => ContactLaw::PositivePart {
                k: -self.sp.penalty_stiffness(gamma0),
            },
        }
    }

    fn step_law(&self, s_prev: f64) -> ContactLaw {
        match (self.scheme, self.state_law()) {
            (Scheme::Hybrid, _) if self.reduced => {
                let k = self.sp.bar.young / self.sp.h;
                ContactLaw::HybridReduced {
                    k,
                    s_prev,
                    offset: -k * self.sp.bar.gap,
                }
            }
            (Scheme::Hybrid, ContactLaw::PositivePart { k }) => {
                ContactLaw::HybridNitsche { k, s_prev }
            }
            (_, law) => law,
        }
    }

    /// Solve the quasi-static equation of the massless contact node for u₀ (t = 0):
    /// K00 u₀ + K01 u₁ = φ q₀ with φ the state law of s = p·u + p₀. Returns φ.
    fn quasi_static_node0(&self, u: &mut [f64]) -> Result<f64, ContactSolveError> {
        let sp = &self.sp;
        let (_, k00, k01) = sp.stiffness_lin.row(0);
        if k00 <= 0.0 {
            return Err(ContactSolveError::NonPositive { w: k00 });
        }
        let base = -k01 * u[1] / k00;
        let s_free = sp.p.0[0] * base + sp.p.0[1] * u[1] + sp.p0;
        let w = sp.p.0[0] * sp.q.0[0] / k00;
        let sol = contact::solve(&self.state_law(), s_free, w)?;
        u[0] = base + sol.phi * sp.q.0[0] / k00;
        Ok(sol.phi)
    }

    /// Contact pressure to report for a state whose step returned `phi`.
    pub(super) fn sigma(&self, u: &[f64], phi: f64) -> f64 {
        if let Scheme::MoreauJean(_) = self.scheme {
            // φ is the impulse p^{n+1} of the step: the force is p/τ (contract §3.2).
            return phi / self.tau;
        }
        if self.sp.method == ContactMethod::Mixed && !self.reduced {
            phi
        } else {
            self.sp.contact_pressure(u)
        }
    }

    /// a = M⁻¹(φ q − K_lin u) on the nodes with inertia (a₀ = 0 on a massless node).
    fn acceleration_into(&self, u: &[f64], phi: f64, a: &mut [f64]) {
        self.sp.stiffness_lin.mul_into(u, a);
        for x in a.iter_mut() {
            *x = -*x;
        }
        a[0] += phi * self.sp.q.0[0];
        a[1] += phi * self.sp.q.0[1];
        if self.sp.massless_contact {
            a[0] = 0.0;
        }
        self.mass_lu.solve_in_place(a);
    }

    /// Solve A y = b, the scalar contact problem, and set y ← y + φ z. Returns (s, φ).
    fn solve_step(
        &self,
        wk: &mut Work,
        law: &ContactLaw,
        p0: f64,
    ) -> Result<(f64, f64), ContactSolveError> {
        self.a_lu.solve_in_place(&mut wk.b);
        std::mem::swap(&mut wk.b, &mut wk.y);
        let s_free = self.p.dot(&wk.y) + p0;
        let sol = match &self.tangential {
            None => contact::solve(law, s_free, self.w)?,
            Some(t) => {
                let (s, phi) = self.tangential_solve(t, s_free);
                contact::ContactSolution { s, phi }
            }
        };
        if sol.phi != 0.0 {
            for (y, z) in wk.y.iter_mut().zip(&self.z) {
                *y += sol.phi * z;
            }
        }
        Ok((sol.s, sol.phi))
    }

    /// One step of a one-step scheme; returns φ of the step.
    pub(super) fn step(&self, st: &mut State, wk: &mut Work) -> Result<f64, ContactSolveError> {
        if self.kinematic || self.scheme.is_comparison() {
            return self.step_comparison(st, wk);
        }
        let tau = self.tau;
        let m = self.sp.m;
        let sp = &self.sp;
        match self.scheme {
            Scheme::Newmark(NewmarkParams { beta, .. }) => {
                let k = tau * tau / 2.0 * (1.0 - 2.0 * beta);
                predict_into(&mut wk.pred, st, tau, k);
                sp.mass.mul_into(&wk.pred, &mut wk.b);
            }
            Scheme::Theta(th) => {
                let k = tau * tau * th.theta * (1.0 - th.theta);
                predict_into(&mut wk.pred, st, tau, k);
                sp.mass.mul_into(&wk.pred, &mut wk.b);
            }
            Scheme::Hybrid => {
                // Incremental form A Δu = τ M vⁿ − (τ²/2) K uⁿ (+ c_f φ q): Δu is computed
                // without the cancellation of u^{n+1} − uⁿ, which the velocity 2Δu/τ − vⁿ would
                // amplify by 2/τ (round-off then shows in energy differences at small τ).
                sp.mass.mul_into(&st.v, &mut wk.b);
                self.klin.mul_into(&st.u, &mut wk.y);
                let c = tau * tau / 2.0;
                for i in 0..m {
                    wk.b[i] = tau * wk.b[i] - c * wk.y[i];
                }
            }
            Scheme::PaoliSchatzman(_) => unreachable!("two-step scheme"),
            _ => unreachable!("contract §3.2 methods step in step_comparison"),
        }
        if sp.massless_contact {
            // Massless row: only the contact force (and, for the hybrid, its own history).
            if self.reduced || !matches!(self.scheme, Scheme::Hybrid) {
                wk.b[0] = 0.0;
            }
        }
        let law = self.step_law(st.s_prev);
        let incremental = matches!(self.scheme, Scheme::Hybrid);
        let p0 = if incremental {
            self.p0 + self.p.dot(&st.u)
        } else {
            self.p0
        };
        let (s, phi) = self.solve_step(wk, &law, p0)?;
        if incremental {
            // wk.y = Δu: velocity first, then u^{n+1} = uⁿ + Δu.
            for i in 0..m {
                st.v[i] = 2.0 * wk.y[i] / tau - st.v[i];
                wk.y[i] += st.u[i];
            }
        }
        if self.reduced {
            wk.y[0] = (-sp.bar.gap).max(wk.y[1]);
        }
        // Velocity and acceleration updates; wk.y holds u^{n+1}.
        match self.scheme {
            Scheme::Newmark(NewmarkParams { beta, gamma }) if beta > 0.0 => {
                let ib = 1.0 / (beta * tau * tau);
                // Slices zipped: no bounds checks, no reloads of the vectors through `st`/`wk`.
                for (((v, a), y), pred) in st.v.iter_mut().zip(&mut st.a).zip(&wk.y).zip(&wk.pred) {
                    let an = (y - pred) * ib;
                    *v += tau * ((1.0 - gamma) * *a + gamma * an);
                    *a = an;
                }
            }
            Scheme::Newmark(NewmarkParams { gamma, .. }) => {
                self.acceleration_into(&wk.y, phi, &mut wk.b);
                for i in 0..m {
                    st.v[i] += tau * ((1.0 - gamma) * st.a[i] + gamma * wk.b[i]);
                    st.a[i] = wk.b[i];
                }
            }
            Scheme::Theta(th) => {
                let it = 1.0 / (tau * th.theta);
                for i in 0..m {
                    let vn = (wk.y[i] - st.u[i] - tau * (1.0 - th.theta) * st.v[i]) * it;
                    let an = (vn - st.v[i] - tau * (1.0 - th.theta) * st.a[i]) * it;
                    st.v[i] = vn;
                    st.a[i] = an;
                }
            }
            Scheme::Hybrid => {} // velocity set above from Δu
            _ => unreachable!(),
        }
        if sp.massless_contact {
            st.v[0] = (wk.y[0] - st.u[0]) / tau;
            st.a[0] = 0.0;
        }
        std::mem::swap(&mut st.u, &mut wk.y);
        st.s_prev = s;
        Ok(phi)
    }

    /// Stiffness k of the contact potential Φ = k/2 [s]₊² (discrete gradient): κ (penalty),
    /// 1/γ_h (Nitsche, Θ = 1).
    fn potential_stiffness(&self) -> f64 {
        match self.sp.method {
            ContactMethod::Penalty { gamma0 } => self.sp.penalty_stiffness(gamma0),
            ContactMethod::Nitsche { gamma0, .. } => 1.0 / (gamma0 * self.sp.h),
            ContactMethod::Mixed => 0.0,
        }
    }

    /// The right-hand side τ M vⁿ − τ²/2 K uⁿ of the increment S Δu (kane, discrete
    /// gradient), into wk.b; wk.y keeps K uⁿ.
    fn increment_rhs(&self, st: &State, wk: &mut Work) {
        let tau = self.tau;
        self.sp.mass.mul_into(&st.v, &mut wk.b);
        self.klin.mul_into(&st.u, &mut wk.y);
        let c = tau * tau / 2.0;
        for (b, ku) in wk.b.iter_mut().zip(&wk.y) {
            *b = tau * *b - c * ku;
        }
    }

    /// One step of a method of contract §3.2 (or kinematic central difference); returns φ.
    ///
    /// Never inlined into [`Self::step`]: inlined, it made the Newmark/θ/hybrid path of `step`
    /// 4× as costly (its loops lost their vectorised form; CN on the 400-run overhead sweep went
    /// from 1.91 to 2.31 s of runs).
    #[inline(never)]
    fn step_comparison(&self, st: &mut State, wk: &mut Work) -> Result<f64, ContactSolveError> {
        let tau = self.tau;
        let s_n = self.p.dot(&st.u) + self.p0;
        let phi = match self.scheme {
            _ if self.kinematic => self.kinematic_step(st),
            Scheme::Kane => {
                // A massless node keeps contract §3.2's formula as written: its row of S Δu is
                // (τ²/4)(K Δu)₀ = −(τ²/2)(K uⁿ)₀ + (τ²/2)φq₀, i.e. (K u^{n+½})₀ = φq₀ — quasi-static
                // at the midpoint, where the trapezoidal rule evaluates K u. Then the step's
                // energy change is φq₀·Δu₀ ≤ 0 for every mass; the row at t^{n+1} instead
                // (the Newmark schemes' choice) let E^h rise by 8 % of E⁰ in one step (mod3,
                // h = ¼, ν = 1).
                self.increment_rhs(st, wk);
                let (_, phi) = self.solve_step(wk, &ContactLaw::Complementarity, s_n)?;
                self.finish_increment(st, wk, tau);
                phi
            }
            Scheme::DiscreteGradient => self.discrete_gradient_step(st, wk, s_n)?,
            Scheme::ContactStabilizedNewmark => self.stabilized_step(st, wk)?,
            Scheme::GeneralizedAlpha(ga) => self.gen_alpha_step(st, wk, ga)?,
            Scheme::MoreauJean(mj) => self.moreau_jean_step(st, wk, s_n, mj)?,
            _ => unreachable!("not a contract §3.2 method"),
        };
        st.s_prev = self.p.dot(&st.u) + self.p0;
        st.phi_prev = phi;
        Ok(phi)
    }

    /// Central difference with `mixed` and a diagonal mass: the contact node put back on the
    /// obstacle (or held by friction) by an impulse on the half-step velocity; returns φ.
    fn kinematic_step(&self, st: &mut State) -> f64 {
        let tau = self.tau;
        let m = self.sp.m;
        let sp = &self.sp;
        // v^{n+½} = vⁿ + τ/2 aⁿ, u^{n+1} = uⁿ + τ v^{n+½}, the contact node put back on
        // the obstacle by an impulse on v^{n+½}; a^{n+1} = M⁻¹(−K u^{n+1}).
        for i in 0..m {
            st.v[i] += 0.5 * tau * st.a[i];
            st.u[i] += tau * st.v[i];
        }
        let (u0, dv, lambda) = match &self.tangential {
            None => crate::time::kinematic_impulse(st.u[0], -sp.bar.gap, sp.mass.diag[0], tau),
            // Kinematic friction: the tangential impulse that stops the node's slip
            // increment, limited by the bound (μ_f times the normal impulse's force).
            Some(t) => {
                let m0 = sp.mass.diag[0];
                let s_ref = t.s_ref.get();
                let (f_t, slip, _) =
                    friction::solve_tangential(st.u[0] - s_ref, tau * tau / m0, t.bound.get());
                (s_ref + slip, tau * f_t / m0, f_t)
            }
        };
        st.u[0] = u0;
        st.v[0] += dv;
        self.acceleration_into(&st.u, 0.0, &mut st.a);
        for i in 0..m {
            st.v[i] += 0.5 * tau * st.a[i];
        }
        // λ ≥ 0 pushes the node up: φ = −λ with the force φ q, q = −e₀.
        -lambda
    }

    /// The discrete gradient's step: kane's increment with φ = −D(sⁿ, s^{n+1}), the difference
    /// quotient of the contact potential (a Newton iteration); returns φ.
    fn discrete_gradient_step(
        &self,
        st: &mut State,
        wk: &mut Work,
        s_n: f64,
    ) -> Result<f64, ContactSolveError> {
        let tau = self.tau;
        self.increment_rhs(st, wk);
        self.a_lu.solve_in_place(&mut wk.b);
        std::mem::swap(&mut wk.b, &mut wk.y);
        let s_free = self.p.dot(&wk.y) + s_n;
        let sol = gradient::solve(self.potential_stiffness(), s_n, s_free, self.w)?;
        self.extra_iterations
            .set(self.extra_iterations.get() + sol.iterations.max(1) as i64 - 1);
        // The force −D p enters as φ q̃ with q = p (penalty; Nitsche with Θ = 1).
        let phi = -sol.d;
        if phi != 0.0 {
            for (y, z) in wk.y.iter_mut().zip(&self.z) {
                *y += phi * z;
            }
        }
        self.finish_increment(st, wk, tau);
        Ok(phi)
    }

    /// Contact-stabilized Newmark's step: the M-projection of the free flight, then kane from
    /// the projected predictor; returns φ.
    fn stabilized_step(&self, st: &mut State, wk: &mut Work) -> Result<f64, ContactSolveError> {
        let tau = self.tau;
        let m = self.sp.m;
        // Predictor: the M-projection of uⁿ + τvⁿ onto the admissible set.
        for i in 0..m {
            wk.pred[i] = st.u[i] + tau * st.v[i];
        }
        let s_free = self.p.dot(&wk.pred) + self.p0;
        // The admissible set constrains the normal rows only: a tangential chain's
        // predictor is the free flight.
        let pred = match self.tangential {
            None => contact::solve(&ContactLaw::Complementarity, s_free, self.wm)?,
            Some(_) => contact::ContactSolution {
                s: s_free,
                phi: 0.0,
            },
        };
        self.extra_iterations.set(self.extra_iterations.get() + 1);
        if pred.phi != 0.0 {
            for (x, z) in wk.pred.iter_mut().zip(&self.zm) {
                *x += pred.phi * z;
            }
        }
        // kane from u^pred: S Δ = −τ²/4 K(uⁿ + u^pred) + τ²/2 φ q, Δ = u^{n+1} − u^pred.
        for i in 0..m {
            wk.y[i] = st.u[i] + wk.pred[i];
        }
        self.klin.mul_into(&wk.y, &mut wk.b);
        let c = 0.25 * tau * tau;
        for b in wk.b.iter_mut() {
            *b *= -c;
        }
        let s_pred = self.p.dot(&wk.pred) + self.p0;
        let (_, phi) = self.solve_step(wk, &ContactLaw::Complementarity, s_pred)?;
        for i in 0..m {
            st.v[i] += 2.0 * wk.y[i] / tau;
            st.u[i] = wk.pred[i] + wk.y[i];
        }
        Ok(phi)
    }

    /// Generalized-α's (and HHT's) step at t^{n+1−α}, carrying the previous contact force;
    /// returns φ^{n+1}.
    fn gen_alpha_step(
        &self,
        st: &mut State,
        wk: &mut Work,
        ga: GeneralizedAlphaParams,
    ) -> Result<f64, ContactSolveError> {
        let GeneralizedAlphaParams { beta, gamma, .. } = ga;
        let tau = self.tau;
        let m = self.sp.m;
        let sp = &self.sp;
        // ũ = uⁿ + τvⁿ + τ²(½ − β)aⁿ, a^{n+1} = (u^{n+1} − ũ)/(βτ²); the equation at
        // t^{n+1−α} times βτ²/(1−α_m):
        // (M + cK)u^{n+1} = M(ũ − κ_m aⁿ) − κ_f K uⁿ + κ_f φⁿ q + c φ^{n+1} q.
        let bt2 = beta * tau * tau;
        let kp = tau * tau * (0.5 - beta);
        let (km, kf) = ga.history_coefficients(tau);
        gen_alpha_rhs_into(
            &sp.mass,
            &self.klin,
            st,
            (tau, kp, km, kf),
            (&mut wk.pred, &mut wk.y, &mut wk.b),
        );
        wk.b[0] += kf * st.phi_prev * sp.q.0[0];
        wk.b[1] += kf * st.phi_prev * sp.q.0[1];
        let (_, phi) = self.solve_step(wk, &self.state_law(), self.p0)?;
        let ib = 1.0 / bt2;
        for i in 0..m {
            let an = (wk.y[i] - wk.pred[i]) * ib;
            st.v[i] += tau * ((1.0 - gamma) * st.a[i] + gamma * an);
            st.a[i] = an;
        }
        std::mem::swap(&mut st.u, &mut wk.y);
        Ok(phi)
    }

    /// Moreau–Jean's step on Δv, the contact row active when the predicted gap closes;
    /// returns the impulse p^{n+1}.
    fn moreau_jean_step(
        &self,
        st: &mut State,
        wk: &mut Work,
        s_n: f64,
        MoreauJeanParams { theta, restitution }: MoreauJeanParams,
    ) -> Result<f64, ContactSolveError> {
        let tau = self.tau;
        let m = self.sp.m;
        // (M + θ²τ²K)Δv = −τK(uⁿ + θτvⁿ) + Bᵀp; the contact row is active when its
        // predicted gap (Buⁿ + g) + ½τ Bvⁿ closes, and then 0 ≤ p ⊥ Bv^{n+1} + e Bvⁿ ≥ 0.
        for i in 0..m {
            wk.y[i] = st.u[i] + theta * tau * st.v[i];
        }
        self.klin.mul_into(&wk.y, &mut wk.b);
        for b in wk.b.iter_mut() {
            *b *= -tau;
        }
        let vn = self.p.dot(&st.v);
        let law = if s_n + 0.5 * tau * vn <= 0.0 {
            ContactLaw::Complementarity
        } else {
            ContactLaw::PositivePart { k: 0.0 }
        };
        let (_, phi) = self.solve_step(wk, &law, (1.0 + restitution) * vn)?;
        for i in 0..m {
            st.u[i] += tau * (st.v[i] + theta * wk.y[i]);
            st.v[i] += wk.y[i];
        }
        Ok(phi)
    }

    /// wk.y = Δu of an incremental step: v^{n+1} = 2Δu/τ − vⁿ, u^{n+1} = uⁿ + Δu (a massless
    /// node's velocity is its difference quotient).
    fn finish_increment(&self, st: &mut State, wk: &Work, tau: f64) {
        for ((u, v), d) in st.u.iter_mut().zip(st.v.iter_mut()).zip(&wk.y) {
            *v = 2.0 * d / tau - *v;
            *u += d;
        }
        if self.sp.massless_contact {
            st.v[0] = wk.y[0] / tau;
            st.a[0] = 0.0;
        }
    }
}

/// Build the initial state: interpolated u⁰ (perturbed for ensembles), v⁰ the bar's uniform
/// initial velocity (0 but for the flying bar, contract §1.4), a massless
/// node at its quasi-static value (or left at the interpolant, `contact_init = interpolant`),
/// a⁰ from the equation at t = 0 on the free nodes. Returns the state and σ_C⁰.
pub(super) fn initial_state(
    eng: &Engine,
    cfg: &Bar1dConfig,
) -> Result<(State, f64), ContactSolveError> {
    let sp = &eng.sp;
    let m = sp.m;
    let mut u: Vec<f64> = (0..m)
        .map(|i| sp.bar.initial_displacement(i as f64 * sp.h))
        .collect();
    if let Some((delta, seed)) = cfg.perturbation {
        let mut rng = fastrand::Rng::with_seed(seed);
        for x in u.iter_mut() {
            *x *= 1.0 + delta * (2.0 * rng.f64() - 1.0);
        }
    }
    let quasi_static = sp.massless_contact && cfg.contact_init == ContactInit::Consistent;
    let phi = if quasi_static {
        eng.quasi_static_node0(&mut u)?
    } else {
        // The contact force of the state itself: σ_C(u) for Nitsche and penalty; for the
        // multiplier of a node not yet in contact (u₀ = a > −g), zero.
        match eng.state_law() {
            ContactLaw::PositivePart { k } => k * (sp.p.dot(&u) + sp.p0).max(0.0),
            _ => 0.0,
        }
    };
    // a⁰ from this state's own equation, free nodes only. For the interpolant start of the
    // default bar that is a⁰ = 0 (u⁰ is affine, K u⁰ vanishes on the free rows): what the
    // reference implementations did — computing a⁰ from the quasi-static state instead gives
    // E(T)/E⁰ = 0.98516 for zero-contact + CN at h = 0.01, τ = 0.015, not their 0.97845.
    let mut a = vec![0.0; m];
    eng.acceleration_into(&u, phi, &mut a);
    let s_prev = eng.p.dot(&u) + eng.p0;
    // The multiplier of the mixed method is reported as such, except on a quasi-static node,
    // where the contact element's stress is the exact pressure (its equation holds).
    let sigma = if sp.method == ContactMethod::Mixed && !quasi_static {
        phi
    } else {
        sp.contact_pressure(&u)
    };
    Ok((
        State {
            u,
            v: (0..m)
                .map(|i| sp.bar.initial_velocity(i as f64 * sp.h))
                .collect(),
            a,
            s_prev,
            phi_prev: phi,
        },
        sigma,
    ))
}

/// Observation helper shared by both loops.
struct Recorder<'a> {
    sp: &'a Bar1dSpace,
    /// Whether σ_C is a function of the state (else a multiplier).
    state_pressure: bool,
    /// (u₀, u₁) of the previous observation.
    prev01: Option<[f64; 2]>,
    exact: Option<BarExact>,
    tau: f64,
    obs: Observer,
    /// The mean velocity of the last observed state (free end: the flying bar's exit speed).
    exit_velocity: Option<f64>,
}

impl Recorder<'_> {
    /// Observe step `step`. The midpoint pressure σ_C(u^{n−½}) is evaluated on the midpoint
    /// state where the pressure is a function of the state (Nitsche, penalty, a quasi-static
    /// contact node); a multiplier of a node with mass is averaged by the observer instead.
    fn record(&mut self, step: usize, u: &[f64], v: &[f64], sigma: f64) -> Result<(), Divergence> {
        let now = [u[0], u[1]];
        let sigma_mid = match self.prev01.replace(now) {
            Some(p) if self.state_pressure => Some(
                self.sp
                    .contact_pressure(&[0.5 * (p[0] + now[0]), 0.5 * (p[1] + now[1])]),
            ),
            _ => None,
        };
        let t = step as f64 * self.tau;
        if self.sp.bar.free_end {
            self.exit_velocity = Some(self.sp.mean_velocity(v));
        }
        let (energy, energy_theta) = self.sp.energies(u, v);
        let exact = self.exact.map(|ex| {
            let (l2_sq, h1_semi_sq) = ex.error_sq(u, self.sp.h, t);
            ExactValues {
                u_contact: ex.u(0.0, t),
                sigma_contact: ex.contact_stress(t),
                sigma_contact_mid: (step > 0).then(|| ex.contact_stress(t - 0.5 * self.tau)),
                energy: ex.energy(),
                l2_sq,
                h1_semi_sq,
            }
        });
        self.obs.observe(
            StepValues {
                step,
                t,
                u_contact: u[0],
                v_contact: v[0],
                sigma_contact: sigma,
                sigma_mid,
                energy,
                energy_theta,
                // Not stored in 1D: contract §5 lists no energy parts for the bar, and two more
                // float columns would add ≈ 60 % to the series' bytes and writer time (issue 12).
                energy_kinetic: None,
                energy_elastic: None,
                energy_gravity: None,
                u_lowest: None,
                // u_n = −u₀ at the contact node, non-penetration u₀ ≥ −g (contract §1.1).
                penetration: Some((-u[0] - self.sp.bar.gap).max(0.0)),
            },
            exact,
        )
    }
}

/// How often the wall clock is read for the timeout (a read costs ~20 ns; a step ~m·10 ns).
const CLOCK_EVERY: usize = 64;

/// Run one bar1d simulation.
pub fn simulate(cfg: &Bar1dConfig, opts: &RunOptions) -> Outcome {
    let start = Instant::now();
    let mut metrics = Metrics {
        dofs: cfg.grid.elements as i64,
        length_scale: Some(cfg.bar.length),
        ..Metrics::default()
    };
    let sp = match Bar1dSpace::new(cfg.bar, cfg.grid.elements, &cfg.grid.mass, cfg.grid.method) {
        Ok(sp) => sp,
        Err(e) => return failed(Status::Invalid, e.to_string(), metrics),
    };
    metrics.mass_total = Some(sp.mass_total);
    if let Some((status, msg)) = opts.setup_stop(start, "the operators") {
        return failed(status, msg, metrics);
    }
    let tau = cfg.grid.dt;
    let (eng, starter) = match engines(&sp, cfg.grid.scheme, tau) {
        Ok(x) => x,
        Err(e) => return failed(Status::SolverFailed, e, metrics),
    };
    metrics.factorizations = eng.factorizations + starter.as_ref().map_or(0, |s| s.factorizations);
    if let Some((status, msg)) = opts.setup_stop(start, "the factorisation") {
        return failed(status, msg, metrics);
    }
    let m = sp.m;
    let mut wk = Work {
        b: vec![0.0; m],
        y: vec![0.0; m],
        pred: vec![0.0; m],
    };
    let mut rec = Recorder {
        sp: &eng.sp,
        state_pressure: eng.sp.method != ContactMethod::Mixed || eng.sp.massless_contact,
        prev01: None,
        exact: cfg.bar.exact(),
        tau,
        obs: Observer::new(tau, opts.series_every, cfg.grid.steps),
        exit_velocity: None,
    };
    let (mut st, sigma0) = match initial_state(&eng, cfg) {
        Ok(x) => x,
        Err(e) => {
            metrics.solver_failures = 1;
            return failed(
                Status::SolverFailed,
                format!("initial state (t = 0): {e}"),
                metrics,
            );
        }
    };
    let steps = cfg.grid.steps;
    let end = time_loop(
        opts,
        start,
        (CLOCK_EVERY, tau, steps),
        &mut metrics,
        |clock, metrics| {
            rec.record(0, &st.u, &st.v, sigma0)
                .map_err(Stop::Diverged)?;
            let mut run = LoopParts {
                st: &mut st,
                wk: &mut wk,
                rec: &mut rec,
                clock,
                metrics,
            };
            match &starter {
                None => run.one_step(&eng, steps),
                Some(first) => run.paoli_schatzman(&eng, first, steps),
            }
        },
    );
    metrics.iterations += eng.extra_iterations.get();
    rec.obs.finish(&mut metrics, end.status == Status::Ok);
    metrics.exit_velocity = rec.exit_velocity;
    finished(end.status, end.message, metrics, &mut rec.obs)
}

/// The run's engine and, for Paoli–Schatzman, the Newmark(β, ½) engine of its first step.
fn engines(sp: &Bar1dSpace, scheme: Scheme, tau: f64) -> Result<(Engine, Option<Engine>), String> {
    match scheme {
        Scheme::PaoliSchatzman(ps) => {
            let nm = Scheme::Newmark(NewmarkParams {
                beta: ps.beta,
                gamma: 0.5,
            });
            match (
                Engine::new(sp.clone(), scheme, tau),
                Engine::new(sp.clone(), nm, tau),
            ) {
                (Ok(a), Ok(b)) => Ok((a, Some(b))),
                (Err(e), _) | (_, Err(e)) => Err(e),
            }
        }
        _ => Engine::new(sp.clone(), scheme, tau).map(|e| (e, None)),
    }
}

/// What the time loop steps and observes, once the initial state is recorded.
struct LoopParts<'l, 'r, 'c, 'o> {
    st: &'l mut State,
    wk: &'l mut Work,
    rec: &'l mut Recorder<'r>,
    clock: &'l mut Clock<'c>,
    metrics: &'o mut Metrics,
}

impl LoopParts<'_, '_, '_, '_> {
    /// Steps 1…`steps` of a one-step scheme.
    fn one_step(&mut self, eng: &Engine, steps: usize) -> LoopEnd {
        let (st, rec) = (&mut *self.st, &mut *self.rec);
        for n in 1..=steps {
            let phi = eng.step(st, self.wk).map_err(|e| Stop::Solver(n, e))?;
            self.metrics.iterations += 1;
            let sigma = eng.sigma(&st.u, phi);
            self.clock
                .observe(n, || rec.record(n, &st.u, &st.v, sigma))?;
            self.clock.completed(n)?;
        }
        Ok(())
    }

    /// Paoli–Schatzman's two-step loop: U¹ from Newmark(β, ½) (`first`); then U^{n+1} from
    /// (U^n, U^{n−1}) and v^n centred, step n recorded once U^{n+1} is known.
    fn paoli_schatzman(&mut self, eng: &Engine, first: &Engine, steps: usize) -> LoopEnd {
        let (st, wk, rec) = (&mut *self.st, &mut *self.wk, &mut *self.rec);
        let m = eng.sp.m;
        let tau = eng.tau;
        let mut prev = st.u.clone();
        first.step(st, wk).map_err(|e| Stop::Solver(1, e))?;
        self.metrics.iterations += 1;
        let mut vn = vec![0.0; m];
        let Scheme::PaoliSchatzman(ps) = eng.scheme else {
            unreachable!()
        };
        let e = ps.restitution;
        for n in 1..=steps {
            // b = M(2Uⁿ − Uⁿ⁻¹) − τ²K((1−2β)Uⁿ + βUⁿ⁻¹)
            for i in 0..m {
                wk.pred[i] = 2.0 * st.u[i] - prev[i];
                vn[i] = (1.0 - 2.0 * ps.beta) * st.u[i] + ps.beta * prev[i];
            }
            eng.sp.mass.mul_into(&wk.pred, &mut wk.b);
            eng.klin.mul_into(&vn, &mut wk.y);
            for i in 0..m {
                wk.b[i] -= tau * tau * wk.y[i];
            }
            if eng.sp.massless_contact {
                wk.b[0] = 0.0;
            }
            let p0 = e * prev[0] / (1.0 + e) + eng.sp.bar.gap;
            let (_, lambda) = eng
                .solve_step(wk, &ContactLaw::Complementarity, p0)
                .map_err(|err| Stop::Solver(n, err))?;
            self.metrics.iterations += 1;
            // wk.y = U^{n+1}; v^n = (U^{n+1} − U^{n−1}) / 2τ
            for i in 0..m {
                vn[i] = (wk.y[i] - prev[i]) / (2.0 * tau);
            }
            self.clock
                .observe(n, || rec.record(n, &st.u, &vn, lambda))?;
            std::mem::swap(&mut prev, &mut st.u);
            std::mem::swap(&mut st.u, &mut wk.y);
            self.clock.completed(n)?;
        }
        Ok(())
    }
}
