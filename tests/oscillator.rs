//! The impact oscillator (SPEC §1.5): its exact solution on its own (impact times by hand,
//! energy, Zeno accumulation), and what the schemes do against it.

mod common;

use contact_sweep::run::oscillator::OscillatorConfig;
use contact_sweep::run::{Outcome, RunConfig, RunOptions, Status, simulate};
use contact_sweep::scene::OscillatorParams;
use contact_sweep::space::ContactMethod;
use contact_sweep::time::{NewmarkParams, PaoliSchatzmanParams, Scheme};
use std::f64::consts::PI;

fn run(
    p: OscillatorParams,
    dt: f64,
    t_final: f64,
    method: ContactMethod,
    scheme: Scheme,
) -> Outcome {
    let o = simulate(
        &RunConfig::Oscillator(OscillatorConfig::new(p, dt, t_final, method, scheme)),
        &RunOptions {
            series_every: 1,
            timeout: None,
            cancel: None,
        },
    );
    assert_eq!(o.status, Status::Ok, "{:?}", o.message);
    o
}

#[test]
fn exact_impact_times_by_hand_and_energy_for_e_1() {
    // Defaults: x = −sin t hits x = −½ at t = π/6 with speed cos(π/6); reflected, the flight
    // above the obstacle lasts 2·acos(−½) = 4π/3: impacts at π/6 + j·4π/3. Sums of a few
    // roundings of numbers ≤ 4π/3·j: 1e-13.
    let p = OscillatorParams::default();
    let ex = p.exact(20.0);
    let want: Vec<f64> = (0..)
        .map(|j| PI / 6.0 + j as f64 * 4.0 * PI / 3.0)
        .take_while(|t| *t <= 20.0)
        .collect();
    assert_eq!(ex.impacts().len(), want.len());
    assert_eq!(want.len(), 5);
    for (a, b) in ex.impacts().iter().zip(&want) {
        assert!((a - b).abs() < 1e-13, "impact {a} vs {b}");
    }
    assert_eq!(ex.rest_time(), None);
    // Between impacts x = −½ … 1 and the energy ½ is conserved (e = 1), also with a load:
    // f = −0.3 (x_e = −0.3 above the obstacle) keeps ½mv² + ½kx² − fx to round-off (1e-14
    // relative of E ≈ 0.5).
    let mut cur = 0;
    for i in 0..=2000 {
        let t = i as f64 * 0.01;
        let (x, v) = ex.state(t, &mut cur);
        assert!(x >= -0.5 - 1e-15, "x({t}) = {x} below the obstacle");
        assert!((p.energy(x, v) - 0.5).abs() < 1e-14, "E({t})");
    }
    let loaded = OscillatorParams {
        force: -0.3,
        ..OscillatorParams::default()
    };
    let ex = loaded.exact(30.0);
    assert!(ex.impacts().len() >= 5);
    let mut cur = 0;
    let e0 = loaded.energy(0.0, -1.0);
    for i in 0..=3000 {
        let (x, v) = ex.state(i as f64 * 0.01, &mut cur);
        assert!((loaded.energy(x, v) - e0).abs() < 1e-14 * e0.abs().max(1.0));
    }
}

#[test]
fn zeno_accumulation_and_rest() {
    // f = −2 pushes into the obstacle (x_e = −2 < −g = −½) and e = ½: the rebound speeds fall
    // geometrically and the flights with them. By hand: x = −2 + 2cos t − sin t reaches −½ at
    // 2cos t − sin t = 3/2, t₁ = acos(3/(2√5)) − atan(½); impact speed u₁ from the energy,
    // u₁² = v0² + ω²(x0 + g)(x0 − g − 2x_e) = 1 + ½·3.5 = 2.75; after the j-th rebound (speed
    // w_j = u₁/2^j) the flight is 2·atan(w_j/d)/ω with d = −g − x_e = 3/2, and the impact
    // speed equals the rebound speed. The rest time is t₁ plus the sum of the flights.
    let p = OscillatorParams {
        force: -2.0,
        impact_law: 0.5,
        ..OscillatorParams::default()
    };
    let ex = p.exact(10.0);
    let t1 = (3.0 / (2.0 * 5f64.sqrt())).acos() - 0.5f64.atan();
    assert!(
        (ex.impacts()[0] - t1).abs() < 1e-14,
        "{} vs {t1}",
        ex.impacts()[0]
    );
    let u1 = 2.75f64.sqrt();
    let mut t_rest = t1;
    let mut k = 0;
    // The exact solution stops at a rebound below 1e-14·|v0|: the same impacts.
    while u1 * 0.5f64.powi(k + 1) > 1e-14 {
        k += 1;
        t_rest += 2.0 * (u1 * 0.5f64.powi(k) / 1.5).atan();
    }
    assert_eq!(ex.impacts().len(), k as usize + 1);
    let rest = ex.rest_time().expect("Zeno: the mass comes to rest");
    // Sums of ~47 flights, each to a few roundings: 1e-13.
    assert!((rest - t_rest).abs() < 1e-13, "rest at {rest} vs {t_rest}");
    // The accumulation point against the geometric-series estimate: for short flights
    // atan(w/d) ≈ w/d, Σ 2w_j/d = 2u₁/d·(1/(1 − ½) − 1) = 2u₁/1.5 — the arctangent makes the
    // real sum shorter, by ≤ Σ (w_j/d)³·2/3 ≈ 0.14.
    let approx = t1 + 2.0 * u1 / 1.5;
    assert!(rest < approx && rest > approx - 0.15, "{rest} vs {approx}");
    // Resting afterwards: x = −g, v = 0.
    let mut cur = 0;
    for t in [rest + 1e-9, rest + 1.0, 9.9] {
        let (x, v) = ex.state(t, &mut cur);
        assert_eq!((x, v), (-0.5, 0.0));
    }
}

const CN: Scheme = Scheme::Newmark(NewmarkParams {
    beta: 0.25,
    gamma: 0.5,
});

fn ps(e: f64) -> Scheme {
    Scheme::PaoliSchatzman(PaoliSchatzmanParams {
        beta: 0.25,
        restitution: e,
    })
}

/// Errors of a scheme over a τ ladder (ω = 1, T = 10: seven impacts for e_x = 1).
fn ladder(p: OscillatorParams, method: ContactMethod, scheme: Scheme) -> Vec<(f64, f64, f64, f64)> {
    [0.02, 0.01, 0.005, 0.0025, 0.00125]
        .iter()
        .map(|&dt| {
            let o = run(p, dt, 10.0, method, scheme);
            let m = &o.metrics;
            (
                dt,
                m.err_u_l2l2.unwrap(),
                m.err_v_l2.unwrap(),
                m.err_impact_time.unwrap(),
            )
        })
        .collect()
}

fn rate(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.1 / b.1).ln() / (a.0 / b.0).ln()
}
