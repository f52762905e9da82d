//! Regression tests, one per bug found while building the engine; each header states the
//! mechanism and the invariant.

mod common;

use common::cli;
use contact_sweep::scene::BarParams;
use contact_sweep::space::{Bar1dSpace, ContactMethod, MassVariant};

/// Bug: for a non-default bar, time levels t^n = nτ meant to hit an impact instant exactly
/// (c0 t / L = 1) landed just before it by round-off, so the exact contact stress was taken on
/// the wrong side of its jump and σ errors of scaled runs differed from the default's.
/// Invariant: the exact solution at t = n·τ with c0 n τ / L integral is that of the integer.
#[test]
fn exact_stress_at_an_impact_instant_does_not_depend_on_rounding() {
    let p = BarParams {
        length: 2.5,
        young: 9.0,
        density: 4.0,
        amplitude: 0.2,
        gap: 0.0,
        ..BarParams::default()
    };
    let ex = p.exact().unwrap();
    let tau = (p.length / p.wave_speed()) / 20.0;
    for n in [20usize, 40, 80, 100] {
        let t = n as f64 * tau; // c0 t / L = 1, 2, 4, 5 up to rounding
        let s = (n / 20) % 3;
        let expected = if s == 1 {
            -p.amplitude * p.young / p.length
        } else {
            0.0
        };
        assert_eq!(ex.contact_stress(t), expected, "n = {n}");
    }
}

/// Bug: ½uᵀKu evaluated as Σ K_ii u_i² + 2Σ K_i,i+1 u_i u_i+1 cancels terms of size E/h·u²
/// down to O(1) and lost ~1e-12 of the energy, enough to break the 1e-12 monotonicity checks
/// of the hybrid schemes at fine meshes. Invariant: the strain energy of the affine initial
/// state equals E a²/(2L) to a few ulps at any mesh size.
#[test]
fn strain_energy_is_summed_from_strains_without_cancellation() {
    let bar = BarParams::default();
    for m in [12usize, 1000, 60000] {
        let sp = Bar1dSpace::new(bar, m, &MassVariant::Consistent, ContactMethod::Mixed).unwrap();
        let u: Vec<f64> = (0..m)
            .map(|i| bar.initial_displacement(i as f64 * sp.h))
            .collect();
        // Worst-case bound of a sum of m terms each correct to 1 ulp: m·ε relative.
        let bound = m as f64 * f64::EPSILON * 0.125;
        let e = sp.strain_energy(&u);
        assert!((e - 0.125).abs() <= bound, "m = {m}: {e}");
        if m == 60000 {
            // The nodal quadratic form misses that bound by orders of magnitude.
            let nodal = 0.5 * sp.stiffness.quad(&u);
            assert!((nodal - 0.125).abs() > 10.0 * bound, "nodal form {nodal}");
        }
    }
}

/// Bug: the summary listed columns of this version's own runs schema (iterations,
/// factorizations, …) as "columns not known to this version". Invariant: a folder written by
/// this version has no ignored columns.
#[test]
fn summary_ignores_none_of_its_own_columns() {
    let repo = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("qs");
    let o = cli(
        repo,
        &[
            "run",
            "sweeps/quickstart.toml",
            "--out",
            out.to_str().unwrap(),
            "--no-summary",
        ],
    );
    assert!(o.status.success());
    let s = contact_sweep::summary::summarize(&out).unwrap();
    assert!(s.ignored_columns.is_empty(), "{:?}", s.ignored_columns);
    assert!(!s.terminal.contains("not known to this version"));
}
