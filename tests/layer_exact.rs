//! The frictional layer's exact solution (contract §1.7) on its own, before any method is measured
//! against it: the bulk wave equations (characteristic invariants, the displacement's
//! derivatives), the free top, the initial state, Signorini and the friction law at the base
//! (stick and slip, Coulomb and Tresca), the energy identity E + W_f = E⁰, the mean tangential
//! velocity after the impact, and the exact error integration against brute force — at the
//! defaults and on a non-default material.

use contact_sweep::contact::friction::FrictionLaw;
use contact_sweep::scene::{LayerExact, LayerParams, PlaneWave};

fn layer(v_t: f64, friction: FrictionLaw) -> LayerExact {
    LayerParams {
        velocity_tangential: v_t,
        friction,
        ..LayerParams::default()
    }
    .exact()
    .unwrap()
}

/// A non-default material, height, gap and velocities: c_p = √((0.7 + 2.6)/2.5) ≈ 1.149,
/// c_s = √(1.3/2.5) ≈ 0.721.
fn odd(v_t: f64, friction: FrictionLaw) -> LayerExact {
    LayerParams {
        height: 1.7,
        density: 2.5,
        lame_lambda: 0.7,
        lame_mu: 1.3,
        gap: 0.05,
        velocity: -0.8,
        velocity_tangential: v_t,
        friction,
    }
    .exact()
    .unwrap()
}

/// Deterministic uniform numbers in [0, 1) (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn cases() -> Vec<(&'static str, LayerExact)> {
    vec![
        (
            "default slip",
            layer(1.0, FrictionLaw::Coulomb { coefficient: 0.1 }),
        ),
        (
            "default stick",
            layer(0.3, FrictionLaw::Coulomb { coefficient: 0.3 }),
        ),
        ("default frictionless", layer(0.3, FrictionLaw::None)),
        (
            "odd coulomb slip",
            odd(-0.4, FrictionLaw::Coulomb { coefficient: 0.25 }),
        ),
        (
            "odd coulomb stick",
            odd(-0.4, FrictionLaw::Coulomb { coefficient: 0.9 }),
        ),
        (
            "odd tresca slip",
            odd(-0.4, FrictionLaw::Tresca { threshold: 0.3 }),
        ),
        (
            "odd tresca stick",
            odd(0.2, FrictionLaw::Tresca { threshold: 1.0 }),
        ),
    ]
}

/// contract §6's friction rows state the exact values: slip (V_t = 1, μ_f = 0.1): σ_t* = 0.2,
/// v_slip = 0.8, v̄_t⁺ = 0.8, E(T)/E⁰ = 0.84; stick (V_t = μ_f = 0.3): σ_t* = 0.3, v̄_t⁺ = 0,
/// E(T)/E⁰ = 1. The values are short binary-inexact decimals: a few ulps.
#[test]
fn the_default_slip_and_stick_values() {
    let s = layer(1.0, FrictionLaw::Coulomb { coefficient: 0.1 });
    assert!(!s.sticks());
    assert!((s.sigma_t_star() - 0.2).abs() < 1e-15);
    assert!((s.v_slip() - 0.8).abs() < 1e-15);
    assert!((s.mean_tangential_velocity_after() - 0.8).abs() < 1e-15);
    assert!((s.energy(2.5) / s.energy_initial() - 0.84).abs() < 1e-15);
    assert_eq!(s.contact_window(), (0.1, 1.0));
    let k = layer(0.3, FrictionLaw::Coulomb { coefficient: 0.3 });
    assert!(k.sticks());
    assert!((k.sigma_t_star() - 0.3).abs() < 1e-15);
    assert!(k.mean_tangential_velocity_after().abs() < 1e-15);
    assert_eq!(k.friction_work(2.5), 0.0);
    // Coulomb's v̄_t⁺ = V_t − min(2V_t c_s/c_p, 2μ_f V_n) (contract §1.7) on the odd material.
    for e in [
        odd(0.4, FrictionLaw::Coulomb { coefficient: 0.25 }),
        odd(0.4, FrictionLaw::Coulomb { coefficient: 0.9 }),
    ] {
        let p = e.params();
        let mu = match p.friction {
            FrictionLaw::Coulomb { coefficient } => coefficient,
            _ => unreachable!(),
        };
        let want = 0.4 - (2.0 * 0.4 * p.c_s() / p.c_p()).min(2.0 * mu * 0.8);
        assert!((e.mean_tangential_velocity_after() - want).abs() < 1e-14);
    }
}

/// The bulk: along dz/dt = ±c the invariants σ ∓ Z v are constant (the wave equation
/// ρ v_t = σ_z, σ_t = M v_z in characteristic form), and away from the fronts the displacement's
/// derivatives are the velocity and σ/M. The fields are piecewise affine, so a centred
/// difference over δ = 1e-6 is exact up to the rounding of the displacement (|d| ≲ 3, 3e-16/1e-6
/// ≈ 3e-10): 1e-8.
#[test]
fn the_fields_satisfy_the_wave_equations() {
    let mut rng = Rng(0x9e3779b97f4a7c15);
    for (name, e) in cases() {
        for wave in [e.normal(), e.tangential()] {
            let (h, c, z) = (wave.height, wave.c, wave.impedance);
            let modulus = z * c;
            for _ in 0..400 {
                let t = rng.next() * 4.0;
                let zz = rng.next() * h;
                let dt = (rng.next() - 0.5) * 0.5;
                // Upward characteristic: σ − Z v carried.
                let z2 = zz + c * dt;
                if z2 > 0.0 && z2 < h && t + dt > 0.0 {
                    let a = wave.stress(zz, t) - z * wave.velocity(zz, t);
                    let b = wave.stress(z2, t + dt) - z * wave.velocity(z2, t + dt);
                    assert!((a - b).abs() < 1e-12, "{name}: upward invariant {a} vs {b}");
                }
                let z3 = zz - c * dt;
                if z3 > 0.0 && z3 < h && t + dt > 0.0 {
                    let a = wave.stress(zz, t) + z * wave.velocity(zz, t);
                    let b = wave.stress(z3, t + dt) + z * wave.velocity(z3, t + dt);
                    assert!(
                        (a - b).abs() < 1e-12,
                        "{name}: downward invariant {a} vs {b}"
                    );
                }
                let d = 1e-6;
                let mut fronts = [0.0; 4];
                let n = wave.fronts(t, &mut fronts);
                let near_front = fronts[..n].iter().any(|f| (f - zz).abs() < 10.0 * c * d)
                    || wave_near_breakpoint(wave, zz, t, 10.0 * d);
                if near_front || zz < 2.0 * d || zz > h - 2.0 * d || t < 2.0 * d {
                    continue;
                }
                let d_t = (wave.displacement(zz, t + d) - wave.displacement(zz, t - d)) / (2.0 * d);
                let d_z = (wave.displacement(zz + d, t) - wave.displacement(zz - d, t)) / (2.0 * d);
                assert!(
                    (d_t - wave.velocity(zz, t)).abs() < 1e-8,
                    "{name}: u_t at ({zz}, {t})"
                );
                assert!(
                    (modulus * d_z - wave.stress(zz, t)).abs() < 1e-8 * modulus,
                    "{name}: σ at ({zz}, {t})"
                );
            }
        }
    }
}

/// Whether (z, t ± δ) may straddle a front: a breakpoint of q within δ of either argument.
fn wave_near_breakpoint(w: &PlaneWave, z: f64, t: f64, delta: f64) -> bool {
    [t - z / w.c, t + z / w.c - w.round_trip].iter().any(|a| {
        [w.t_c, w.t_c + w.duration].iter().any(|base| {
            let x = (a - base).rem_euclid(w.round_trip);
            x < delta || w.round_trip - x < delta
        })
    })
}

/// Initial state, free top, Signorini and the friction law at the base. Values are sums of
/// a few products of the data: 1e-14 relative to their scale.
#[test]
fn the_boundary_and_initial_conditions_hold() {
    for (name, e) in cases() {
        let p = *e.params();
        let (t_c, d) = e.contact_window();
        let v_n = -p.velocity;
        let scale_s = p.z_p() * v_n + p.z_s() * p.velocity_tangential.abs();
        for i in 0..=50 {
            let z = p.height * i as f64 / 50.0;
            assert_eq!(e.w(z, 0.0), 0.0, "{name}");
            assert_eq!(e.u(z, 0.0), 0.0, "{name}");
            assert_eq!(e.w_t(z, 0.0), p.velocity, "{name}");
            assert_eq!(e.u_t(z, 0.0), p.velocity_tangential, "{name}");
        }
        for i in 0..=4000 {
            let t = 5.0 * i as f64 / 4000.0;
            // Free top.
            assert!(
                e.sigma_n(p.height, t).abs() < 1e-14 * scale_s,
                "{name} t = {t}"
            );
            assert!(
                e.sigma_t(p.height, t).abs() < 1e-14 * scale_s,
                "{name} t = {t}"
            );
            // Signorini: w(0) ≥ −g, σ_n ≤ 0, complementarity.
            // The gap is a difference of displacements of size g + V_n t: its round-off.
            let scale_u = p.gap + v_n * t;
            let gap = e.w(0.0, t) + p.gap;
            assert!(
                gap >= -1e-14 * scale_u,
                "{name}: penetration {gap} at t = {t}"
            );
            let sn = e.base_sigma_n(t);
            assert!(sn <= 0.0);
            assert!(
                (gap * sn).abs() < 1e-14 * scale_u * scale_s,
                "{name} t = {t}"
            );
            // The base stress inside the window is the field's.
            if t > t_c + 1e-9 && t < t_c + d - 1e-9 {
                assert!((e.sigma_n(0.0, t) - sn).abs() < 1e-14 * scale_s, "{name}");
                assert!((e.sigma_t(0.0, t) - e.base_sigma_t(t)).abs() < 1e-14 * scale_s);
                assert!((e.u_t(0.0, t) - e.base_u_t(t)).abs() < 1e-14 * scale_s);
            } else if t < t_c - 1e-9 || t > t_c + d + 1e-9 {
                assert!(e.sigma_n(0.0, t).abs() < 1e-14 * scale_s, "{name} t = {t}");
                assert!(e.sigma_t(0.0, t).abs() < 1e-14 * scale_s, "{name} t = {t}");
            }
            // Friction: |σ_t| ≤ b = bound(f_n = −σ_n); the traction on the body −σ_t opposes
            // the slip where it slips, and the base does not move where it sticks.
            let b = p.friction.bound(-sn, 1.0);
            let st = e.base_sigma_t(t);
            assert!(
                st.abs() <= b * (1.0 + 1e-15),
                "{name}: |σ_t| = {st} > b = {b}"
            );
            if e.in_contact(t) {
                let slip = e.base_u_t(t);
                if e.sticks() {
                    assert_eq!(slip, 0.0);
                } else {
                    assert!(slip != 0.0);
                    assert!((st - b * slip.signum()).abs() < 1e-14 * scale_s, "{name}");
                }
            }
        }
        // The layer leaves at t_c + D with +V_n and never comes back.
        assert!((e.w_t(0.0, t_c + d + 1e-3) - v_n).abs() < 1e-14, "{name}");
    }
}

/// E(t) integrated over the fields piece by piece equals E⁰ − W_f(t) at every time, through
/// the contact and long after it, to round-off (sums of a few hundred terms of size E⁰: 1e-14).
#[test]
fn energy_plus_friction_work_is_the_initial_energy() {
    for (name, e) in cases() {
        let e0 = e.energy_initial();
        assert!((e.field_energy(0.0) - e0).abs() < 1e-15 * e0);
        for i in 0..=997 {
            let t = 7.0 * i as f64 / 997.0;
            let fields = e.field_energy(t);
            assert!(
                (fields - e.energy(t)).abs() < 1e-14 * e0,
                "{name}: t = {t}: fields {fields}, E⁰ − W_f {}",
                e.energy(t)
            );
        }
        // The mean tangential velocity is the momentum's: ∫ρu_t/(ρH), piecewise constant.
        let t = 6.3;
        let p = e.params();
        let n = 20000;
        let mean: f64 = (0..n)
            .map(|i| e.u_t(p.height * (i as f64 + 0.5) / n as f64, t))
            .sum::<f64>()
            / n as f64;
        // Midpoint sampling of a piecewise constant: error ≤ (fronts)·(jump)/n ≈ 4·2/2e4.
        assert!(
            (mean - e.mean_tangential_velocity_after()).abs() < 5e-4,
            "{name}: {mean} vs {}",
            e.mean_tangential_velocity_after()
        );
    }
}

/// The exact error integration (elements split at both components' fronts) against brute
/// force: 20000 midpoint samples per element. e is continuous and piecewise affine, so the
/// midpoint rule on e² is off by O(dz²) relative: 1e-6. e' jumps at the fronts (at most eight
/// at a time), where a midpoint cell errs by at most dz·|jump of e'²| ≤ dz·4B² (B = max|e'|):
/// the H1 bound is 8·dz·4B², stated in the assertion.
#[test]
fn error_norms_are_integrated_exactly() {
    let e = odd(-0.4, FrictionLaw::Coulomb { coefficient: 0.25 });
    let p = *e.params();
    let m = 7;
    let h = p.height / m as f64;
    for t in [0.03, 0.9, 1.77, 3.1] {
        // A P1 field that is not the interpolant: nodal values off by a smooth perturbation.
        let w: Vec<f64> = (0..=m)
            .map(|i| e.w(i as f64 * h, t) + 0.01 * (i as f64).sin())
            .collect();
        let u: Vec<f64> = (0..=m)
            .map(|i| e.u(i as f64 * h, t) - 0.02 * (i as f64 * 0.7).cos())
            .collect();
        let (l2, h1) = e.error_sq(&w, &u, h, t);
        let (mut bl2, mut bh1, mut bmax) = (0.0, 0.0, 0.0f64);
        let k = 20000;
        for el in 0..m {
            for j in 0..k {
                let dz = h / k as f64;
                let z = el as f64 * h + (j as f64 + 0.5) * dz;
                let xi = (z - el as f64 * h) / h;
                let wh = w[el] * (1.0 - xi) + w[el + 1] * xi;
                let uh = u[el] * (1.0 - xi) + u[el + 1] * xi;
                let ew = wh - e.w(z, t);
                let eu = uh - e.u(z, t);
                bl2 += dz * (ew * ew + eu * eu);
                let dw = (w[el + 1] - w[el]) / h - e.sigma_n(z, t) / p.p_modulus();
                let du = (u[el + 1] - u[el]) / h - e.sigma_t(z, t) / p.lame_mu;
                bh1 += dz * (dw * dw + du * du);
                bmax = bmax.max(dw.abs()).max(du.abs());
            }
        }
        let dz = h / k as f64;
        assert!((l2 - bl2).abs() < 1e-6 * bl2, "t = {t}: L2 {l2} vs {bl2}");
        let tol = 8.0 * dz * 4.0 * bmax * bmax;
        assert!(
            (h1 - bh1).abs() < tol,
            "t = {t}: H1 {h1} vs {bh1} (bound {tol:e})"
        );
        // The bound is tight enough to matter: it is a small part of the norm.
        assert!(tol < 0.05 * bh1, "t = {t}: bound {tol:e} against {bh1}");
    }
}
