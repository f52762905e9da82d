//! Time schemes as data (SPEC §3): one engine ([`crate::run`]) runs them all.
//!
//! Unknowns u^n, v^n, a^n; x^{n+θ} = (1−θ)x^n + θx^{n+1}. Every implicit scheme here has a
//! constant iteration matrix A = M + c K_lin (c = βτ², θ²τ², τ²/4) factored once per run:
//! - Newmark(β, γ): u^{n+1} = u^n + τv^n + τ²/2((1−2β)a^n + 2βa^{n+1}),
//!   v^{n+1} = v^n + τ((1−γ)a^n + γa^{n+1}), equation at t^{n+1};
//! - θ-scheme: u^{n+1} = u^n + τv^{n+θ}, v^{n+1} = v^n + τa^{n+θ}, equation at t^{n+1};
//! - Paoli–Schatzman(β, e): two-step, contact on (u₀^{n+1} + e u₀^{n−1})/(1+e), 000 (4.5);
//! - hybrid: midpoint linear part, the contact term switched between midpoint and
//!   Crank–Nicolson on the sign of the contact argument at t^n (003 (10)–(11), 000 §5).
//!
//! β = 0 (central difference) is explicit and conditionally stable; the planner refuses a step
//! above its CFL limit.

/// Newmark parameters (β, γ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewmarkParams {
    pub beta: f64,
    pub gamma: f64,
}

impl NewmarkParams {
    /// Trapezoidal rule: energy conserving without contact, order 2.
    pub fn crank_nicolson() -> Self {
        Self {
            beta: 0.25,
            gamma: 0.5,
        }
    }
    /// The most dissipative Newmark variant studied in 003 §4.1.2a (order 1).
    pub fn dissipative() -> Self {
        Self {
            beta: 0.5,
            gamma: 1.0,
        }
    }
    /// Explicit central difference.
    pub fn central_difference() -> Self {
        Self {
            beta: 0.0,
            gamma: 0.5,
        }
    }
}

/// θ-scheme parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThetaParams {
    pub theta: f64,
}

impl ThetaParams {
    pub fn backward_euler() -> Self {
        Self { theta: 1.0 }
    }
}

/// Paoli–Schatzman parameters (β, restitution e).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaoliSchatzmanParams {
    pub beta: f64,
    pub restitution: f64,
}

impl PaoliSchatzmanParams {
    /// The setting of 000 §4: (β, e) = (¼, 1).
    pub fn paper() -> Self {
        Self {
            beta: 0.25,
            restitution: 1.0,
        }
    }
}

/// A time scheme with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    Newmark(NewmarkParams),
    Theta(ThetaParams),
    PaoliSchatzman(PaoliSchatzmanParams),
    Hybrid,
}

impl Scheme {
    /// Canonical family name (the `scheme` column).
    pub fn family(&self) -> &'static str {
        match self {
            Scheme::Newmark(_) => "newmark",
            Scheme::Theta(_) => "theta",
            Scheme::PaoliSchatzman(_) => "paoli-schatzman",
            Scheme::Hybrid => "hybrid",
        }
    }

    /// Human label: the preset's name when the parameters are a preset's.
    pub fn label(&self) -> String {
        match *self {
            Scheme::Newmark(p) if p == NewmarkParams::crank_nicolson() => "crank-nicolson".into(),
            Scheme::Newmark(p) if p == NewmarkParams::dissipative() => "newmark-dissipative".into(),
            Scheme::Newmark(p) if p == NewmarkParams::central_difference() => {
                "central-difference".into()
            }
            Scheme::Newmark(p) => format!("newmark(β={},γ={})", p.beta, p.gamma),
            Scheme::Theta(p) if p == ThetaParams::backward_euler() => "backward-euler".into(),
            Scheme::Theta(p) => format!("theta(θ={})", p.theta),
            Scheme::PaoliSchatzman(p) => {
                format!("paoli-schatzman(β={},e={})", p.beta, p.restitution)
            }
            Scheme::Hybrid => "hybrid".into(),
        }
    }

    /// Whether the step is explicit (no contact force in the displacement update).
    pub fn is_explicit(&self) -> bool {
        match self {
            Scheme::Newmark(p) => p.beta == 0.0,
            Scheme::Theta(p) => p.theta == 0.0,
            Scheme::PaoliSchatzman(p) => p.beta == 0.0,
            Scheme::Hybrid => false,
        }
    }

    /// Stiffness coefficient c of A = M + c K and force coefficient c_f of the contact force in
    /// the right-hand side.
    pub fn coefficients(&self, tau: f64) -> (f64, f64) {
        let t2 = tau * tau;
        match *self {
            Scheme::Newmark(p) => (p.beta * t2, p.beta * t2),
            Scheme::Theta(p) => (p.theta * p.theta * t2, p.theta * p.theta * t2),
            Scheme::PaoliSchatzman(p) => (p.beta * t2, t2),
            Scheme::Hybrid => (t2 / 4.0, t2 / 2.0),
        }
    }

    /// Stability bound of an explicit scheme on τ·ω_max (ω_max² the largest eigenvalue of
    /// M⁻¹K): central difference (β = 0, γ = ½) needs τω ≤ 2, generally τω ≤ 1/sqrt(γ/2);
    /// forward Euler (θ = 0) is never stable for an undamped system (bound 0).
    pub fn explicit_stability_limit(&self) -> Option<f64> {
        match self {
            Scheme::Newmark(p) if p.beta == 0.0 => Some(1.0 / (p.gamma / 2.0).max(1e-300).sqrt()),
            Scheme::PaoliSchatzman(p) if p.beta == 0.0 => Some(2.0),
            Scheme::Theta(p) if p.theta == 0.0 => Some(0.0),
            _ => None,
        }
    }
}
