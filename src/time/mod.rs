//! Time schemes as data (contract §3): one engine ([`crate::run`]) runs them all.
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
//! above its CFL limit. With `mixed` and a diagonal mass (`lumped`) it enforces contact
//! kinematically (Taylor–Flanagan 1989): a dof that would penetrate is put on the obstacle by
//! an impulse on its half-step velocity ([`kinematic_impulse`]).
//!
//! The methods of the comparison literature (contract §3.2), with S = M + τ²/4 K:
//! - `kane` (Kane–Repetto–Ortiz–Marsden 1999): the trapezoidal rule with the contact force
//!   fully implicit, S Δu = τMvⁿ − τ²/2 Kuⁿ + τ²/2 Bᵀλ^{n+1}, v^{n+1} = 2Δu/τ − vⁿ: the
//!   contact force λ^{n+1} does the work λ·B Δu ≤ 0 over the step, so E^h never increases;
//! - `contact-stabilized-newmark` (Deuflhard–Krause–Ertel 2008): the same step from the
//!   M-projection u^pred of the free flight uⁿ + τvⁿ onto the admissible set;
//! - `generalized-alpha` (Chung–Hulbert 1993) and its preset `hht` ([`GeneralizedAlphaParams`]):
//!   M a^{n+1−α_m} + K u^{n+1−α_f} = (1−α_f) f_c^{n+1} + α_f f_c^n with Newmark's updates;
//! - `moreau-jean` (Jean 1999): velocity-level θ-scheme with impulses, on the contact rows
//!   whose predicted gap closes ([`MoreauJeanParams`]);
//! - `discrete-gradient` (Gonzalez 1996): the midpoint rule with the contact force the
//!   difference quotient of the contact potential ([`crate::contact::gradient`]), so
//!   E^h + Φ (penalty) and E_Θ (Nitsche, Θ = 1) are conserved exactly.
//!
//! Every per-step formula acts on the contact rows through a scalar (1D: the contact node;
//! a one-dof oscillator is the same equation with 1×1 matrices), so the coefficients below are
//! plain functions of (τ, parameters), reused by any engine.

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

/// How a generalized-α parameter set was given (the preset it came from names the run).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlphaPreset {
    /// Chung–Hulbert with spectral radius at infinity ρ∞ (`rho_inf`).
    RhoInf(f64),
    /// Hilber–Hughes–Taylor with α (`hht_alpha`).
    Hht(f64),
}

/// Generalized-α parameters (contract §3.2): M a^{n+1−α_m} + K u^{n+1−α_f} = F^{n+1−α_f} +
/// (1−α_f) f_c^{n+1} + α_f f_c^n, x^{n+1−α} = (1−α)x^{n+1} + αx^n, Newmark's (β, γ) updates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlphaParams {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
    pub preset: AlphaPreset,
}

impl GeneralizedAlphaParams {
    /// Chung–Hulbert 1993: α_m = (2ρ∞ − 1)/(ρ∞ + 1), α_f = ρ∞/(ρ∞ + 1), γ = ½ − α_m + α_f,
    /// β = ¼(1 − α_m + α_f)². ρ∞ = 1 gives α_m = α_f = ½, γ = ½, β = ¼: the average of the
    /// equations at tⁿ and t^{n+1}, i.e. Crank–Nicolson when the equation held at tⁿ.
    pub fn from_rho_inf(rho_inf: f64) -> Self {
        let alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);
        let alpha_f = rho_inf / (rho_inf + 1.0);
        let d = 1.0 - alpha_m + alpha_f;
        Self {
            alpha_m,
            alpha_f,
            beta: 0.25 * d * d,
            gamma: 0.5 - alpha_m + alpha_f,
            preset: AlphaPreset::RhoInf(rho_inf),
        }
    }

    /// Hilber–Hughes–Taylor: α_m = 0, α_f = α, γ = ½ + α, β = ¼(1 + α)², α ∈ [0, ⅓].
    pub fn hht(alpha: f64) -> Self {
        Self {
            alpha_m: 0.0,
            alpha_f: alpha,
            beta: 0.25 * (1.0 + alpha) * (1.0 + alpha),
            gamma: 0.5 + alpha,
            preset: AlphaPreset::Hht(alpha),
        }
    }

    /// c of the step matrix M + cK: multiplying the equation at t^{n+1−α} by βτ²/(1−α_m)
    /// (a^{n+1} = (u^{n+1} − ũ)/(βτ²)) leaves M u^{n+1} + (1−α_f)βτ²/(1−α_m) K u^{n+1}; the new
    /// contact force enters with the same coefficient.
    pub fn stiffness_coefficient(&self, tau: f64) -> f64 {
        (1.0 - self.alpha_f) * self.beta * tau * tau / (1.0 - self.alpha_m)
    }

    /// (κ_m, κ_f) = (α_m, α_f)·βτ²/(1−α_m): the weights of the previous step's acceleration
    /// and of its elastic and contact forces in the same scaled equation,
    /// (M + cK)u^{n+1} = M(ũ − κ_m aⁿ) − κ_f K uⁿ + κ_f φⁿ q + c φ^{n+1} q.
    pub fn history_coefficients(&self, tau: f64) -> (f64, f64) {
        let bt2 = self.beta * tau * tau;
        (
            self.alpha_m * bt2 / (1.0 - self.alpha_m),
            self.alpha_f * bt2 / (1.0 - self.alpha_m),
        )
    }
}

/// Moreau–Jean parameters (contract §3.2): θ (`theta_scheme`, ½ … 1) and Newton's restitution e.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoreauJeanParams {
    pub theta: f64,
    pub restitution: f64,
}

impl MoreauJeanParams {
    /// θ = ½, e = 0: E^h never increases, energy is lost at impacts only.
    pub fn midpoint() -> Self {
        Self {
            theta: 0.5,
            restitution: 0.0,
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
    /// Trapezoidal rule with the contact force fully implicit (contract §3.2 `kane`).
    Kane,
    /// `kane` from the M-projected free flight (contract §3.2 `contact-stabilized-newmark`).
    ContactStabilizedNewmark,
    GeneralizedAlpha(GeneralizedAlphaParams),
    MoreauJean(MoreauJeanParams),
    /// Midpoint rule with the contact potential's difference quotient (contract §3.2).
    DiscreteGradient,
}

impl Scheme {
    /// Canonical family name (the `scheme` column).
    pub fn family(&self) -> &'static str {
        match self {
            Scheme::Newmark(_) => "newmark",
            Scheme::Theta(_) => "theta",
            Scheme::PaoliSchatzman(_) => "paoli-schatzman",
            Scheme::Hybrid => "hybrid",
            Scheme::Kane => "kane",
            Scheme::ContactStabilizedNewmark => "contact-stabilized-newmark",
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams {
                preset: AlphaPreset::Hht(_),
                ..
            }) => "hht",
            Scheme::GeneralizedAlpha(_) => "generalized-alpha",
            Scheme::MoreauJean(_) => "moreau-jean",
            Scheme::DiscreteGradient => "discrete-gradient",
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
            Scheme::Kane => "kane".into(),
            Scheme::ContactStabilizedNewmark => "contact-stabilized-newmark".into(),
            Scheme::GeneralizedAlpha(p) => match p.preset {
                AlphaPreset::RhoInf(r) => format!("generalized-alpha(ρ∞={r})"),
                AlphaPreset::Hht(a) => format!("hht(α={a})"),
            },
            Scheme::MoreauJean(p) => format!("moreau-jean(θ={},e={})", p.theta, p.restitution),
            Scheme::DiscreteGradient => "discrete-gradient".into(),
        }
    }

    /// Whether the step is explicit (no contact force in the displacement update).
    pub fn is_explicit(&self) -> bool {
        match self {
            Scheme::Newmark(p) => p.beta == 0.0,
            Scheme::Theta(p) => p.theta == 0.0,
            Scheme::PaoliSchatzman(p) => p.beta == 0.0,
            Scheme::Hybrid
            | Scheme::Kane
            | Scheme::ContactStabilizedNewmark
            | Scheme::GeneralizedAlpha(_)
            | Scheme::MoreauJean(_)
            | Scheme::DiscreteGradient => false,
        }
    }

    /// Whether the scheme is one of the methods of contract §3.2 (the comparison literature).
    pub fn is_comparison(&self) -> bool {
        matches!(
            self,
            Scheme::Kane
                | Scheme::ContactStabilizedNewmark
                | Scheme::GeneralizedAlpha(_)
                | Scheme::MoreauJean(_)
                | Scheme::DiscreteGradient
        )
    }

    /// Whether the scheme needs inertia on every contact dof (contract §3.2: the predictor of
    /// contact-stabilized Newmark is an M-projection, generalized-α and Moreau–Jean step the
    /// contact dof's acceleration or velocity).
    pub fn needs_contact_mass(&self) -> bool {
        matches!(
            self,
            Scheme::ContactStabilizedNewmark | Scheme::GeneralizedAlpha(_) | Scheme::MoreauJean(_)
        )
    }

    /// Stiffness coefficient c of A = M + c K and force coefficient c_f of the contact force in
    /// the right-hand side.
    pub fn coefficients(&self, tau: f64) -> (f64, f64) {
        let t2 = tau * tau;
        match *self {
            Scheme::Newmark(p) => (p.beta * t2, p.beta * t2),
            Scheme::Theta(p) => (p.theta * p.theta * t2, p.theta * p.theta * t2),
            Scheme::PaoliSchatzman(p) => (p.beta * t2, t2),
            Scheme::Hybrid | Scheme::Kane | Scheme::ContactStabilizedNewmark => {
                (t2 / 4.0, t2 / 2.0)
            }
            Scheme::DiscreteGradient => (t2 / 4.0, t2 / 2.0),
            Scheme::GeneralizedAlpha(p) => {
                let c = p.stiffness_coefficient(tau);
                (c, c)
            }
            // Unknown Δv: (M + θ²τ²K)Δv = … + Bᵀp, the impulse entering with coefficient 1.
            Scheme::MoreauJean(p) => (p.theta * p.theta * t2, 1.0),
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

/// Kinematic contact of the explicit central difference (Taylor–Flanagan 1989; the
/// forward-increment multiplier of Carpenter–Taylor–Katona 1991 for a diagonal mass): a dof of
/// mass `mass` whose predicted position `u_pred` would pass the obstacle `lower` is put on it,
/// its half-step velocity changed by Δv = (lower − u_pred)/τ. Returns (u^{n+1}, Δv, λ^{n+1})
/// with λ = m Δv/τ ≥ 0 the contact force (zero when the dof stays admissible).
pub fn kinematic_impulse(u_pred: f64, lower: f64, mass: f64, tau: f64) -> (f64, f64, f64) {
    if u_pred >= lower {
        return (u_pred, 0.0, 0.0);
    }
    let dv = (lower - u_pred) / tau;
    (lower, dv, mass * dv / tau)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generalized_alpha_presets_follow_their_definitions() {
        // ρ∞ = 1: α_m = α_f = ½, (β, γ) = (¼, ½), c = ½·¼τ²/½ = τ²/4 (CN's step matrix); exact
        // binary fractions, so equality.
        let p = GeneralizedAlphaParams::from_rho_inf(1.0);
        assert_eq!(
            (p.alpha_m, p.alpha_f, p.beta, p.gamma),
            (0.5, 0.5, 0.25, 0.5)
        );
        assert_eq!(p.stiffness_coefficient(2.0), 1.0);
        // ρ∞ = ½: α_m = 0, α_f = ⅓, γ = ⅚, β = ¼(4/3)² = 4/9 (a few ulps of round-off).
        let p = GeneralizedAlphaParams::from_rho_inf(0.5);
        assert!(p.alpha_m.abs() < 1e-16 && (p.alpha_f - 1.0 / 3.0).abs() < 1e-16);
        assert!((p.gamma - 5.0 / 6.0).abs() < 1e-15 && (p.beta - 4.0 / 9.0).abs() < 1e-15);
        let h = GeneralizedAlphaParams::hht(0.1);
        assert!((h.beta - 0.3025).abs() < 1e-15 && (h.gamma - 0.6).abs() < 1e-15);
        assert_eq!(Scheme::GeneralizedAlpha(h).family(), "hht");
        assert_eq!(Scheme::GeneralizedAlpha(p).family(), "generalized-alpha");
    }

    #[test]
    fn kinematic_impulse_puts_the_dof_on_the_obstacle() {
        assert_eq!(kinematic_impulse(0.2, 0.0, 2.0, 0.5), (0.2, 0.0, 0.0));
        let (u, dv, lam) = kinematic_impulse(-0.25, 0.0, 2.0, 0.5);
        // Δv = 0.25/0.5 = 0.5, λ = 2·0.5/0.5 = 2: binary fractions, exact.
        assert_eq!((u, dv, lam), (0.0, 0.5, 2.0));
    }
}
