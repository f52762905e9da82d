//! The closed form of the bar (contract §1.1) and the exactness of the error norms.

mod common;

use common::*;
use contact_sweep::run::Grid1d;
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{NewmarkParams, Scheme};

const CN: Scheme = Scheme::Newmark(NewmarkParams {
    beta: 0.25,
    gamma: 0.5,
});

// The reference solution is piecewise affine with breakpoints at rationals: values at the
// kinks are exact up to a few roundings (1e-14).
#[test]
fn exact_solution_at_kinks_and_across_periods() {
    let ex = BarParams::default().exact().unwrap();
    // Contact node: ½ − t/2 before impact, 0 in contact (t ∈ [1, 2]), (t−2)/2 after.
    for (t, u) in [
        (0.0, 0.5),
        (0.5, 0.25),
        (1.0, 0.0),
        (1.5, 0.0),
        (2.0, 0.0),
        (2.5, 0.25),
        (3.0, 0.5),
    ] {
        assert!((ex.u(0.0, t) - u).abs() < 1e-14, "u(0,{t})");
        // periodic with period 3
        assert!((ex.u(0.0, t + 3.0) - u).abs() < 1e-14);
        assert!((ex.u(0.0, t + 9.0) - u).abs() < 1e-13);
    }
    assert_eq!(ex.period(), 3.0);
    // Continuity across the characteristic kinks x = f and x = 1 − f at t = 1.3 (f = 0.3).
    for xk in [0.3, 0.7] {
        let (a, b) = (ex.u(xk - 1e-12, 1.3), ex.u(xk + 1e-12, 1.3));
        assert!((a - b).abs() < 1e-11, "jump at x = {xk}: {a} vs {b}");
    }
    // Contact stress −aE/L during contact, 0 otherwise.
    assert!((ex.contact_stress(1.2) + 0.5).abs() < 1e-15);
    assert_eq!(ex.contact_stress(0.8), 0.0);
    assert_eq!(ex.contact_stress(2.2), 0.0);
}

#[test]
fn exact_solution_conserves_energy_and_satisfies_the_wave_equation() {
    let p = BarParams {
        length: 2.0,
        young: 4.0,
        density: 0.25,
        amplitude: 0.3,
        gap: 0.0,
        ..BarParams::default()
    };
    let ex = p.exact().unwrap();
    // ½∫ρu_t² + E u_x² by the midpoint rule on 2e5 cells: the integrand is piecewise constant,
    // so the rule is exact except on the ≤ 2 cells containing a kink (error ≤ 2/2e5 relative).
    for t in [0.0, 0.2, 0.8, 1.1, 1.6, 2.9] {
        let n = 200_000;
        let dx = p.length / n as f64;
        let mut e = 0.0;
        for i in 0..n {
            let x = (i as f64 + 0.5) * dx;
            e += 0.5 * (p.density * ex.u_t(x, t).powi(2) + p.young * ex.u_x(x, t).powi(2)) * dx;
        }
        assert!(
            (e - ex.energy()).abs() < 2e-5 * ex.energy(),
            "t={t}: {e} vs {}",
            ex.energy()
        );
    }
    // u_t from a central difference (u is affine in t between kinks).
    let (x, t, d) = (0.37, 0.9, 1e-7);
    let fd = (ex.u(x, t + d) - ex.u(x, t - d)) / (2.0 * d);
    assert!((fd - ex.u_t(x, t)).abs() < 1e-6);
}

#[test]
fn error_norms_are_integrated_exactly() {
    let ex = BarParams::default().exact().unwrap();
    let m = 7;
    let h = 1.0 / m as f64;
    let nodal: Vec<f64> = (0..m).map(|i| 0.3 * (i as f64).cos() - 0.1).collect();
    for t in [0.0, 0.45, 1.3, 2.71] {
        let (l2, h1) = ex.error_sq(&nodal, h, t);
        // Brute force: midpoint rule on 7e5 cells; the integrands are piecewise quadratic /
        // constant, so the error is O(1/n²) away from the ≤ 2m kinks, O(1/n) at them: 1e-5.
        let n = 700_000;
        let dx = 1.0 / n as f64;
        let (mut bl2, mut bh1) = (0.0, 0.0);
        for i in 0..n {
            let x = (i as f64 + 0.5) * dx;
            let k = ((x / h) as usize).min(m - 1);
            let (ua, ub) = (nodal[k], if k + 1 < m { nodal[k + 1] } else { 0.0 });
            let uh = ua + (ub - ua) * (x - k as f64 * h) / h;
            let duh = (ub - ua) / h;
            bl2 += (uh - ex.u(x, t)).powi(2) * dx;
            bh1 += (duh - ex.u_x(x, t)).powi(2) * dx;
        }
        assert!(
            (l2 - bl2).abs() < 1e-5 * bl2.max(1e-3),
            "t={t}: L2² {l2} vs {bl2}"
        );
        assert!(
            (h1 - bh1).abs() < 1e-5 * bh1.max(1e-3),
            "t={t}: H1² {h1} vs {bh1}"
        );
    }
}

/// The discrete problem with (L, E, ρ, a) maps exactly onto the default one when h/L and c0τ/L
/// are kept: A = ρL·Â and u = 2a·û. So the scaled run's errors are the default's times known
/// factors — to round-off (1e-10 relative).
#[test]
fn non_default_bar_scales_exactly_onto_the_default() {
    let p = BarParams {
        length: 2.5,
        young: 9.0,
        density: 4.0,
        amplitude: 0.2,
        gap: 0.0,
        ..BarParams::default()
    };
    let c0 = p.wave_speed();
    let mut rates = Vec::new();
    for (m, nu) in [(20usize, 1.0), (40, 1.0), (80, 1.0), (40, 0.5)] {
        let dt_hat = nu / m as f64;
        let d = ok(bar1d(
            BarParams::default(),
            Grid1d::new(m, dt_hat, 12.0, ContactMethod::Mixed, MassVariant::Mod3, CN),
            1,
        ));
        let s = ok(bar1d(
            p,
            Grid1d::new(
                m,
                dt_hat * p.length / c0,
                12.0 * p.length / c0,
                ContactMethod::Mixed,
                MassVariant::Mod3,
                CN,
            ),
            1,
        ));
        assert_eq!(d.metrics.steps, s.metrics.steps);
        let (a, l) = (p.amplitude, p.length);
        // err_u_l2l2 = 2a·sqrt(L·L/c0)·êrr (u scales by 2a, dx by L, τ by L/c0).
        let f_l2 = 2.0 * a * (l * l / c0).sqrt();
        let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
        assert!(
            rel(
                s.metrics.err_u_l2l2.unwrap(),
                f_l2 * d.metrics.err_u_l2l2.unwrap()
            ) < 1e-10
        );
        assert!(
            rel(
                s.metrics.err_u_contact_max.unwrap(),
                2.0 * a * d.metrics.err_u_contact_max.unwrap()
            ) < 1e-9
        );
        // σ = E u_x scales by 2aE/L, τ by L/c0.
        let f_sig = 2.0 * a * p.young / l * (l / c0).sqrt();
        assert!(
            rel(
                s.metrics.err_sigma_l2.unwrap(),
                f_sig * d.metrics.err_sigma_l2.unwrap()
            ) < 1e-9
        );
        // Contact displacement time series, step by step, against the exact solution.
        for (rs, rd) in s.series.rows().zip(d.series.rows()) {
            assert!((rs.u_contact - 2.0 * a * rd.u_contact).abs() < 1e-12);
            assert!(
                (rs.u_contact_exact.unwrap() - 2.0 * a * rd.u_contact_exact.unwrap()).abs() < 1e-14
            );
        }
        if nu == 1.0 {
            rates.push((l / m as f64, s.metrics.err_u_l2l2.unwrap()));
        }
    }
    // The contact displacement itself against the closed form of the scaled bar over four
    // impacts: max error 14.2 % of the amplitude at m = 20 and 5.4 % at m = 80 (the phase error
    // of mod3 + CN accumulates over the periods), i.e. a rate of 0.70 like the L2 error. Bounds:
    // below 6 % at m = 80, and a rate above 0.5.
    let contact_err = |m: usize| {
        let o = ok(bar1d(
            p,
            Grid1d::new(
                m,
                (1.0 / m as f64) * p.length / c0,
                12.0 * p.length / c0,
                ContactMethod::Mixed,
                MassVariant::Mod3,
                CN,
            ),
            1,
        ));
        o.series
            .rows()
            .map(|r| (r.u_contact - r.u_contact_exact.unwrap()).abs())
            .fold(0.0, f64::max)
            / p.amplitude
    };
    let (coarse, fine) = (contact_err(20), contact_err(80));
    let rate = (coarse / fine).ln() / 4f64.ln();
    assert!(
        fine < 0.06 && rate > 0.5,
        "relative contact errors {coarse} → {fine} (rate {rate})"
    );
    // …and so the scaled errors shrink at the default's rate: ≈ 0.7–0.9 in L2 (contract §6).
    let r = (rates[0].1 / rates[2].1).ln() / (rates[0].0 / rates[2].0).ln();
    assert!((0.6..1.1).contains(&r), "L2 rate {r}");
}

#[test]
fn mass_totals_reported_per_run() {
    let m = 10;
    let h = 0.1;
    for (mass, total) in [
        (MassVariant::Consistent, 1.0),
        (MassVariant::Lumped, 1.0),
        (MassVariant::Mod1, 1.0 - h),
        (MassVariant::Mod2, 1.0),
        (MassVariant::Mod3, 1.0),
        (MassVariant::Weights(vec![1.5, 1.0]), 1.0 - h + 0.5 * h),
    ] {
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(m, 0.05, 1.0, ContactMethod::Mixed, mass.clone(), CN),
            0,
        ));
        // A sum of 4m entries of size ≤ h: round-off ≤ 4m·ε ≈ 1e-14.
        assert!(
            (o.metrics.mass_total.unwrap() - total).abs() < 1e-14,
            "{mass:?}"
        );
    }
}
