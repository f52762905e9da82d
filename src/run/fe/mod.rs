//! The sparse finite-element engine: every FE scene × mass variant × implicit scheme with nodal
//! (`mixed`) Signorini contact (contract §1.2, §2.1–2.2, §3, §4).
//!
//! Semi-discrete system M ü + K u = F + Bᵀλ on the free dofs (the clamped face removed), with
//! λ ≥ 0 the upward nodal contact forces on the vertical dofs of Γ_C and u_d + g ≥ 0 there.
//! Newmark(β, γ) and the θ-scheme share one form,
//!
//!   u^{n+1} = p^n + c τ² a^{n+1},   p^n = u^n + τ v^n + c₁ τ² a^n,
//!   v^{n+1} = v^n + τ((1−γ) a^n + γ a^{n+1}),   equation at t^{n+1},
//!
//! with (c₁, c, γ) = ((1−2β)/2, β, γ) for Newmark and (θ(1−θ), θ², θ) for the θ-scheme. So every
//! step solves (M + c τ² K) u^{n+1} = M p^n + c τ² (F + Bᵀλ^{n+1}): A = M + cτ²K is constant —
//! factored once per run (sparse Cholesky, symbolic analysis once per mesh) and shared between
//! runs with the same matrix. The contact is condensed onto the contact dofs: Z = A⁻¹Bᵀ and
//! W = B Z are computed once per run; a step is one sparse solve y = A⁻¹(M p^n + cτ²F), the exact
//! LCP λ ≥ 0 ⊥ By + g + cτ²Wλ ≥ 0 ([`crate::contact::lcp`], warm-started from the previous
//! step), and u^{n+1} = y + cτ² Z λ over the active contact dofs. Never a refactorisation.
//! With `solver = "cg"` ([`crate::space::step_solver`]) nothing is factored: the same solves
//! (the step's and Z's columns) are made by preconditioned conjugate gradient on A itself,
//! each step warm-started from the previous one; a CG failure ends the run `solver-failed`.
//!
//! Massless dofs (the bottom nodes with mod1/mod2/mod3/weights/zero-contact) need no special
//! case: their rows of M are zero, so their row of the step system is c τ² (K u − F − Bᵀλ) = 0,
//! the quasi-static equation at t^{n+1} (contract §1.2). Their a and v are never used (their M rows
//! and columns vanish), the energy E = ½vᵀMv + ½uᵀKu − Fᵀu is the run's own.
//!
//! Errors against a reference run (nested mesh and step): e^n = u^n − I_h u_ref(t^n) at the
//! coarse nodes, ‖e‖²_L2 = eᵀ G e with the unweighted Gram matrix, H1 = L2 + eᵀ D e with
//! D = ∫∇e:∇e (contract §1.2). The disc/ball's and the mesh files' references may be on another
//! mesh (the mapped meshes of different sizes are not nested; another mesh file; the bars' box
//! for a mesh file of the bar): the reference's function is interpolated at the run's nodes
//! ([`reference::ball_ref_map`]).
//!
//! Observables per step (contract §1.3): the parts ½vᵀMv, ½uᵀKu, −Fᵀu of E^h, the lowest Γ_C
//! node's u_d (disc/ball), and the penetration max (u_n − g)_+ = max(−u_d − g)_+ over the Γ_C
//! nodes (the run's `max_penetration` is its maximum over the steps; Nitsche and the penalty
//! are measured at the same nodes). Nothing is allocated in the time loop.

mod bodies;
mod cache;
mod cfl;
mod config;
mod factor;
mod full_newton;
mod geometry;
mod load;
mod lockstep;
mod mass;
mod mesh_bodies;
mod methods;
mod newmark;
pub mod nitsche;
mod nitsche_interface;
mod nitsche_pair;
mod pairing;
mod products;
mod reference;
mod refine;
mod rows;
mod schur;
mod setup;
mod simulate;
mod start;

pub use config::FeConfig;
pub use geometry::cholesky_options;
pub use lockstep::lockstep_key;
pub use simulate::{simulate, simulate_group};
