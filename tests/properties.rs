//! Invariants over random discretisations (seeded, reproducible).
//!
//! - Nitsche-Hybrid with Θ = 1: the augmented energy E_Θ never increases from one step to the
//!   next (003 Cor 3.8), for every h, τ, γ0 — E^h itself may rise slightly within a step;
//! - the 000 §5 hybrid on the mass-redistribution reduced system: E^h never increases
//!   (Lemma 5.1), for mod1, mod2, mod3;
//! - backward Euler: E_Θ non-increasing (003 Cor 3.2).
//!
//! Tolerance 1e-12 of the initial energy: the proofs give ≤ 0 exactly; what remains is the
//! round-off of an energy difference of O(1) quantities accumulated over ≤ 1e5 steps (worst seen
//! over 200 draws: 5e-13, contract §6).

mod common;

use common::*;
use contact_sweep::run::Grid1d;
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{Scheme, ThetaParams};

struct Draw {
    elements: usize,
    dt: f64,
    gamma0: f64,
}

/// h ∈ [1/400, 1/4] (so that h divides L = 1), τ ∈ [h/10, 10h] log-uniform, γ0 ∈ [1e-8, 1e-2]
/// log-uniform.
fn draws(seed: u64, n: usize) -> Vec<Draw> {
    let mut rng = fastrand::Rng::with_seed(seed);
    let log_uniform = |rng: &mut fastrand::Rng, lo: f64, hi: f64| {
        (lo.ln() + rng.f64() * (hi.ln() - lo.ln())).exp()
    };
    (0..n)
        .map(|_| {
            let elements = rng.usize(4..=400);
            let h = 1.0 / elements as f64;
            Draw {
                elements,
                dt: log_uniform(&mut rng, h / 10.0, 10.0 * h),
                gamma0: log_uniform(&mut rng, 1e-8, 1e-2),
            }
        })
        .collect()
}

const TOL: f64 = 1e-12;

/// Which energy must not increase.
#[derive(Clone, Copy)]
enum Energy {
    /// E^h (plus the penalty potential for the penalty).
    Mechanical,
    /// E_Θ (Nitsche).
    Augmented,
}

/// Run every draw with the method, mass and scheme `setup` builds, and assert the one-step
/// increase of `energy` stays below TOL·E0.
fn assert_never_increases(
    seed: u64,
    n: usize,
    energy: Energy,
    setup: impl Fn(usize, &Draw) -> (ContactMethod, MassVariant, Scheme),
) {
    for (i, d) in draws(seed, n).iter().enumerate() {
        let (method, mass, scheme) = setup(i, d);
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(d.elements, d.dt, 6.0, method, mass.clone(), scheme),
            0,
        ));
        let inc = match energy {
            Energy::Mechanical => o.metrics.energy_max_increase,
            Energy::Augmented => o.metrics.energy_theta_max_increase,
        }
        .unwrap();
        assert!(
            inc <= TOL,
            "{method:?} {mass:?} {scheme:?} m={} dt={}: the energy rose by {inc:e}·E0",
            d.elements,
            d.dt
        );
    }
}

#[test]
fn nitsche_hybrid_augmented_energy_never_increases() {
    assert_never_increases(1, 24, Energy::Augmented, |_, d| {
        (
            ContactMethod::Nitsche {
                theta: 1.0,
                gamma0: d.gamma0,
            },
            MassVariant::Consistent,
            Scheme::Hybrid,
        )
    });
}

#[test]
fn reduced_hybrid_energy_never_increases_for_mass_redistribution() {
    assert_never_increases(2, 24, Energy::Mechanical, |i, _| {
        let mass = [MassVariant::Mod1, MassVariant::Mod2, MassVariant::Mod3][i % 3].clone();
        (ContactMethod::Mixed, mass, Scheme::Hybrid)
    });
}

#[test]
fn backward_euler_augmented_energy_non_increasing() {
    assert_never_increases(3, 16, Energy::Augmented, |_, d| {
        (
            ContactMethod::Nitsche {
                theta: 1.0,
                gamma0: d.gamma0,
            },
            MassVariant::Consistent,
            Scheme::Theta(ThetaParams::backward_euler()),
        )
    });
}

#[test]
fn penalty_hybrid_energy_with_its_potential_never_increases() {
    // For the penalty the contact argument and the force direction coincide (p = q), so the
    // proof of 003 Prop 3.7 applies with E^h + κ/2 [s]₊² in place of E_Θ; κ h/E = 1/γ0 of the
    // draw spans 1e2 … 1e8.
    assert_never_increases(4, 16, Energy::Mechanical, |_, d| {
        (
            ContactMethod::Penalty {
                gamma0: 1.0 / d.gamma0,
            },
            MassVariant::Consistent,
            Scheme::Hybrid,
        )
    });
}

#[test]
fn hybrid_schemes_stay_stable_over_a_hundred_impacts_at_large_courant_numbers() {
    // Hard case: T = 300 (100 periods, 100 impacts) at ν = 4 and 10 on a coarse mesh. The
    // proofs hold for every τ, so the one-step increase stays at round-off (1e-12·E0, as above)
    // however many impacts accumulate. (Crank–Nicolson with the same mod3 mass gains energy here:
    // measured ×1.9 at ν = 4 and ×126 at ν = 10 — the reason for the hybrid, 000 §5.)
    for nu in [4.0, 10.0] {
        let dt = nu / 50.0;
        let cases = [
            (
                ContactMethod::Nitsche {
                    theta: 1.0,
                    gamma0: 1e-6,
                },
                MassVariant::Consistent,
                Energy::Augmented,
            ),
            (ContactMethod::Mixed, MassVariant::Mod3, Energy::Mechanical),
            (
                ContactMethod::Penalty { gamma0: 100.0 },
                MassVariant::Consistent,
                Energy::Mechanical,
            ),
        ];
        for (method, mass, energy) in cases {
            let o = ok(bar1d(
                BarParams::default(),
                Grid1d::new(50, dt, 300.0, method, mass.clone(), Scheme::Hybrid),
                0,
            ));
            let inc = match energy {
                Energy::Mechanical => o.metrics.energy_max_increase,
                Energy::Augmented => o.metrics.energy_theta_max_increase,
            }
            .unwrap();
            assert!(inc <= TOL, "{method:?} {mass:?} ν={nu}: rose by {inc:e}·E0");
            assert!(o.metrics.energy_drift.unwrap() < 0.0);
        }
    }
}

// ---- Methods of the comparison literature (contract §3.2) ----

/// kane (trapezoidal rule, contact force fully implicit): the force λ^{n+1} does the work
/// λ·(u₀^{n+1} − u₀ⁿ) ≤ 0 (it acts only with u₀^{n+1} = −g ≤ u₀ⁿ), so E^h never increases —
/// for every mass: a massless node takes its row at the midpoint, as the formula has it.
/// Same round-off tolerance as above.
#[test]
fn kane_energy_never_increases() {
    assert_never_increases(11, 24, Energy::Mechanical, |i, _| {
        let mass = [
            MassVariant::Consistent,
            MassVariant::Lumped,
            MassVariant::Mod3,
            MassVariant::ZeroContact,
        ][i % 4]
            .clone();
        (ContactMethod::Mixed, mass, Scheme::Kane)
    });
}

/// contact-stabilized Newmark: the M-projection of the predictor does not increase ‖·‖_M, and
/// the kane step from it does not increase E^h (Deuflhard–Krause–Ertel 2008, Thm 3.2).
#[test]
fn contact_stabilized_newmark_energy_never_increases() {
    assert_never_increases(12, 24, Energy::Mechanical, |i, _| {
        let mass = [MassVariant::Consistent, MassVariant::Lumped][i % 2].clone();
        (ContactMethod::Mixed, mass, Scheme::ContactStabilizedNewmark)
    });
}

/// Moreau–Jean with θ = ½: the impulse p ≥ 0 does the work p·B v^{n+½} = ½p(1 − e)·B vⁿ
/// (B v^{n+1} = −e B vⁿ where p > 0). With e = 1 that is zero whatever the row does: E^h never
/// increases (round-off, as above). With e < 1 it is ≤ 0 on a row that approaches (B vⁿ ≤ 0)
/// but positive on an active row that separates (B vⁿ > 0, its predicted gap still closed after
/// a bounce): contract §3.2's "never increases" holds for e = 1 only. Measured over 40 draws
/// (h ∈ [1/400, 1/4], τ ∈ [h/10, 10h]): e = ½ rose in every draw, by up to 4.7e-2·E⁰; e = 0 in 2
/// draws (ν ≈ 10, by 1.5e-4·E⁰). Asserted: e = 1 at round-off on every draw; e = 0 at round-off
/// for ν ≤ 2 (no separating active row there).
#[test]
fn moreau_jean_midpoint_energy_never_increases() {
    use contact_sweep::time::MoreauJeanParams;
    let mj = |restitution| {
        Scheme::MoreauJean(MoreauJeanParams {
            theta: 0.5,
            restitution,
        })
    };
    assert_never_increases(13, 24, Energy::Mechanical, |i, _| {
        let mass = [MassVariant::Consistent, MassVariant::Lumped][i % 2].clone();
        (ContactMethod::Mixed, mass, mj(1.0))
    });
    for (i, d) in draws(17, 24).iter().enumerate() {
        let h = 1.0 / d.elements as f64;
        let dt = d.dt.min(2.0 * h);
        let mass = [MassVariant::Consistent, MassVariant::Lumped][i % 2].clone();
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(
                d.elements,
                dt,
                6.0,
                ContactMethod::Mixed,
                mass.clone(),
                mj(0.0),
            ),
            0,
        ));
        let inc = o.metrics.energy_max_increase.unwrap();
        assert!(
            inc <= TOL,
            "{mass:?} m={} dt={dt}: rose by {inc:e}·E0",
            d.elements
        );
    }
}

/// The discrete gradient conserves E^h + Φ (penalty, the energy the run reports) and E_Θ
/// (Nitsche, Θ = 1) exactly: the step-to-step change, in both directions, is round-off
/// (tolerance 1e-12·E⁰ as above: O(1) energies differenced after ≤ 1e5 steps).
#[test]
fn discrete_gradient_conserves_its_energy_every_step() {
    for (i, d) in draws(14, 24).iter().enumerate() {
        let (method, augmented) = if i % 2 == 0 {
            // κh/E = 1/γ0 ∈ [1e2, 1e8]: from soft to very stiff penalties.
            (
                ContactMethod::Penalty {
                    gamma0: 1.0 / d.gamma0,
                },
                false,
            )
        } else {
            (
                ContactMethod::Nitsche {
                    theta: 1.0,
                    gamma0: d.gamma0,
                },
                true,
            )
        };
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(
                d.elements,
                d.dt,
                6.0,
                method,
                MassVariant::Consistent,
                Scheme::DiscreteGradient,
            ),
            1,
        ));
        let e0 = o.metrics.energy_initial.unwrap();
        let energy = |r: &contact_sweep::run::SeriesRow| {
            if augmented {
                r.energy_theta.unwrap()
            } else {
                r.energy
            }
        };
        let rows: Vec<_> = o.series.rows().collect();
        let worst = rows
            .windows(2)
            .map(|w| (energy(&w[1]) - energy(&w[0])).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= TOL * e0,
            "{method:?} m={} dt={}: the conserved energy moved by {:e}·E0 in one step",
            d.elements,
            d.dt,
            worst / e0
        );
        // The run did meet the obstacle (else conservation would be the trivial linear case).
        assert!(o.metrics.contact_switches >= 1, "{method:?}: no contact");
        // Newton iterations are counted: at least one per step, at most 100 (contract §4).
        let (it, steps) = (o.metrics.iterations, o.metrics.steps);
        assert!(
            it >= steps && it <= 100 * steps,
            "{it} iterations, {steps} steps"
        );
    }
}

/// generalized-α with ρ∞ = 1 (α_m = α_f = ½, β = ¼, γ = ½) averages the equations at tⁿ and
/// t^{n+1}; with a⁰ from the equation at t = 0, the average of two equations that hold is
/// Crank–Nicolson's equation at t^{n+1}: the same step (same matrix, same contact coefficient)
/// up to round-off in the right-hand side. hht with α = 0 is Newmark(¼, ½) itself.
///
/// - a soft penalty (κh/E = 100·γ0 of the draw, 1e-6 … 1: a contact that does not chatter):
///   the round-off stays round-off — u(0, t) and E^h agree to 1e-9 through T = 2, the end of
///   the first impact. (A stiff penalty chatters like the mixed method and amplifies round-off
///   the same way: κh/E = 1126 at m = 139, τ = 4.4e-3 — 1e-10 at t = 1.12, 2e-5 at 1.77.)
/// - mixed + consistent mass (ill-posed, contract §2.1): they agree to round-off until the first
///   contact (measured ≤ 3e-11 after ≤ 2e4 steps; asserted 1e-9), after which the chattering contact amplifies
///   the round-off exponentially, not "to round-off through the impact" as contract §3.2 says:
///   measured at m = 139, τ = 4.4e-3: 4e-11 at t = 1.04, 1e-9 at 1.17, 2e-6 at 1.52, 4e-2 at
///   1.89 — both runs chatter (σ_C switching on and off) and the chatter's phase drifts.
#[test]
fn generalized_alpha_with_rho_one_is_crank_nicolson_through_the_first_impact() {
    use contact_sweep::time::{GeneralizedAlphaParams, NewmarkParams};
    let cn = Scheme::Newmark(NewmarkParams::crank_nicolson());
    for (i, d) in draws(15, 16).iter().enumerate() {
        let ga = if i % 2 == 0 {
            GeneralizedAlphaParams::from_rho_inf(1.0)
        } else {
            GeneralizedAlphaParams::hht(0.0)
        };
        for method in [
            ContactMethod::Mixed,
            ContactMethod::Penalty {
                gamma0: 100.0 * d.gamma0,
            },
        ] {
            let run = |scheme| {
                ok(bar1d(
                    BarParams::default(),
                    Grid1d::new(
                        d.elements,
                        d.dt,
                        2.0,
                        method,
                        MassVariant::Consistent,
                        scheme,
                    ),
                    1,
                ))
            };
            let (a, b) = (run(Scheme::GeneralizedAlpha(ga)), run(cn));
            assert_eq!(a.series.len(), b.series.len());
            let (end, tol) = match method {
                ContactMethod::Mixed => (
                    a.series
                        .rows()
                        .position(|r| r.sigma_contact < 0.0)
                        .expect("the bar reaches the obstacle by t = 2"),
                    1e-9,
                ),
                _ => (a.series.len(), 1e-9),
            };
            let diff = a
                .series
                .rows()
                .take(end)
                .zip(b.series.rows())
                .map(|(x, y)| {
                    (x.u_contact - y.u_contact)
                        .abs()
                        .max((x.energy - y.energy).abs())
                })
                .fold(0.0, f64::max);
            assert!(
                diff <= tol,
                "{ga:?} {method:?} m={} dt={}: differs from crank-nicolson by {diff:e}",
                d.elements,
                d.dt
            );
        }
    }
}

/// Kinematic contact (central difference, `mixed`, lumped mass) puts a penetrating node back
/// on the obstacle at every step: max_penetration is exactly 0, for every h and every τ below
/// the CFL limit h/c (lumped mass: ω_max = 2c/h, bound τω ≤ 2).
#[test]
fn kinematic_contact_never_penetrates() {
    use contact_sweep::time::NewmarkParams;
    let mut rng = fastrand::Rng::with_seed(16);
    for _ in 0..24 {
        let elements = rng.usize(4..=400);
        let h = 1.0 / elements as f64;
        let dt = h * (0.1 + 0.9 * rng.f64());
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(
                elements,
                dt,
                6.0,
                ContactMethod::Mixed,
                MassVariant::Lumped,
                Scheme::Newmark(NewmarkParams::central_difference()),
            ),
            0,
        ));
        assert_eq!(o.metrics.max_penetration, Some(0.0), "m={elements} dt={dt}");
        assert!(
            o.metrics.contact_switches >= 2,
            "m={elements} dt={dt}: no impact"
        );
    }
}
