//! `bars1d`, two bars colliding (contract §1.9, §2.6): the momentum invariant of every scheme ×
//! treatment × mass variant × `mass_side`, the mean velocities of §1.9's table, the clamped
//! case's two contact phases, and Code_Aster's SDNL111.
//!
//! The engine runs in the bodies' own frames; these tests see only what a run reports (the
//! columns and series of contract §5), as a user would.

use contact_sweep::run::bars1d::{Bars1dConfig, simulate};
use contact_sweep::run::{Grid1d, Outcome, RunOptions, Status};
use contact_sweep::scene::{BarMaterial, Bars1dParams, MassSide, NitscheSides};
use contact_sweep::space::{ContactMethod, MassVariant};
use contact_sweep::time::{
    GeneralizedAlphaParams, MoreauJeanParams, NewmarkParams, Scheme, ThetaParams,
};

const CN: Scheme = Scheme::Newmark(NewmarkParams {
    beta: 0.25,
    gamma: 0.5,
});

fn bar(length: f64, young: f64, density: f64, velocity: f64) -> BarMaterial {
    BarMaterial {
        length,
        young,
        density,
        velocity,
    }
}

/// Two bars with A = (L = E = ρ = 1, V = 1), B as given, gap 0 (contract §1.9's table).
fn pair(b: BarMaterial, clamped: bool) -> Bars1dParams {
    Bars1dParams {
        a: bar(1.0, 1.0, 1.0, 1.0),
        b,
        gap: 0.0,
        clamped,
        mass_side: MassSide::Both,
        nitsche_sides: NitscheSides::Unbiased,
    }
}

/// Run `bars` with A's `elements`, step `dt` to `t_final`.
fn run(
    bars: Bars1dParams,
    (elements, dt, t_final): (usize, f64, f64),
    (method, mass, scheme): (ContactMethod, MassVariant, Scheme),
) -> Outcome {
    let grid = Grid1d::new(elements, dt, t_final, method, mass, scheme);
    simulate(&Bars1dConfig::new(bars, grid), &RunOptions::default())
}

/// The contact phases [t_first, t_last] of a run.
fn phases(o: &Outcome) -> Vec<(f64, f64)> {
    o.metrics
        .impacts
        .as_ref()
        .unwrap()
        .iter()
        .map(|p| (p.t_first, p.t_last))
        .collect()
}

/// Every scheme the two-bar engine takes, with the treatments it applies to (contract §3,
/// §3.2): (scheme, takes mixed, takes penalty/nitsche, needs inertia on the contact ends).
fn schemes() -> Vec<(Scheme, bool, bool, bool)> {
    vec![
        (CN, true, true, false),
        (
            Scheme::Newmark(NewmarkParams {
                beta: 0.5,
                gamma: 1.0,
            }),
            true,
            true,
            false,
        ),
        (
            Scheme::Newmark(NewmarkParams {
                beta: 0.3,
                gamma: 0.6,
            }),
            true,
            true,
            false,
        ),
        (Scheme::Theta(ThetaParams { theta: 1.0 }), true, true, false),
        (Scheme::Theta(ThetaParams { theta: 0.6 }), true, true, false),
        (Scheme::Hybrid, false, true, false),
        (Scheme::Kane, true, false, false),
        (Scheme::ContactStabilizedNewmark, true, false, true),
        (
            Scheme::MoreauJean(MoreauJeanParams {
                theta: 0.5,
                restitution: 0.0,
            }),
            true,
            false,
            true,
        ),
        (
            Scheme::MoreauJean(MoreauJeanParams {
                theta: 1.0,
                restitution: 0.5,
            }),
            true,
            false,
            true,
        ),
        (
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::from_rho_inf(0.5)),
            true,
            true,
            true,
        ),
        (
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::hht(0.1)),
            true,
            true,
            true,
        ),
    ]
}

fn masses() -> Vec<MassVariant> {
    vec![
        MassVariant::Consistent,
        MassVariant::Lumped,
        MassVariant::Mod1,
        MassVariant::Mod2,
        MassVariant::Mod3,
        MassVariant::Weights(vec![1.5, 0.8]),
        MassVariant::ZeroContact,
        MassVariant::SingularDynamic,
        MassVariant::NodeNeighbour,
    ]
}

/// Contract §2.6's invariant: with both far ends free every row acts equally and oppositely,
/// so P = Σ_i 1ᵀM_iv is constant for every scheme, treatment, mass variant and `mass_side`,
/// over random meshes, steps, materials, velocities and gaps. Tolerance 1e-12 (the issue's):
/// P changes by round-off only — each step adds O(n·ε) relative to Σ m_i|V_i| through the
/// tridiagonal solves and the velocity updates, a few hundred steps stay below 1e-13.
#[test]
fn momentum_is_conserved_to_round_off() {
    let mut rng = fastrand::Rng::with_seed(44);
    let mut worst: f64 = 0.0;
    let mut runs = 0;
    for (scheme, mixed, potential, needs_mass) in schemes() {
        for mass in masses() {
            if needs_mass && mass.massless_contact() {
                continue;
            }
            for side in [MassSide::Both, MassSide::A, MassSide::B] {
                let mut methods = Vec::new();
                if mixed {
                    methods.push((ContactMethod::Mixed, NitscheSides::Unbiased));
                }
                if potential {
                    methods.push((
                        ContactMethod::Penalty { gamma0: 50.0 },
                        NitscheSides::Unbiased,
                    ));
                    for (theta, sides) in [
                        (1.0, NitscheSides::Unbiased),
                        (0.0, NitscheSides::A),
                        (-1.0, NitscheSides::Unbiased),
                    ] {
                        if scheme == Scheme::Hybrid && theta != 1.0 && sides == NitscheSides::A {
                            continue;
                        }
                        methods.push((
                            ContactMethod::Nitsche {
                                theta,
                                gamma0: 0.05,
                            },
                            sides,
                        ));
                    }
                }
                for (method, sides) in methods {
                    let la = 0.5 + rng.f64();
                    let bars = Bars1dParams {
                        a: bar(la, 0.5 + rng.f64(), 0.5 + rng.f64(), 0.5 + rng.f64()),
                        b: bar(
                            0.5 + rng.f64(),
                            0.5 + 2.0 * rng.f64(),
                            0.5 + rng.f64(),
                            rng.f64() - 0.5,
                        ),
                        gap: 0.05 * rng.f64(),
                        clamped: false,
                        mass_side: side,
                        nitsche_sides: sides,
                    };
                    let elements = 8 + rng.usize(0..12);
                    let h = la / elements as f64;
                    let dt = h * (0.3 + 1.2 * rng.f64()) / bars.wave_speed();
                    let out = run(bars, (elements, dt, 3.0), (method, mass.clone(), scheme));
                    assert_eq!(
                        out.status,
                        Status::Ok,
                        "{scheme:?} {method:?} {mass:?} {side:?}: {:?}",
                        out.message
                    );
                    let drift = out.metrics.momentum_drift.unwrap();
                    assert!(
                        drift <= 1e-12,
                        "{scheme:?} {method:?} {mass:?} {side:?}: momentum_drift {drift:e}"
                    );
                    // The bars did meet: a run without contact would test nothing.
                    assert!(
                        out.metrics.contact_phases.unwrap() >= 1,
                        "{scheme:?} {method:?}"
                    );
                    worst = worst.max(drift);
                    runs += 1;
                }
            }
        }
    }
    eprintln!("momentum_drift: worst {worst:e} over {runs} runs");
}

/// Contract §1.9's table: (B, v̄_a, v̄_b) after separation, A = (1, 1, 1), V = 1, g = 0.
fn table() -> Vec<(&'static str, BarMaterial, f64, f64)> {
    vec![
        ("equal", bar(1.0, 1.0, 1.0, 0.0), 0.0, 1.0),
        ("L_b = 2", bar(2.0, 1.0, 1.0, 0.0), 0.0, 0.5),
        ("L_b = 1/2", bar(0.5, 1.0, 1.0, 0.0), 0.5, 1.0),
        (
            "rho_b = E_b = 2",
            bar(1.0, 2.0, 2.0, 0.0),
            -1.0 / 3.0,
            2.0 / 3.0,
        ),
        ("E_b = 4", bar(1.0, 4.0, 1.0, 0.0), 1.0 / 9.0, 8.0 / 9.0),
    ]
}

/// The Courant number of done-when 1's convergence study: ν = 1/√2 on the faster bar (c0 =
/// max(c_a, c_b), contract §1.9). P1 with the consistent mass runs fast, ω_h = ω(1 + (kh)²/24 +
/// …), and CN slow, Ω = ω_h(1 − (ω_hτ)²/12 + …), so Ω = ω(1 + (kh)²(1 − 2ν²)/24 + O((kh)⁴)):
/// at ν = 1/√2 the leading dispersion of the pair cancels. That matters here because the
/// answers hinge on a stress *jump* returning to the interface: a dispersive scheme turns the
/// jump into a wave train of width ∝ (t h²)^{1/3} and the momentum it hands over converges like
/// h^{2/3} (at ν = 1: 3.7e-3 at 400 elements for L_b = ½, rates ½–¾; contract §6).
const NU: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// Done-when 1: `mixed` + `zero-contact` on both bars + CN at a fixed Courant number ([`NU`]):
/// the mean velocities at T = 4 (after separation in every row) converge to the table's as
/// h, τ → 0. One h on both bars (contract §1.9), m the shorter bar's elements (so each bar has
/// at least m: "m elements per bar"). The rate table (run with --nocapture), measured,
/// |v̄ − exact| max over both bars:
///
/// | row | m = 100 | 200 | 400 | 800 | 1600 |
/// |---|---|---|---|---|---|
/// | equal | 4.4e-4 | 3.8e-4 | 2.5e-4 | 1.8e-4 | 1.2e-4 |
/// | L_b = 2 | 3.9e-3 | 2.0e-3 | 1.1e-3 | 5.6e-4 | 2.9e-4 |
/// | L_b = ½ | 3.9e-3 | 2.0e-3 | 1.1e-3 | 5.6e-4 | 2.9e-4 |
/// | ρ_b = E_b = 2 | 5.9e-4 | 5.1e-4 | 3.4e-4 | 2.4e-4 | 1.6e-4 |
/// | E_b = 4 | 2.0e-3 | 8.7e-4 | 3.4e-4 | 1.0e-4 | 1.1e-5 |
///
/// Rates ½ (equal impedances' rows), 1 (different lengths), faster for E_b = 4. The issue's
/// 2e-3 at 400 elements per bar holds for every row (worst 1.1e-3). (At m = 50 the equal rows
/// are 2.8e-4 and 3.7e-4, below m = 100's: pre-asymptotic, so the study starts at 100.) Every
/// error must fall from one m to the next (5 % slack for the rate's wobble), and so must
/// `err_u_l2l2` over both bars (measured 6.3e-4 … 2.4e-3 at m = 400).
#[test]
fn mean_velocities_converge_to_the_table() {
    for (name, b, va, vb) in table() {
        let (mut prev, mut prev_l2) = (f64::INFINITY, f64::INFINITY);
        eprintln!("{name}:  m   |v̄_a − exact|   |v̄_b − exact|");
        for m in [100, 200, 400, 800, 1600] {
            let bars = pair(b, false);
            // A gets `elements`, B round(elements·L_b/L_a): the shorter bar has m.
            let elements = (m as f64 / b.length.min(1.0)).round() as usize;
            let dt = NU * (1.0 / elements as f64) / bars.wave_speed();
            let out = run(
                bars,
                (elements, dt, 4.0),
                (ContactMethod::Mixed, MassVariant::ZeroContact, CN),
            );
            assert_eq!(out.status, Status::Ok, "{name}: {:?}", out.message);
            let ea = (out.metrics.velocity_a_final.unwrap() - va).abs();
            let eb = (out.metrics.velocity_b_final.unwrap() - vb).abs();
            // The run's own error columns hold the same numbers: the exact mean velocities at
            // T = 4 are the table's (the exact solution's signals are piecewise constant and
            // its means exact to round-off, 1e-12).
            let (xa, xb) = (
                out.metrics.err_velocity_a_final.unwrap(),
                out.metrics.err_velocity_b_final.unwrap(),
            );
            assert!((xa - ea).abs() < 1e-12 && (xb - eb).abs() < 1e-12, "{name}");
            let (l2, sig) = (
                out.metrics.err_u_l2l2.unwrap(),
                out.metrics.err_sigma_mid_l2.unwrap(),
            );
            eprintln!(
                "{name}: {m:4}   {ea:.3e}   {eb:.3e}   err_u_l2l2 {l2:.3e}   err_sigma_mid_l2 {sig:.3e}"
            );
            assert!(l2 < prev_l2, "{name}: err_u_l2l2 grew at m = {m}");
            prev_l2 = l2;
            let e = ea.max(eb);
            assert!(e <= prev * 1.05, "{name}: error grew at m = {m}");
            if m == 400 {
                assert!(
                    e <= 2e-3,
                    "{name}: |v̄ − exact| = {e:e} at 400 elements per bar"
                );
            }
            prev = e;
        }
    }
}

/// The equal bars are the flying bar twice (contract §1.4, §1.9): in the centre-of-mass frame
/// each bar flies at ½ onto the other's mirror image, and the scheme is Galilean invariant, so
/// with the same mesh, step and method the two-bar engine's mean velocities are ½ ∓ the
/// one-bar engine's exit velocity at V = ½ — an independent check of the pair's rows, the
/// mirrored frame and the stacking against the one-bar engine. Equal to round-off: 1e-11 — the
/// one-bar engine solves for u^{n+1} and its acceleration (u^{n+1} − ũ)/(βτ²) carries
/// ε|u|/(βτ²) per step where the two-bar engine's increment form carries ε|τv|/(βτ²)
/// (measured 2.6e-13 apart after 120 steps).
#[test]
fn equal_bars_are_the_flying_bar_twice() {
    use contact_sweep::scene::BarParams;
    for (mass, scheme) in [
        (MassVariant::ZeroContact, CN),
        (MassVariant::Consistent, CN),
        (MassVariant::Mod3, Scheme::Theta(ThetaParams { theta: 1.0 })),
    ] {
        let m = 40;
        let dt = 0.8 / m as f64;
        let two = run(
            pair(bar(1.0, 1.0, 1.0, 0.0), false),
            (m, dt, 3.0),
            (ContactMethod::Mixed, mass.clone(), scheme),
        );
        let one = contact_sweep::run::bar1d::simulate(
            &contact_sweep::run::bar1d::Bar1dConfig::new(
                BarParams {
                    length: 1.0,
                    young: 1.0,
                    density: 1.0,
                    amplitude: 0.0,
                    gap: 0.0,
                    free_end: true,
                    velocity: -0.5,
                },
                Grid1d::new(m, dt, 3.0, ContactMethod::Mixed, mass.clone(), scheme),
            ),
            &RunOptions::default(),
        );
        let exit = one.metrics.exit_velocity.unwrap();
        let (va, vb) = (
            two.metrics.velocity_a_final.unwrap(),
            two.metrics.velocity_b_final.unwrap(),
        );
        eprintln!("{mass:?}: exit {exit}, v̄_a {va}, v̄_b {vb}");
        assert!(
            (va - (0.5 - exit)).abs() < 1e-11,
            "{mass:?}: {va} vs {}",
            0.5 - exit
        );
        assert!(
            (vb - (0.5 + exit)).abs() < 1e-11,
            "{mass:?}: {vb} vs {}",
            0.5 + exit
        );
        // The phases and the contact force are the one bar's too.
        assert_eq!(phases(&two), phases(&one));
    }
}

/// Done-when 1, the clamped case (contract §1.9): B clamped, L_b = ½, ρ_b = 9/2, E_b = ½
/// (c_b = ⅓, Z_b = 3/2): contact on [0, 2] and [10/3, 5], then v̄_a = −4/5. Measured at
/// [`NU`] on A (B, three times slower, runs at ν/3), in steps off the exact ends, m = 100 …
/// 1600: first phase [+1, +3.2 … +3.6], second [−5.8 … −5.2, −1.4 … +3.3]; v̄_a + 4/5 =
/// 1.6e-3, 1.6e-3, 1.6e-3, 1.2e-3, 8.6e-4. The offsets stay put in steps as m grows (a time
/// error O(τ); at ν = 1 the first release came 4, 5, 6, 7, 8 steps late, growing like
/// h^{−1/3}): CN smears each jump of the contact pressure over about three steps, and B's
/// echo, stepped at ν/3 where CN and the consistent mass do not cancel, returns a few steps
/// early. The "within 2 steps" holds for the first contact only; held here: exactly
/// two phases at every m, each end within 6 steps, v̄_a within 2e-3 at every m and within 1e-3
/// at m = 1600. Why the ends cannot come closer with this method:
/// [`clamped_phase_ends_are_the_discrete_methods_own`].
#[test]
fn clamped_case_has_two_contact_phases() {
    for m in [100, 200, 400, 800, 1600] {
        let bars = pair(bar(0.5, 0.5, 4.5, 0.0), true);
        let dt = NU * (1.0 / m as f64) / bars.wave_speed();
        let out = run(
            bars,
            (m, dt, 6.0),
            (ContactMethod::Mixed, MassVariant::ZeroContact, CN),
        );
        assert_eq!(out.status, Status::Ok, "{:?}", out.message);
        let ph = phases(&out);
        let va = out.metrics.velocity_a_final.unwrap();
        let off: Vec<_> = ph
            .iter()
            .zip([(0.0, 2.0), (10.0 / 3.0, 5.0)])
            .map(|((t0, t1), (e0, e1))| ((t0 - e0) / dt, (t1 - e1) / dt))
            .collect();
        eprintln!("clamped, m = {m}: phases {ph:?}, steps off {off:.1?}, v̄_a = {va}");
        assert_eq!(ph.len(), 2, "{ph:?}");
        for (d0, d1) in off {
            assert!(d0.abs() <= 6.0 && d1.abs() <= 6.0, "m = {m}: {ph:?}");
        }
        assert!((va + 0.8).abs() <= 2e-3, "m = {m}: v̄_a = {va}");
        if m == 1600 {
            assert!((va + 0.8).abs() <= 1e-3, "v̄_a = {va}");
        }
        // A clamp takes momentum: no drift column.
        assert_eq!(out.metrics.momentum_drift, None);
    }
}

/// The clamped case's discrete method written again, densely and without the engine: A's P1
/// bar on nodes 0..=m and B's on m+1..=m+1+m_b (its last node clamped), the same h, the
/// consistent mass with the two contact ends' rows and columns zeroed (`zero-contact` on both
/// sides), Newmark ¼, ½ in acceleration form, and the one contact row C = e_{m+1} − e_m (the
/// gap u_b − u_a ≥ 0, gap 0 initially) whose one-row complementarity problem is solved in
/// closed form: λ = [−d_free/w]_+ with d_free the gap of the step without contact and w = (τ²/4)
/// C(M + τ²K/4)⁻¹Cᵀ. Returns the contact stress −λ after each step up to `t_final` (step n at
/// index n − 1). While the ends touch it is the two bars glued into one massless node: a linear
/// problem with no contact law in it.
fn clamped_reference_stress(m: usize, dt: f64, t_final: f64) -> Vec<f64> {
    use nalgebra::{DMatrix, DVector};
    let h = 1.0 / m as f64;
    let mb = m / 2; // B's round(m·L_b/L_a) elements, the same h.
    let n = m + 1 + mb; // free nodes 0..n; node n (B's far end) clamped.
    let (mut k, mut mass) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    let elements = (0..m)
        .map(|e| (e, 1.0, 1.0))
        .chain((0..mb).map(|e| (m + 1 + e, 0.5, 4.5)));
    for (e, young, density) in elements {
        for (i, j) in [(e, e), (e, e + 1), (e + 1, e), (e + 1, e + 1)] {
            if i < n && j < n {
                let same = if i == j { 1.0 } else { -1.0 };
                k[(i, j)] += same * young / h;
                mass[(i, j)] += density * h / if i == j { 3.0 } else { 6.0 };
            }
        }
    }
    for end in [m, m + 1] {
        mass.row_mut(end).fill(0.0);
        mass.column_mut(end).fill(0.0);
    }
    let q = dt * dt / 4.0;
    let lu = (&mass + &k * q).lu();
    let mut c = DVector::zeros(n);
    (c[m], c[m + 1]) = (-1.0, 1.0);
    let z = lu.solve(&c).expect("M + τ²K/4 is regular"); // (M + τ²K/4)⁻¹Cᵀ
    let w = q * c.dot(&z);
    let mut u = DVector::zeros(n);
    let mut v = DVector::from_fn(n, |i, _| if i <= m { 1.0 } else { 0.0 });
    let mut a = DVector::zeros(n);
    let mut stress = Vec::new();
    for _ in 0..(t_final / dt).ceil() as usize {
        let predictor = &u + &v * dt + &a * q;
        let free = lu.solve(&(-(&k * &predictor))).expect("regular");
        let lambda = (-(c.dot(&(&predictor + &free * q))) / w).max(0.0);
        let a1 = free + &z * lambda;
        u = predictor + &a1 * q;
        v += (&a + &a1) * (dt / 2.0);
        a = a1;
        stress.push(-lambda);
    }
    stress
}

/// The contact phases [first, last step with contact] of a stress history (step n at n − 1).
fn phase_steps(stress: impl Iterator<Item = f64>) -> Vec<(usize, usize)> {
    let mut phases: Vec<(usize, usize)> = Vec::new();
    let mut previous = false;
    for (i, s) in stress.enumerate() {
        let on = s != 0.0;
        match phases.last_mut() {
            Some(p) if on && previous => p.1 = i + 1,
            _ if on => phases.push((i + 1, i + 1)),
            _ => {}
        }
        previous = on;
    }
    phases
}

/// Why the clamped case's phase ends stay 3–6 steps off the exact [0, 2] and [10/3, 5] (issue
/// 44 asks for 2) whatever contact solve one writes: they are the discrete method's own. The
/// engine's run equals [`clamped_reference_stress`], the same method written densely, step by
/// step (to 1e-10: the same equations, one solved by the engine's tridiagonal elimination and
/// exact branch choice, one by a dense LU; measured 2.7e-13, 7.4e-13, 1.8e-12 against |σ| = 0.6
/// at m = 100, 200, 400) and phase by
/// phase, to the step. And in the reference the first phase ends where the *glued* bars'
/// interface stress turns tensile — until then the ends move as one massless node, a linear
/// problem with no contact law in it — 3.2, 3.3, 3.6 steps after t = 2 at m = 100, 200, 400
/// (measured): CN smears the returning tension front over several steps and the tension it
/// brings, +0.12 had the ends stayed glued, is small against the −0.6 it replaces, so the
/// smeared stress crosses 0 late in the front. The second phase starts 5.4–5.8 steps early: the
/// free flight of B (stepped at ν/3, where CN and the consistent mass do not cancel) brings
/// its end back early. Asserted: engine = reference, and an end more than 2 steps off at every
/// m (the offsets in steps do not shrink with m: a time error O(τ) of the linear scheme).
#[test]
fn clamped_phase_ends_are_the_discrete_methods_own() {
    for m in [100, 200, 400] {
        let bars = pair(bar(0.5, 0.5, 4.5, 0.0), true);
        let dt = NU * (1.0 / m as f64) / bars.wave_speed();
        let t_final = 6.0;
        let out = run(
            bars,
            (m, dt, t_final),
            (ContactMethod::Mixed, MassVariant::ZeroContact, CN),
        );
        assert_eq!(out.status, Status::Ok, "{:?}", out.message);
        let reference = clamped_reference_stress(m, dt, t_final);
        let steps = reference.len().min(out.series.t.len() - 1);
        let worst = (1..=steps)
            .map(|n| (out.series.row(n).sigma_contact - reference[n - 1]).abs())
            .fold(0.0, f64::max);
        let engine = phase_steps((1..=steps).map(|n| out.series.row(n).sigma_contact));
        let discrete = phase_steps(reference[..steps].iter().copied());
        let off: Vec<(f64, f64)> = discrete
            .iter()
            .zip([(0.0, 2.0), (10.0 / 3.0, 5.0)])
            .map(|(&(s0, s1), (e0, e1))| (s0 as f64 - e0 / dt, s1 as f64 - e1 / dt))
            .collect();
        eprintln!("m = {m}: |σ − σ_ref| ≤ {worst:e}; phases {discrete:?}, steps off {off:.1?}");
        assert!(worst <= 1e-10, "m = {m}: {worst:e}");
        assert_eq!(engine, discrete, "m = {m}");
        assert_eq!(discrete.len(), 2, "m = {m}: {discrete:?}");
        let worst_end = off.iter().flat_map(|&(a, b)| [a.abs(), b.abs()]);
        assert!(worst_end.fold(0.0, f64::max) > 2.0, "m = {m}: {off:?}");
    }
}

/// Code_Aster's SDNL111 (contract §1.9): L = 1 m, ρ = 7800, V = 1 m/s, B clamped; u_a(L_a) at
/// t = 2 … 10 × 1e-4 s against the exact values of both readings, each within 1 % of its own
/// value (the bound), and for the uniaxial reading within 5 % of Code_Aster's 3D
/// references (their own tolerance). CN, `mixed` + `zero-contact`, 1600 elements per bar and
/// τ = 1.25e-7 s (ν ≈ 1.01 and 1.17; the sampled times are whole steps). Measured: worst
/// 0.30 % (E = 2e11, t = 8e-4 s, the value crossing zero) and 0.13 % (uniaxial); at 400
/// elements that crossing value is 3.8 % off (the others ≤ 0.2 %), hence the finer mesh.
#[test]
fn sdnl111_contact_end_displacement() {
    let nu = 0.3;
    let uniaxial = 2e11 * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let readings = [
        (
            2e11,
            0.0,
            [1.0000e-4, 1.9497e-4, 9.4968e-5, -1.0063e-5, -2.1006e-4],
        ),
        (
            uniaxial,
            1e-5,
            [1.0500e-4, 1.5542e-4, 5.5420e-5, -9.9160e-5, -2.9916e-4],
        ),
    ];
    let aster = [1.05e-4, 1.55e-4, 5.54e-5, -9.92e-5, -2.99e-4];
    for (young, gap, exact) in readings {
        let steel = bar(1.0, young, 7800.0, 1.0);
        let bars = Bars1dParams {
            a: steel,
            b: BarMaterial {
                velocity: 0.0,
                ..steel
            },
            gap,
            clamped: true,
            mass_side: MassSide::Both,
            nitsche_sides: NitscheSides::Unbiased,
        };
        let (m, per) = (1600, 1600);
        let dt = 2e-4 / per as f64;
        let out = run(
            bars,
            (m, dt, 1e-3),
            (ContactMethod::Mixed, MassVariant::ZeroContact, CN),
        );
        assert_eq!(out.status, Status::Ok, "{:?}", out.message);
        for (k, ex) in exact.iter().enumerate() {
            let step = per * (k + 1);
            let row = out.series.row(step);
            assert!((row.t - (k + 1) as f64 * 2e-4).abs() < 1e-12);
            let u = row.u_contact;
            eprintln!(
                "SDNL111 E = {young:.4e}: t = {:.0e}  u_a(L_a) = {u:.5e}  exact {ex:.5e}  rel {:.2e}",
                row.t,
                (u - ex).abs() / ex.abs()
            );
            assert!(
                (u - ex).abs() <= 0.01 * ex.abs(),
                "t = {}: {u} vs {ex}",
                row.t
            );
            if gap > 0.0 {
                assert!(
                    (u - aster[k]).abs() <= 0.05 * aster[k].abs(),
                    "Code_Aster: {u} vs {}",
                    aster[k]
                );
            }
        }
    }
}
