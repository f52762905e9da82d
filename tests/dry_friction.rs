//! The dry-friction oscillator's exact solution (SPEC §1.5, Siconos' FrictionOscillator) on
//! its own: SPEC's setting (turning points, stop time and position), the energy lost at each
//! half oscillation, the equation of motion between events, impacts with friction, and F = 0
//! equal to the frictionless closed form.

use contact_sweep::scene::{DryFrictionExact, OscillatorParams};

fn spec_setting() -> OscillatorParams {
    OscillatorParams {
        x0: 12.0,
        v0: 6.0,
        gap: 1e3,
        ..OscillatorParams::default()
    }
}

/// m = k = 1, f = 0, x0 = 12, v0 = 6, F = 1, a far obstacle: the first turning point is
/// −1 + √205 (the centre −1, the radius √(13² + 6²)), each next one mirrors about ∓1, and the
/// eighth, 15 − √205 = 0.68218, has |k x| ≤ F: the stop, at atan2(6, 13) + 7π = 22.4236.
/// Sums of a few closed-form terms: 1e-12.
#[test]
fn spec_stop_time_and_position() {
    let e = DryFrictionExact::new(spec_setting(), 1.0, 40.0);
    let r = 205f64.sqrt();
    let want = [
        -1.0 + r,
        3.0 - r,
        -5.0 + r,
        7.0 - r,
        -9.0 + r,
        11.0 - r,
        -13.0 + r,
        15.0 - r,
    ];
    let tp = e.turning_points();
    assert_eq!(tp.len(), 8, "{tp:?}");
    for (j, ((t, x), w)) in tp.iter().zip(want).enumerate() {
        assert!((x - w).abs() < 1e-12, "turning point {j}: {x} vs {w}");
        let t_want = 6f64.atan2(13.0) + j as f64 * std::f64::consts::PI;
        assert!(
            (t - t_want).abs() < 1e-12,
            "turning time {j}: {t} vs {t_want}"
        );
    }
    let (t_stop, x_stop) = e.stop().unwrap();
    assert!((t_stop - 22.4236).abs() < 5e-5, "{t_stop}");
    assert!((x_stop - 0.68218).abs() < 5e-6, "{x_stop}");
    assert!((x_stop - (15.0 - r)).abs() < 1e-12);
    // At rest for good.
    assert_eq!(e.state(t_stop + 3.0), (x_stop, 0.0));
    assert!(e.impacts().is_empty());
}

/// Between two turning points the mechanical energy drops by exactly the friction's work
/// F·|x_{j+1} − x_j| (energies of size ~100: 1e-12 relative).
#[test]
fn each_half_oscillation_loses_the_friction_work() {
    let e = DryFrictionExact::new(spec_setting(), 1.0, 40.0);
    let mut prev = (0.0, 12.0);
    for &(t, x) in e.turning_points() {
        let lost = e.energy(prev.0) - e.energy(t);
        assert!(
            (lost - (x - prev.1).abs()).abs() < 1e-12 * e.energy(0.0),
            "{lost} vs {}",
            (x - prev.1).abs()
        );
        prev = (t, x);
    }
}

/// Away from the events, m ẍ + k x = f − F·sign(ẋ): a centred second difference over δ = 1e-4
/// is exact to O(δ²·ω⁴|x|) ≈ 1e-7 plus round-off 4·1e-16·14/δ² ≈ 6e-7: 1e-5.
#[test]
fn the_motion_solves_the_equation_between_events() {
    let p = OscillatorParams {
        force: 0.3,
        stiffness: 2.0,
        mass: 0.5,
        ..spec_setting()
    };
    let f = 0.7;
    let e = DryFrictionExact::new(p, f, 40.0);
    let (t_stop, _) = e.stop().unwrap();
    let d = 1e-4;
    let mut checked = 0;
    for i in 1..2000 {
        let t = t_stop * i as f64 / 2000.0;
        if e.turning_points()
            .iter()
            .any(|(tj, _)| (tj - t).abs() < 3.0 * d)
        {
            continue;
        }
        let (x, v) = e.state(t);
        let acc = (e.state(t + d).0 - 2.0 * x + e.state(t - d).0) / (d * d);
        let residual = p.mass * acc + p.stiffness * x - p.force + f * v.signum();
        assert!(residual.abs() < 1e-5, "t = {t}: residual {residual}");
        checked += 1;
    }
    assert!(checked > 1900);
}

/// With the obstacle in reach: the mass meets x = −g moving down and leaves it with the
/// speed reversed (e_x = 1), friction acting in both flights.
#[test]
fn impacts_reverse_the_velocity() {
    let p = OscillatorParams {
        gap: 0.5,
        x0: 0.0,
        v0: -1.0,
        ..OscillatorParams::default()
    };
    let e = DryFrictionExact::new(p, 0.1, 5.0);
    let hit = e.impacts()[0];
    let (x_before, v_before) = e.state(hit - 1e-9);
    let (x_after, v_after) = e.state(hit + 1e-9);
    // Within 1e-9 of the impact the position moves by |v|·1e-9.
    assert!((x_before + 0.5).abs() < 2e-9 && (x_after + 0.5).abs() < 2e-9);
    assert!(v_before < 0.0 && v_after > 0.0);
    assert!((v_before + v_after).abs() < 1e-8, "{v_before} {v_after}");
    // Energy from the start to the impact: ½v0² − F·(g) = ½v² − ½k g² (f = 0).
    let want = (1.0 - 2.0 * 0.1 * 0.5 - 0.25f64).sqrt();
    assert!((v_before.abs() - want).abs() < 1e-8, "{v_before} vs {want}");
}

/// F = 0 is the frictionless oscillator's closed form (one rounding per evaluation: 1e-12).
#[test]
fn zero_friction_is_the_frictionless_solution() {
    let p = OscillatorParams::default();
    let e = DryFrictionExact::new(p, 0.0, 10.0);
    let free = p.exact(10.0);
    let mut cursor = 0;
    for i in 0..=500 {
        let t = 10.0 * i as f64 / 500.0;
        let (x, v) = e.state(t);
        let (xf, vf) = free.state(t, &mut cursor);
        assert!((x - xf).abs() < 1e-12 && (v - vf).abs() < 1e-12, "t = {t}");
    }
    assert_eq!(e.impacts().len(), free.impacts().len());
    assert!(e.stop().is_none());
}
