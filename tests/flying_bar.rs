//! The flying bar (SPEC §1.4): its closed form on its own, the exactness of its error norms,
//! Siconos' steel bar run from its sweep file in SI units, and convergence in h = cτ.
//!
//! Every tolerance is relative to the bar's own scales (length L, time L/c, speed V, pressure
//! ρcV, energy ½ρLV²): the tests run the closed form with non-unit parameters and in SI units.

mod common;

use common::*;
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{NewmarkParams, Scheme};

const CN: Scheme = Scheme::Newmark(NewmarkParams {
    beta: 0.25,
    gamma: 0.5,
});

/// Siconos' ImpactingBar (SPEC §1.4).
fn siconos() -> BarParams {
    BarParams {
        length: 1.0,
        young: 210e9,
        density: 7800.0,
        amplitude: 0.0,
        gap: 5e-5,
        free_end: true,
        velocity: -0.1,
    }
}

/// A non-unit bar with L/c = 0.8 and V = 0.3.
fn odd_bar() -> BarParams {
    BarParams {
        length: 2.0,
        young: 2.5,
        density: 0.4,
        amplitude: 0.0,
        gap: 0.15,
        free_end: true,
        velocity: -0.3,
    }
}

/// Midpoint-rule integrals over (0, L) of ρu_t (momentum) and ½(ρu_t² + E u_x²) (energy) at t.
/// Both integrands are piecewise constant in x with jumps at the two fronts only, so the rule
/// is exact but for the ≤ 2 cells holding a front: relative error ≤ 2/n.
fn momentum_energy(p: &BarParams, t: f64, n: usize) -> (f64, f64) {
    let ex = p.exact().unwrap();
    let dx = p.length / n as f64;
    let (mut mom, mut en) = (0.0, 0.0);
    for i in 0..n {
        let x = (i as f64 + 0.5) * dx;
        let (ut, ux) = (ex.u_t(x, t), ex.u_x(x, t));
        mom += p.density * ut * dx;
        en += 0.5 * (p.density * ut * ut + p.young * ux * ux) * dx;
    }
    (mom, en)
}

#[test]
fn exact_solution_fronts_contact_momentum_energy() {
    for p in [odd_bar(), siconos()] {
        let ex = p.exact().expect("the flying bar has a closed form");
        let (c, v, l, g) = (p.wave_speed(), -p.velocity, p.length, p.gap);
        let (t_c, dur) = ex.contact_interval().unwrap();
        assert_eq!(t_c, g / v);
        assert_eq!(dur, 2.0 * l / c);
        let tl = l / c;
        // Continuity across both fronts, x = c s and x = 2L − c s, at s = 0.3 L/c and
        // 1.4 L/c: u jumps by nothing; a slope of V/c over 2ε·L is the only difference
        // (ε = 1e-9, so |Δu| ≤ 2e-9·V·L/c; 1e-8·V·L/c leaves room for round-off of g).
        for (frac, front) in [(0.3, 0.3 * l), (1.4, 2.0 * l - 1.4 * l)] {
            let t = t_c + frac * tl;
            let eps = 1e-9 * l;
            let (a, b) = (ex.u(front - eps, t), ex.u(front + eps, t));
            assert!((a - b).abs() < 1e-8 * v * tl, "jump at x = {front}: {a} vs {b}");
            // ... while the strain does jump there (it is a front): V/c on one side only.
            assert_ne!(ex.u_x(front - eps, t), ex.u_x(front + eps, t));
        }
        // u(0, t) = −g throughout the contact, with σ(0, t) = −ρcV; before it the rigid
        // flight −Vt, after it −g + V(t − t_c − 2L/c); σ = 0 outside. Values are sums of two
        // or three roundings of numbers of size g: 1e-12·g.
        for k in 1..20 {
            let t = t_c + dur * k as f64 / 20.0;
            assert!((ex.u(0.0, t) + g).abs() <= 1e-12 * g, "u(0,{t})");
            let sig = ex.contact_stress(t);
            assert!((sig + p.density * c * v).abs() <= 1e-12 * p.density * c * v);
        }
        for t in [0.0, 0.5 * t_c, 0.99 * t_c] {
            assert!((ex.u(0.3 * l, t) + v * t).abs() <= 1e-12 * g);
            assert_eq!(ex.contact_stress(t), 0.0);
        }
        let t_after = t_c + 1.3 * dur;
        assert!((ex.u(0.7 * l, t_after) - (-g + v * 0.3 * dur)).abs() <= 1e-12 * g);
        assert_eq!(ex.contact_stress(t_after), 0.0);
        // Steps landing on either end of the contact take σ = 0 (SPEC §1.4).
        assert_eq!(ex.contact_stress(t_c), 0.0);
        assert_eq!(ex.contact_stress(t_c + dur), 0.0);
        // Momentum −ρLV before, +ρLV after, and energy ½ρLV² at every time (midpoint rule on
        // 2e5 cells: 2/n = 1e-5 relative at the fronts).
        let n = 200_000;
        let (p0, e0) = (p.density * l * v, 0.5 * p.density * l * v * v);
        assert!((ex.energy() - e0).abs() <= 1e-15 * e0);
        for (t, mom) in [
            (0.5 * t_c, -p0),
            (t_c + 1.2 * dur, p0),
            (t_c + 3.0 * dur, p0),
        ] {
            let (m, _) = momentum_energy(&p, t, n);
            assert!((m - mom).abs() <= 1e-5 * p0, "momentum at t = {t}: {m} vs {mom}");
        }
        for k in 0..=12 {
            let t = t_c + (k as f64 / 8.0 - 0.25) * dur;
            let (_, e) = momentum_energy(&p, t, n);
            assert!((e - e0).abs() <= 2e-5 * e0, "energy at t = {t}: {e} vs {e0}");
        }
    }
}

/// ∫(I_h u − u)² and ∫((I_h u)' − u')² over one element [xa, xb] holding one kink k of u:
/// the error of the chord is a tent, 0 at both nodes and δ at the kink, so ∫e² = (xb − xa)δ²/3
/// and ∫e'² = δ²/(k − xa) + δ²/(xb − k). Independent of the engine's piece-by-piece sum.
fn tent(xa: f64, xb: f64, k: f64, delta: f64) -> (f64, f64) {
    (
        (xb - xa) * delta * delta / 3.0,
        delta * delta / (k - xa) + delta * delta / (xb - k),
    )
}

#[test]
fn error_norms_are_integrated_exactly_at_the_fronts() {
    let p = odd_bar();
    let ex = p.exact().unwrap();
    let (c, l) = (p.wave_speed(), p.length);
    let (t_c, _) = ex.contact_interval().unwrap();
    let m = 20;
    let h = l / m as f64;
    let interp = |t: f64| -> Vec<f64> { (0..=m).map(|i| ex.u(i as f64 * h, t)).collect() };
    let scale_l2 = (p.gap * p.gap * l).max(1e-300);
    // Aligned: at s = 0.35 L/c the compression front sits on node 7 (x = 0.35 L), the other
    // front is outside; at s = 1.25 L/c the unloading front sits on node 15. The interpolant
    // is then the exact solution (affine between nodes): both norms vanish to round-off
    // (values of size g summed over 20 elements: 1e-28·g²L).
    for s in [0.35 * l / c, 1.25 * l / c] {
        let t = t_c + s;
        let (l2, h1) = ex.error_sq(&interp(t), h, t);
        assert!(l2 <= 1e-28 * scale_l2, "aligned, s = {s}: L2² = {l2}");
        assert!(h1 <= 1e-24 * p.velocity.powi(2) / c / c * l, "aligned: H1² = {h1}");
    }
    // Not aligned: at s = 0.33 L/c the front x = 0.33 L lies inside element 6 (0.3 L, 0.35 L),
    // one tent there and nothing elsewhere; at s = 1.27 L/c the front x = 0.73 L lies inside
    // element 14 (0.7 L, 0.75 L).
    for (s, el) in [(0.33 * l / c, 6usize), (1.27 * l / c, 14)] {
        let t = t_c + s;
        let k = if s < l / c { c * s } else { 2.0 * l - c * s };
        let (xa, xb) = (el as f64 * h, (el + 1) as f64 * h);
        let chord = ex.u(xa, t) + (ex.u(xb, t) - ex.u(xa, t)) * (k - xa) / h;
        let (want_l2, want_h1) = tent(xa, xb, k, chord - ex.u(k, t));
        let (l2, h1) = ex.error_sq(&interp(t), h, t);
        // Same integrals by two roundings-apart formulas: 1e-12 relative.
        assert!(
            (l2 - want_l2).abs() <= 1e-12 * want_l2,
            "s = {s}: L2² {l2} vs tent {want_l2}"
        );
        assert!(
            (h1 - want_h1).abs() <= 1e-12 * want_h1,
            "s = {s}: H1² {h1} vs tent {want_h1}"
        );
    }
    // An arbitrary nodal field against a brute-force midpoint rule on 4e5 cells: the
    // integrands are piecewise quadratic / constant with jumps only at the ≤ 2 fronts and the
    // nodes, so the rule errs by O(1/n²) away from them and O(1/n) at them: 1e-5 relative.
    let nodal: Vec<f64> = (0..=m)
        .map(|i| p.gap * (0.3 * (i as f64).cos() - 1.1))
        .collect();
    for t in [0.5 * t_c, t_c + 0.33 * l / c, t_c + 1.27 * l / c, t_c + 2.6 * l / c] {
        let (l2, h1) = ex.error_sq(&nodal, h, t);
        let n = 400_000;
        let dx = l / n as f64;
        let (mut bl2, mut bh1) = (0.0, 0.0);
        for i in 0..n {
            let x = (i as f64 + 0.5) * dx;
            let k = ((x / h) as usize).min(m - 1);
            let (ua, ub) = (nodal[k], nodal[k + 1]);
            let uh = ua + (ub - ua) * (x - k as f64 * h) / h;
            bl2 += (uh - ex.u(x, t)).powi(2) * dx;
            bh1 += ((ub - ua) / h - ex.u_x(x, t)).powi(2) * dx;
        }
        assert!((l2 - bl2).abs() < 1e-5 * bl2, "t={t}: L2² {l2} vs {bl2}");
        assert!((h1 - bh1).abs() < 1e-5 * bh1, "t={t}: H1² {h1} vs {bh1}");
    }
}

/// Other combinations of the new keys have no closed form (SPEC §1.4): errors null.
#[test]
fn no_closed_form_means_null_errors() {
    let clamped_moving = BarParams {
        velocity: -0.5,
        ..BarParams::default()
    };
    let free_strained = BarParams {
        free_end: true,
        ..BarParams::default()
    };
    for p in [clamped_moving, free_strained] {
        assert!(p.exact().is_none());
        let o = ok(bar1d(
            p,
            10,
            0.05,
            1.0,
            ContactMethod::Mixed,
            MassVariant::Mod3,
            CN,
            0,
        ));
        assert_eq!(o.metrics.err_u_l2l2, None);
        assert_eq!(o.metrics.err_sigma_l2, None);
    }
}
