//! The methods of the comparison literature (contract §3.2) in the sparse finite-element engine:
//! `kane`, `contact-stabilized-newmark`, `moreau-jean` with the nodal multiplier (`mixed`),
//! `generalized-alpha`/`hht` with `mixed`, `nitsche` and `penalty`, the `discrete-gradient`
//! with `penalty` and `nitsche` (Θ = 1), and `central-difference` with `mixed` and the lumped
//! mass (kinematic contact).
//!
//! The 1D engine ([`crate::run::bar1d`]) holds the verified step formulas; here they act on the
//! FE system M ü + K u = F + Bᵀλ, B the vertical dofs of the Γ_C nodes, B u + g ≥ 0, λ ≥ 0.
//! Every implicit step has a constant matrix A = M + cK, factored once per run through the
//! engine's shared cache (its key is (geometry, mass, contact method, c), so a run shares the
//! factor of every other run with the same matrix — kane, CSN and the discrete gradient use
//! Crank–Nicolson's S = M + τ²/4 K, generalized-α with ρ∞ = 1 too), with Z = A⁻¹Bᵀ and
//! H = c B Z condensed once. A step is one sparse solve y = A⁻¹b, a contact problem on the
//! contact set only, and the correction y + c Z μ: the LCP's μ is the contact force scaled by
//! the method's coefficient c_f/c of Bᵀλ in the right-hand side:
//! - `kane`: S Δu = τMvⁿ − τ²/2 Kuⁿ + τ²/2 F + τ²/2 Bᵀλ, v^{n+1} = 2Δu/τ − vⁿ (c_f = 2c, λ = μ/2).
//!   A massless row (mod1/…/zero-contact) is K u^{n+½} = Bᵀλ: quasi-static at the midpoint, as
//!   in 1D; its velocity is the difference quotient Δu/τ (it carries no energy);
//! - `contact-stabilized-newmark`: the predictor u^pred = ũ + M⁻¹Bᵀν, ũ = uⁿ + τvⁿ, with
//!   0 ≤ ν ⊥ Bũ + g + (BM⁻¹Bᵀ)ν ≥ 0 (the M-projection of the free flight), M⁻¹Bᵀ from a sparse
//!   Cholesky of M computed once per (geometry, mass) and cached like the step factors; then
//!   S Δ = −τ²/4 K(uⁿ + u^pred) + τ²/2 F + τ²/2 Bᵀλ, u^{n+1} = u^pred + Δ, v^{n+1} = vⁿ + 2Δ/τ;
//! - `generalized-alpha`: ũ = uⁿ + τvⁿ + τ²(½ − β)aⁿ, and the equation at t^{n+1−α} times
//!   βτ²/(1−α_m): (M + cK)u^{n+1} = M(ũ − κ_m aⁿ) − κ_f K uⁿ + κ_f Bᵀλⁿ + (c + κ_f)F + c Bᵀλ^{n+1}
//!   ([`crate::time::GeneralizedAlphaParams::history_coefficients`]; c_f = c, λ = μ), Newmark's
//!   updates. With ρ∞ = 1 the right-hand side is Crank–Nicolson's whenever M aⁿ = F − Kuⁿ + Bᵀλⁿ
//!   (its equation at tⁿ), and the matrix is the same: the runs agree to round-off;
//! - `moreau-jean`: (M + θ²τ²K)Δv = −τK(uⁿ + θτvⁿ) + τF + Bᵀp, the rows with
//!   (Buⁿ + g) + ½τBvⁿ ≤ 0 active ([`crate::contact::Lcp::solve_on`]), there
//!   0 ≤ p ⊥ Bv^{n+1} + eBvⁿ ≥ 0 (c_f = 1, p = cμ); u^{n+1} = uⁿ + τ(vⁿ + θΔv), reported
//!   force p/τ;
//! - `discrete-gradient` (penalty; Nitsche with Θ = 1, whose linear part K_Θ = K − Σ wγ s sᵀ is in
//!   A as for the hybrid scheme): the midpoint rule (M + τ²/4 K_Θ)Δu = τMvⁿ − τ²/2 K_Θuⁿ + τ²/2 F
//!   − τ²/2 Σ_q D_q p_q with D_q = w_q (φ_q(s_q^{n+1}) − φ_q(s_qⁿ))/(s_q^{n+1} − s_qⁿ),
//!   φ_q(s) = (1/2γ_q)[s − g_q]_+², s_q = p_q·u. Condensed on the points: s = s⁰ + τ²/2 W D(s),
//!   s⁰ = P(uⁿ + A⁻¹b), W = P A⁻¹C (C = −P, the same rows as the hybrid scheme's), solved by
//!   semismooth Newton with each point's scalar difference quotient and its slope
//!   ([`crate::contact::gradient`]) — D_q depends on s_q only, so the Jacobian is
//!   I − τ²/2 W diag(D'_q) on the points with D_q or D'_q ≠ 0. Since Φ(s^{n+1}) − Φ(sⁿ) =
//!   Σ D_q(s_q^{n+1} − s_qⁿ) the midpoint rule conserves E^h + Φ (penalty) and E_Θ (Θ = 1);
//! - kinematic `central-difference` (lumped M, diagonal): v^{n+½} = vⁿ + τ/2 aⁿ,
//!   u^{n+1} = uⁿ + τv^{n+½}, a contact dof below the obstacle put on it by the impulse
//!   Δv = (−g − u)/τ on v^{n+½} (λ = m Δv/τ), a^{n+1} = M⁻¹(F − Ku^{n+1}),
//!   v^{n+1} = v^{n+½} + τ/2 a^{n+1}: no solve at all. Its CFL limit τω_max ≤ 2 uses a
//!   certified upper bound of ω²_max = λ_max(M⁻¹K): a power-iteration estimate raised until
//!   σM − K factors ([`kinematic_dt_limit`]), within 1 % of the true value.
//!
//! Generalized-α with Nitsche/penalty (disc/ball): the linear part K_Θ (Nitsche's Θ-term) sits in
//! A as for the engine's Newmark steps, the contact force is f_c(u) = Σ_q φ_q(p_q·u) C_q with
//! f_cⁿ = f_c(uⁿ) (the previous step's Newton values) and f_c^{n+1} solved by the engine's
//! semismooth Newton with coefficient c ([`crate::run::fe::nitsche`]). With friction (contract §2.5,
//! issue 33) the same with the engine's frictional operators and Newton: K_Θ in A holds the
//! tangential Θ rows −Θ Σ w γ σ_t σ_tᵀ too (the history term −κ_f K_Θ uⁿ and M u^{n+1} =
//! A u^{n+1} − cK_Θ u^{n+1} use them), f_c(u) = Σ_j λ_j C_j over the d unknowns per point
//! (C's tangential columns u_t − Θγσ_t), f_cⁿ the previous step's λ (normal and tangential),
//! and f_c^{n+1} from [`crate::run::fe::nitsche`]'s frictional Newton with coefficient c, its x0 =
//! P y + k u_tⁿ (the slip (u_t^{n+1} − u_tⁿ)/τ, position level) and its state (u_tⁿ, the
//! tally). W_f uses f̄_t = (1 − α_f) f_t^{n+1} + α_f f_tⁿ, the weight of f_t^{n+1} in the
//! equation at t^{n+1−α_f}. With ρ∞ = 1 (α_m = α_f = ½) this is the frictional
//! Crank–Nicolson of the engine: the same matrix, the same right-hand side while the equation
//! at tⁿ holds, c = τ²/4 and f̄_t = ½(f_tⁿ + f_t^{n+1}) (tests/friction_nitsche.rs: ≤ 3.5e-9).
//!
//! The energy E^h = ½vᵀMv + ½uᵀKu − Fᵀu needs Mv and Ku (the schemes whose equation does not
//! hold at t^{n+1} cannot use Newmark's identity uᵀKu = uᵀ(F + Bᵀλ − Ma)); they are the next
//! step's right-hand side too. They are carried: a step computes one product, KΔ (Δ its
//! increment), and takes MΔ = AΔ − cKΔ from the system it just solved (AΔ its right-hand side
//! plus the contact term) — a subtraction without division by c, so no round-off is amplified.
//! Contact-stabilized Newmark and Moreau–Jean carry Kv as well (their right-hand sides need
//! K u^pred = Kuⁿ + τKvⁿ + KM⁻¹Bᵀν and K(uⁿ + θτvⁿ)). So a step costs the solve and one sparse
//! product, as Crank–Nicolson's does (measured: `benches/fe.rs`, `bar2d-methods`). Every 64
//! steps the products are recomputed from the state. Nothing is allocated in the time loop.
//!
//! Friction (contract §2.5, `space = "mixed"`; issue 33). The contact rows grow from B (the
//! vertical dof of each Γ_C node, normal force λ = f_n ≥ 0 on the body) to C = [B; T], T the
//! node's e_1 (and e_2) dofs carrying the tangential force f_t on the body: the force term
//! Bᵀλ of every step above becomes Cᵀr, r = (f_n, f_t) per node, and the condensation
//! Z = A⁻¹Cᵀ, H = cCZ covers the tangential columns (the frictional factor). A step is still
//! y = A⁻¹b, one contact problem on the contact set, and y + cZμ with μ = (c_f/c) r; the
//! problem is the Coulomb (or Tresca) law on the pair
//!
//!   gap = q_n + (Hμ)_n ≥ 0 ⊥ μ_n ≥ 0,   slip = q_t + (Hμ)_t,   |μ_t| ≤ b, μ_t = −b·slip/|slip|,
//!
//! solved by the semismooth Newton method of [`crate::contact::coulomb`] (the Coulomb disc in
//! 3D). Coulomb's bound b = μ_f μ_n is scale free; Tresca's s·w_j (w_j = ∫_ΓC φ_j, a force) is
//! multiplied by c_f/c, and by τ where the unknown is an impulse. Per method (the slip is the
//! scheme's, contract §2.5; f̄_t is the tangential force as it enters the momentum equation over
//! the step, which W_f^{n+1} = W_f^n − Σ_j f̄_t,j·(u_t,j^{n+1} − u_t,j^n) uses):
//! - `kane`: q_n = Buⁿ + g + By, q_t = Ty (slip = u_t^{n+1} − u_tⁿ = TΔu), μ = 2(λ, f_t)^{n+1},
//!   f̄_t = f_t^{n+1}. The trapezoidal rule gives ΔE = Δuᵀ Cᵀr exactly (massless rows included:
//!   their row is K u^{n+½} = F + Cᵀr), so Δ(E + W_f) = λ·BΔu = −λ·(Buⁿ + g) ≤ 0: the normal
//!   force does no positive work and friction's work is all in W_f;
//! - `contact-stabilized-newmark`: the predictor is frictionless (the M-projection onto the
//!   admissible set constrains the normal rows only); the corrector is `kane`'s with
//!   q_n = Bu^pred + g + By, q_t = T(u^pred − uⁿ) + Ty, μ = 2(λ, f_t)^{n+1}, f̄_t = f_t^{n+1};
//! - `generalized-alpha`/`hht`: q_n = By + g, q_t = Ty − Tuⁿ, μ = r^{n+1}; the force of the
//!   previous step enters the right-hand side as κ_f Cᵀrⁿ (tangential rows included), so
//!   f̄_t = (1 − α_f) f_t^{n+1} + α_f f_tⁿ;
//! - `moreau-jean`: De Saxcé's law per node on the velocity-level problem, over the nodes with
//!   (Buⁿ + g) + ½τBvⁿ ≤ 0 only (the solver's active mask; the others carry no impulse):
//!   "gap" = Bv^{n+1} + eBvⁿ, q_n = (1 + e)Bvⁿ + By; "slip" = v_t^{n+1}, q_t = Tvⁿ + Ty; the
//!   impulses p = cμ, reported forces p/τ, Tresca's bound s·w_j·τ. f̄_t = p_t/τ, so
//!   −f̄_t·Δu_t = −p_t·Tv^{n+θ} and with θ = ½ Δ(E + W_f) = p_n·Bv^{n+½} = ½(1 − e) p_n·Bvⁿ:
//!   zero for e = 1 (conserved to round-off), ≤ 0 on a node that approaches for e < 1;
//! - kinematic `central-difference`: after a contact dof is put on the obstacle by the normal
//!   impulse (force λ_j = m_j Δv_j/τ), the node's tangential force is the one that stops its
//!   slip increment, f_t = −m_j(u_t^pred − u_tⁿ)/τ², projected onto the disc |f_t| ≤ b
//!   (b = μ_f λ_j, Tresca s·w_j, none without a normal impulse): u_t += τ²f_t/m_j,
//!   v_t^{n+½} += τf_t/m_j. A local projection per node, no solve; f̄_t = f_t^{n+1}.
//!
//! Measured per step (contract §5): W_f, the rise of E + W_f, the contact node-steps in stick
//! (|Δu_t| ≤ 1e-12·h) and in slip, |Σf_t|/Σf_n, and the series' σ_t (the total e_1 contact
//! force), the Γ_C mean of v_1 and W_f; at T the mean velocities 1ᵀMv/1ᵀM1 along e_1 (3D: the
//! norm over e_1, e_2) and e_d. A law with μ_f = 0 or s = 0 never reaches this module's
//! frictional path (the engine routes it to the frictionless one: bit for bit).

mod central_difference;
mod contact_stabilized;
mod correction;
mod discrete_gradient;
mod driver;
mod friction;
mod generalized_alpha;
mod gradient_newton;
mod kane;
mod mass_inverse;
mod moreau_jean;
mod run;
mod state;

pub(super) use driver::simulate;
