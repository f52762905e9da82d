//! `nitsche` between the two blocks of `blocks2d`/`blocks3d` (contract §1.10, §2.6; issue 44):
//! unbiased (`nitsche_sides = "unbiased"`, w_a = w_b = ½) and one-sided (`"a"`), Θ ∈ {−1, 0, 1}.
//!
//! Each quadrature point of Γ^a and Γ^b carries both bodies' traces (`run::fe::nitsche_pair`):
//! δ = (u^a − u^b∘π)·n with n = −e_d, σ_n^i from its own side's element, and the force column
//! −(δ − Θγ^iσ_n^i) pushes A and B equally and oppositely. So the total momentum is an exact
//! invariant of every scheme (contract §2.6), and the contact patch test's uniform state is a
//! discrete solution: δ = 0, σ_n^i = −p, so P^i_γ = γ^i p and the pressure (1/γ^i)[P^i_γ]_+ = p
//! on every side, and the Θ-terms cancel (½p·Θγσ_n(v) from the contact term against
//! −½Θγσ_n(u)σ_n(v) = ½Θγpσ_n(v) from the symmetric one).

mod common;

use common::{assert_momentum, outcomes};

/// The contact patch test (contract §1.10) for `nitsche`: B's base clamped, gap 0, at rest,
/// λ = λ_b = 0, μ = 1, μ_b = 2, p = 1e-2, one backward-Euler step of τ = 1e6, unbiased and
/// one-sided, Θ = −1, 0, 1, γ0 = 0.05, 2D and 3D. One step is the static solution up to
/// O(ρH²/(μτ²)) = 1e-12, and the refined step (`run::fe::refine`, the penalty's sweeps with
/// Nitsche's Θ-term in the residual) resolves it to round-off: the bound is issue 44's 1e-8
/// (done-when 5). Measured 5.0e-13 to 6.3e-13 (stress and pressure, every case); without the
/// refinement 3.5e-3 (stress) and 3.3e-2 (pressure) on blocks2d, Θ = −1, unbiased.
#[test]
fn nitsche_passes_the_patch_test() {
    for (scene, h) in [("blocks2d", 0.25), ("blocks3d", 0.5)] {
        let method = "space = \"nitsche\"\nnitsche_gamma0 = 0.05\n[grid]\nnitsche_theta = [-1.0, 0.0, 1.0]\nnitsche_sides = [\"unbiased\", \"a\"]";
        let runs = outcomes(&common::patch_sweep(scene, h, method));
        assert_eq!(runs.len(), 6);
        common::assert_patch(scene, &runs);
    }
}

/// contract §2.6's invariant with `nitsche` on free blocks2d: A thrown down at 1 onto B thrown
/// up at ½, 4 × 4 squares per block, the schemes Nitsche takes × four masses × both sides ×
/// Θ. Tolerance 1e-12 (issue 44 done-when 3): P's terms are O(m|V|) = O(1), each step adds the
/// solve's and the products' round-off, O(10 ε) per step over 40 steps.
#[test]
fn nitsche_keeps_the_momentum_of_blocks2d() {
    let text = "name = \"nm\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.8\nh = 0.25\ndt = 0.02\nvelocity = -1.0\nvelocity_b = 0.5\nspace = \"nitsche\"\nnitsche_gamma0 = 0.05\n[grid]\nscheme = [\"crank-nicolson\", \"backward-euler\", \"hybrid\", \"kane\", \"generalized-alpha\", \"moreau-jean\"]\nmass = [\"consistent\", \"lumped\", \"mod3\", \"zero-contact\"]\nnitsche_sides = [\"unbiased\", \"a\"]\nnitsche_theta = [-1.0, 0.0, 1.0]\n";
    let runs = outcomes(text);
    assert!(runs.len() > 60, "{} runs", runs.len());
    let worst = assert_momentum(&runs, 1e-12);
    eprintln!(
        "nitsche blocks2d: {} runs, worst momentum_drift {worst:e}",
        runs.len()
    );
}

/// The same on blocks3d (2 × 2 × 2 cubes per block, a tangential velocity too), fewer
/// combinations to keep the suite fast; the discrete gradient takes Θ = 1.
#[test]
fn nitsche_keeps_the_momentum_of_blocks3d() {
    let text = "name = \"nm3\"\nscene = \"blocks3d\"\n[fixed]\nT = 0.6\nh = 0.5\ndt = 0.05\nvelocity = -1.0\nvelocity_b = 0.25\nvelocity_tangential = 0.3\nspace = \"nitsche\"\nnitsche_gamma0 = 0.05\nnitsche_theta = 1.0\n[grid]\nscheme = [\"crank-nicolson\", \"backward-euler\", \"kane\", \"discrete-gradient\"]\nmass = [\"consistent\", \"zero-contact\"]\nnitsche_sides = [\"unbiased\", \"a\"]\n";
    let runs = outcomes(text);
    let worst = assert_momentum(&runs, 1e-12);
    eprintln!(
        "nitsche blocks3d: {} runs, worst momentum_drift {worst:e}",
        runs.len()
    );
}
