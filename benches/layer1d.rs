//! The frictional layer (contract §1.7, issue 32): what friction costs a step.
//!
//! `friction-ratio`: for each method that defines friction, a run of the layer with Coulomb
//! friction (slip regime: V_t = 1, μ_f = 0.1) against the same run with `friction = "none"`
//! (both chains stepped, the tangential one free) — m = 1000 elements, c_p τ/h = ½, T = 2.5
//! (2000 steps), errors against the exact solution included, series off. Timed in
//! alternation, 7 rounds, medians; the target is ≤ 1.3×.
//!
//! `cargo bench --bench layer1d`.

use std::time::Instant;

use contact_sweep::contact::friction::FrictionLaw;
use contact_sweep::run::layer1d::{Layer1dConfig, simulate_with_stats};
use contact_sweep::run::{Grid1d, RunOptions, Status};
use contact_sweep::scene::LayerParams;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, Scheme};

fn config(
    friction: FrictionLaw,
    method: ContactMethod,
    mass: MassVariant,
    scheme: Scheme,
) -> Layer1dConfig {
    let m = 1000;
    let layer = LayerParams {
        velocity_tangential: 1.0,
        friction,
        ..LayerParams::default()
    };
    let dt = 0.5 / m as f64 / layer.c_p();
    Layer1dConfig::new(layer, Grid1d::new(m, dt, 2.5, method, mass, scheme))
}

fn time(cfg: &Layer1dConfig, opts: &RunOptions) -> f64 {
    let start = Instant::now();
    let (out, _) = simulate_with_stats(cfg, opts);
    let s = start.elapsed().as_secs_f64();
    assert_eq!(out.status, Status::Ok);
    s
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let cn = Scheme::Newmark(NewmarkParams::crank_nicolson());
    let cases = [
        (
            "zero-contact + CN",
            ContactMethod::Mixed,
            MassVariant::ZeroContact,
            cn,
        ),
        ("mod3 + CN", ContactMethod::Mixed, MassVariant::Mod3, cn),
        (
            "kane",
            ContactMethod::Mixed,
            MassVariant::Consistent,
            Scheme::Kane,
        ),
        (
            "contact-stabilized-newmark",
            ContactMethod::Mixed,
            MassVariant::Consistent,
            Scheme::ContactStabilizedNewmark,
        ),
        (
            "generalized-alpha ρ∞ = ½",
            ContactMethod::Mixed,
            MassVariant::Consistent,
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::from_rho_inf(0.5)),
        ),
        (
            "moreau-jean θ = ½",
            ContactMethod::Mixed,
            MassVariant::Consistent,
            Scheme::MoreauJean(MoreauJeanParams {
                theta: 0.5,
                restitution: 0.0,
            }),
        ),
        (
            "central-difference (lumped)",
            ContactMethod::Mixed,
            MassVariant::Lumped,
            Scheme::Newmark(NewmarkParams::central_difference()),
        ),
        (
            "penalty γ0 = 10 + CN",
            ContactMethod::Penalty { gamma0: 10.0 },
            MassVariant::Consistent,
            cn,
        ),
    ];
    let opts = RunOptions {
        series_every: 0,
        ..RunOptions::default()
    };
    println!("friction-ratio: layer1d, m = 1000, 2000 steps, medians of 7 alternating rounds");
    println!(
        "{:<30} {:>12} {:>12} {:>8}",
        "method", "none (s)", "coulomb (s)", "ratio"
    );
    for (name, method, mass, scheme) in cases {
        let none = config(FrictionLaw::None, method, mass.clone(), scheme);
        let coulomb = config(
            FrictionLaw::Coulomb { coefficient: 0.1 },
            method,
            mass,
            scheme,
        );
        time(&none, &opts);
        time(&coulomb, &opts);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for _ in 0..7 {
            a.push(time(&none, &opts));
            b.push(time(&coulomb, &opts));
        }
        let (ma, mb) = (median(a), median(b));
        println!("{name:<30} {ma:>12.4} {mb:>12.4} {:>8.3}", mb / ma);
    }
}
