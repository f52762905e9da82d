//! Space discretisation: how the body is meshed, which mass matrix it carries and how contact
//! enters the semi-discrete system M ü + K u + f_c(u) = F (contract §2).
//!
//! The contact treatments are data: [`ContactMethod`] names the method and its parameters; the
//! scene-specific module turns it into the linear operators (K_Θ for Nitsche) and the contact
//! *direction* vectors p (the argument s = pᵀu + p₀ of the nonlinearity) and q (where the contact
//! force acts), which the time schemes and the condensed contact solve use without knowing which
//! method produced them.

pub mod bar1d;
pub mod cg;
pub mod fe;
pub mod linalg;
pub mod step_solver;
pub mod tridiag;

pub use bar1d::Bar1dSpace;
pub use tridiag::{Tridiag, TridiagLu};

/// How the Signorini condition is imposed (contract §2.1, §2.3, §2.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactMethod {
    /// Nodal Lagrange multiplier: 0 ≤ u₀ + g ⊥ λ ≤ 0.
    Mixed,
    /// Nitsche's method with parameters Θ and γ₀ (γ_h = γ₀ h).
    Nitsche { theta: f64, gamma0: f64 },
    /// Normal penalty with stiffness κ = E γ₀ / h.
    Penalty { gamma0: f64 },
}

impl ContactMethod {
    pub fn name(&self) -> &'static str {
        match self {
            ContactMethod::Mixed => "mixed",
            ContactMethod::Nitsche { .. } => "nitsche",
            ContactMethod::Penalty { .. } => "penalty",
        }
    }
}

/// The mass matrix variants of contract §2.2.
#[derive(Debug, Clone, PartialEq)]
pub enum MassVariant {
    Consistent,
    Lumped,
    /// Element weights w₀ = 0, w_k = 1 (mass of the contact element removed).
    Mod1,
    /// w₀ = 0, w_k = m/(m−1) (uniform redistribution).
    Mod2,
    /// w₀ = 0, w₁ = 2, w_k = 1 (nearest-neighbour redistribution).
    Mod3,
    /// w₀ = 0 and the user's weights w₁, w₂, …; the last one repeats.
    Weights(Vec<f64>),
    /// Consistent mass with the contact row and column set to zero (003 §4.1.2d).
    ZeroContact,
    /// Renard's singular dynamic mass: contact row/column zero, M₁₁ = 7h/12 ρ.
    SingularDynamic,
    /// GetFEM demo's redistribution: the contact row lumped onto node 1's diagonal.
    NodeNeighbour,
}

impl MassVariant {
    pub const NAMES: [&'static str; 9] = [
        "consistent",
        "lumped",
        "mod1",
        "mod2",
        "mod3",
        "weights",
        "zero-contact",
        "singular-dynamic",
        "node-neighbour",
    ];

    pub fn name(&self) -> &'static str {
        match self {
            MassVariant::Consistent => "consistent",
            MassVariant::Lumped => "lumped",
            MassVariant::Mod1 => "mod1",
            MassVariant::Mod2 => "mod2",
            MassVariant::Mod3 => "mod3",
            MassVariant::Weights(_) => "weights",
            MassVariant::ZeroContact => "zero-contact",
            MassVariant::SingularDynamic => "singular-dynamic",
            MassVariant::NodeNeighbour => "node-neighbour",
        }
    }

    /// Parse a name; `weights` needs the list and is built by the caller.
    pub fn from_name(name: &str) -> Option<MassVariant> {
        Some(match name {
            "consistent" => MassVariant::Consistent,
            "lumped" => MassVariant::Lumped,
            "mod1" => MassVariant::Mod1,
            "mod2" => MassVariant::Mod2,
            "mod3" => MassVariant::Mod3,
            "zero-contact" => MassVariant::ZeroContact,
            "singular-dynamic" => MassVariant::SingularDynamic,
            "node-neighbour" => MassVariant::NodeNeighbour,
            _ => return None,
        })
    }

    /// Whether the contact node carries no inertia (its row of M is zero): it is then solved
    /// quasi-statically at every time, t = 0 included.
    pub fn massless_contact(&self) -> bool {
        !matches!(self, MassVariant::Consistent | MassVariant::Lumped)
    }
}

/// Initial value of a contact node without inertia (contract §2.2, `contact_init`). Only runs whose
/// mass variant has a zero contact row use it; a contact node with mass starts at the
/// interpolant, its equation having an acceleration to absorb the difference.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactInit {
    /// u₀(0) solves the node's quasi-static equation at t = 0 (u₀ = max(−g, u₁) for `mixed` and
    /// the default bar), so the discrete state is consistent from the start: E⁰ = 1/8 − O(h).
    #[default]
    Consistent,
    /// u₀(0) = u0(0) = a, the nodal interpolant (GetFEM's demo): E⁰ is the exact energy, a⁰ is
    /// computed from this state on the free nodes, and the first step of a scheme enforcing the
    /// node's equation at t^{n+1} moves the node to its quasi-static value, costing energy once.
    /// The hybrid scheme with Nitsche or penalty enforces it at t^{n+½} and keeps the defect,
    /// alternating in sign (see [`crate::run::bar1d`]).
    Interpolant,
}

impl ContactInit {
    pub const NAMES: [&'static str; 2] = ["consistent", "interpolant"];

    pub fn name(self) -> &'static str {
        match self {
            ContactInit::Consistent => "consistent",
            ContactInit::Interpolant => "interpolant",
        }
    }

    pub fn from_name(name: &str) -> Option<ContactInit> {
        match name {
            "consistent" => Some(ContactInit::Consistent),
            "interpolant" => Some(ContactInit::Interpolant),
            _ => None,
        }
    }
}
