//! A validated finite-element run ([`FeConfig`]), its scheme coefficients, and the predicates
//! that route it to a time loop (the Newmark/θ/hybrid stepper or a contract §3.2 method; frictional
//! or not). Low in the engine: every other file reads the configuration, none is read here.

use crate::contact::friction::FrictionLaw;
use crate::scene::{FeGeometry, FeSetup};
use crate::space::step_solver::Solver;
use crate::space::{ContactInit, ContactMethod, MassVariant};
use crate::time::{NewmarkParams, Scheme};

/// Steps between two checks of the clock and of an interruption.
pub(super) const CLOCK_EVERY: usize = 64;
/// The contact LCP: tolerance relative to the largest gap, and the iteration cap (contract §4).
pub(super) const LCP_TOL: f64 = 1e-12;
pub(super) const LCP_MAX_ITER: usize = 100;

/// A validated finite-element run.
#[derive(Debug, Clone, PartialEq)]
pub struct FeConfig {
    pub setup: FeSetup,
    pub method: ContactMethod,
    pub mass: MassVariant,
    pub scheme: Scheme,
    pub dt: f64,
    pub steps: usize,
    /// Direct (Cholesky) or iterative (CG) step solves (`solver`, `cg_tol`).
    pub solver: Solver,
    /// Ensemble member: relative amplitude of a uniform perturbation of v⁰ (u⁰ = 0 here) and
    /// its seed.
    pub perturbation: Option<(f64, u64)>,
    /// The friction law on Γ_C (contract §2.5; `None`: today's frictionless engine).
    pub friction: FrictionLaw,
    /// The start of the massless dofs under a body load (contract §1.3, §2.2): quasi-static
    /// (`Consistent`, [`super::start`]) or u⁰ = 0 (`Interpolant`). Without such a load both
    /// are the same state.
    pub contact_init: ContactInit,
}

impl FeConfig {
    /// Free unknowns (nodes off the clamped face × d).
    pub fn unknowns(&self) -> usize {
        match &self.setup.geometry {
            FeGeometry::Box { cells, .. } => {
                let d = cells.len();
                // Saturating: the planner sizes runs before refusing the huge ones.
                let count = |cs: &[usize]| cs.iter().fold(1usize, |p, c| p.saturating_mul(c + 1));
                let (nodes, top) = (count(cells), count(&cells[..d - 1]));
                (nodes - top).saturating_mul(d)
            }
            FeGeometry::Mesh {
                dim,
                nodes,
                clamped_nodes,
                ..
            } => nodes.saturating_sub(*clamped_nodes).saturating_mul(*dim),
            // Two blocks (contract §1.10): every node of both, B's base less when clamped.
            FeGeometry::Blocks(b) => {
                let d = self.setup.dim;
                let face = |n: usize| (n + 1).saturating_pow(d as u32 - 1);
                let a = face(b.across).saturating_mul(b.cells_a + 1);
                let layers_b = b.cells_b + 1 - usize::from(b.base_clamped);
                let nodes = a.saturating_add(face(b.across_b).saturating_mul(layers_b));
                nodes.saturating_mul(d)
            }
            FeGeometry::Ball {
                dim,
                degree,
                n_t,
                n_r,
                ..
            } => {
                // The central block's lattice, then n_r·p shells of the outer blocks: a shell is
                // a square's perimeter (2D) or a cubed sphere's surface lattice (3D).
                let (t, r) = (n_t * degree, n_r * degree);
                let nodes = if *dim == 2 {
                    (t + 1).pow(2) + 4 * t * r
                } else {
                    (t + 1).pow(3) + r * (6 * t * t + 2)
                };
                nodes * dim
            }
        }
    }

    /// (c₁, c, γ) of the common scheme form (module header).
    pub(super) fn coefficients(&self) -> Result<(f64, f64, f64), String> {
        match self.scheme {
            Scheme::Newmark(p) if p.beta > 0.0 => Ok((0.5 - p.beta, p.beta, p.gamma)),
            Scheme::Theta(p) if p.theta > 0.0 => {
                Ok((p.theta * (1.0 - p.theta), p.theta * p.theta, p.theta))
            }
            // The hybrid scheme has its own loop with Crank–Nicolson's step matrix (c = ¼).
            Scheme::Hybrid
                if matches!(
                    self.method,
                    ContactMethod::Nitsche { .. } | ContactMethod::Penalty { .. }
                ) =>
            {
                Ok((0.25, 0.25, 0.5))
            }
            s => Err(format!(
                "scheme {} is not available for scene {}",
                s.label(),
                self.setup.scene
            )),
        }
    }
}

/// Whether [`super::newmark::Stepper`] runs `cfg` with `mixed` contact: the Newmark family and the θ-scheme
/// (the hybrid scheme is Nitsche's and the penalty's; contract §3.2's methods have their own loops).
pub(super) fn mixed_stepper(cfg: &FeConfig) -> bool {
    cfg.method == ContactMethod::Mixed && !handles(cfg) && cfg.coefficients().is_ok()
}

/// Whether the run takes the frictional engine. A law with μ_f = 0 or s = 0 is the
/// frictionless problem, which the frictionless engine solves: the "μ_f = 0 gives the
/// frictionless numbers bit for bit" rule of contract §2.5 holds by construction — except Nitsche
/// with Θ ≠ 0, whose frictional form at μ_f = 0 is the full-vector frictionless Nitsche (σ_t = 0
/// imposed weakly with its Θ term, contract §2.5), not `none`'s: any Coulomb/Tresca law takes
/// the frictional engine there.
pub(super) fn frictional(cfg: &FeConfig) -> bool {
    let full_vector = matches!(cfg.method, ContactMethod::Nitsche { theta, .. } if theta != 0.0);
    match cfg.friction {
        FrictionLaw::None => false,
        FrictionLaw::Coulomb { coefficient } => coefficient != 0.0 || full_vector,
        FrictionLaw::Tresca { threshold } => threshold != 0.0 || full_vector,
    }
}
/// Whether `cfg` is central difference with `mixed` and the lumped mass (kinematic contact).
pub(super) fn kinematic(cfg: &FeConfig) -> bool {
    cfg.scheme == Scheme::Newmark(NewmarkParams::central_difference())
        && cfg.mass == MassVariant::Lumped
        && cfg.method == ContactMethod::Mixed
}

/// Whether this module runs `cfg`.
pub(super) fn handles(cfg: &FeConfig) -> bool {
    cfg.scheme.is_comparison() || kinematic(cfg)
}
