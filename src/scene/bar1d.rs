//! The impacting elastic bar of 000 §4 / 003 §4.1 and its closed-form solution.
//!
//! ρ u_tt − E u_xx = 0 on (0, L), clamped at x = L, Signorini at x = 0 with gap g,
//! u(x, 0) = a (1 − x/L), u_t(x, 0) = 0.
//!
//! For g = 0 the solution is u(x, t) = 2a · U(x/L, c0 t/L) with U the reference solution for
//! L = E = ρ = 1, a = ½ (contract §1.1): period 3, contact during s mod 3 ∈ [1, 2]. U is piecewise
//! affine in (ξ, s); its kinks at a given time lie at ξ = f and ξ = 1 − f (f = s mod 1). Error
//! norms are therefore integrated *exactly*: every element is split at those kinks and the
//! difference between the P1 field and the exact field is affine on each piece.
//!
//! With `right_end = "free"`, no initial strain and a uniform velocity −V towards the obstacle
//! (contract §1.4, the flying bar of Doyen–Ern–Piperno 2011 and Siconos' ImpactingBar) the solution
//! is d'Alembert's: with c = √(E/ρ), t_c = g/V and s = t − t_c,
//! u(x, t) = −g − V·min(x/c, s, 2L/c − s) for every t (before the impact the minimum is s, the
//! rigid flight −Vt; after it 2L/c − s, the rigid rebound). The compression front x = c s
//! leaves the wall at s = 0 and reaches the free end at s = L/c; the unloading front
//! x = 2L − c s returns and reaches the wall at s = 2L/c, when the bar leaves with +V. The
//! kinks at a time are those two fronts: error norms are integrated exactly by splitting the
//! elements there, exactly as for the clamped bar. Every tolerance is relative to the bar's own
//! scales (L, L/c, V), never to a unit bar.

use super::{
    ErrorSource, MeshChoice, MethodNames, Physics, PhysicsKey, Scene, SceneFacts, SceneSetup,
};

/// The scene `bar1d` (contract §1.1): physics keys, mesh from h, closed form for a zero gap.
#[derive(Debug, Clone, Copy)]
pub struct Bar1dScene;

const BAR1D_PHYSICS: [PhysicsKey; 7] = [
    PhysicsKey {
        name: "length",
        default: 1.0,
    },
    PhysicsKey {
        name: "young",
        default: 1.0,
    },
    PhysicsKey {
        name: "density",
        default: 1.0,
    },
    PhysicsKey {
        name: "amplitude",
        default: 0.5,
    },
    PhysicsKey {
        name: "gap",
        default: 0.0,
    },
    // A choice key: the index into `Key::RightEnd.choices()`, 0 = clamped (contract §1.1's bar).
    PhysicsKey {
        name: "right_end",
        default: 0.0,
    },
    PhysicsKey {
        name: "velocity",
        default: 0.0,
    },
];

/// The scene's name, its physics keys and its default final time.
const FACTS: SceneFacts = SceneFacts {
    name: "bar1d",
    physics: &BAR1D_PHYSICS,
    default_t: 12.0,
};

impl Bar1dScene {
    fn bar(physics: &Physics) -> BarParams {
        BarParams {
            length: physics.get("length"),
            young: physics.get("young"),
            density: physics.get("density"),
            amplitude: physics.get("amplitude"),
            gap: physics.get("gap"),
            free_end: physics.get("right_end") == 1.0,
            velocity: physics.get("velocity"),
        }
    }
}

/// The uniform P1 mesh of size `h` on a 1D body of extent `(key, symbol, value)` (the bar's
/// length L, the layer's height H): extent/h elements, a whole number and at least 2, or why
/// not. Shared by the 1D scenes, whose meshes are all this one.
pub(super) fn uniform_mesh(
    (key, symbol, extent): (&str, &str, f64),
    h: f64,
) -> Result<MeshChoice, String> {
    let ratio = extent / h;
    let m = ratio.round();
    if (ratio - m).abs() > 1e-9 * m.max(1.0) || m < 2.0 {
        return Err(format!(
            "h = {h} does not divide {key} = {extent} into at least 2 elements ({symbol}/h = {ratio}); use `elements` or an h with {symbol}/h a whole number"
        ));
    }
    Ok(MeshChoice {
        elements: m as usize,
        h: extent / m,
    })
}

/// The uniform mesh of `elements` elements on a 1D body of extent `extent`.
pub(super) fn uniform_elements(extent: f64, elements: usize) -> MeshChoice {
    MeshChoice {
        elements,
        h: extent / elements as f64,
    }
}

impl Scene for Bar1dScene {
    fn contact_init_matters(&self, _physics: &Physics) -> bool {
        true
    }

    fn facts(&self) -> SceneFacts {
        FACTS
    }
    fn wave_speed(&self, physics: &Physics) -> f64 {
        Self::bar(physics).wave_speed()
    }
    fn mesh_from_h(&self, physics: &Physics, h: f64) -> Result<MeshChoice, String> {
        uniform_mesh(("length", "L", physics.get("length")), h)
    }
    fn mesh_from_elements(&self, physics: &Physics, elements: usize) -> Result<MeshChoice, String> {
        Ok(uniform_elements(physics.get("length"), elements))
    }
    fn supports(&self, _m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        Ok(())
    }
    fn error_source(&self, physics: &Physics) -> Option<ErrorSource> {
        Self::bar(physics).exact().map(|_| ErrorSource::Exact)
    }
    fn setup(&self, physics: &Physics, mesh: MeshChoice) -> SceneSetup {
        SceneSetup::Bar1d {
            bar: Self::bar(physics),
            elements: mesh.elements,
        }
    }
}

/// The bar's physical parameters: defined with its discretisation ([`crate::space::bar1d`]),
/// which builds M and K from them; the scene fills them from the sweep's keys.
pub use crate::space::bar1d::BarParams;

impl BarParams {
    /// The closed form: the clamped bar released at rest with a zero gap (contract §1.1), or the
    /// flying bar — free end, no initial strain, moving towards the obstacle (contract §1.4).
    /// Other combinations have none.
    pub fn exact(&self) -> Option<BarExact> {
        let clamped = !self.free_end && self.gap == 0.0 && self.velocity == 0.0;
        let flying = self.free_end && self.amplitude == 0.0 && self.velocity < 0.0;
        (clamped || flying).then_some(BarExact { p: *self })
    }
}

/// Value and partial derivatives (∂ξ, ∂s) of the reference solution U.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RefValue {
    u: f64,
    u_xi: f64,
    u_s: f64,
}

/// Reference solution U(ξ, s) for L = E = ρ = 1, a = ½ (table of contract §1.1).
fn reference(xi: f64, s: f64) -> RefValue {
    let (phase, f) = phase_of(s);
    reference_at(xi, phase, f)
}

/// Phase k = floor(s mod 3) and f = (s mod 3) mod 1 of a scaled time.
fn phase_of(s: f64) -> (f64, f64) {
    let sp = s.rem_euclid(3.0);
    let phase = sp.floor();
    (phase, sp - phase)
}

/// U(ξ) at a time given by its phase and f (hoisted out of loops over ξ).
fn reference_at(xi: f64, phase: f64, f: f64) -> RefValue {
    // Zone of (ξ, f): I f<ξ, f≤1−ξ; III f<ξ, f>1−ξ; II f≥ξ, f≤1−ξ; IV f≥ξ, f>1−ξ.
    let left = f < xi; // I or III
    let low = f <= 1.0 - xi; // I or II
    let rv = |u, u_xi, u_s| RefValue { u, u_xi, u_s };
    match (phase as i64, left, low) {
        // before impact
        (0, true, _) => rv(0.5 - xi / 2.0, -0.5, 0.0),
        (0, false, _) => rv(0.5 - f / 2.0, 0.0, -0.5),
        // in contact
        (1, true, true) => rv(-f / 2.0, 0.0, -0.5),
        (1, false, true) => rv(-xi / 2.0, -0.5, 0.0),
        (1, true, false) => rv(-0.5 + xi / 2.0, 0.5, 0.0),
        (1, false, false) => rv(-0.5 + f / 2.0, 0.0, 0.5),
        // after impact
        (_, _, true) => rv(f / 2.0, 0.0, 0.5),
        (_, _, false) => rv(0.5 - xi / 2.0, -0.5, 0.0),
    }
}

/// The exact solution of the bar for a zero gap, in physical units.
#[derive(Debug, Clone, Copy)]
pub struct BarExact {
    p: BarParams,
}

impl BarExact {
    /// Scaled time s = c0 t / L, snapped to the nearest integer within 1e-12 relative: time
    /// levels t^n = nτ that are meant to hit an impact instant exactly (s = 1, 2, …) must not
    /// land on either side of the stress jump by round-off.
    fn scaled_time(&self, t: f64) -> f64 {
        let s = self.p.wave_speed() * t / self.p.length;
        let r = s.round();
        if (s - r).abs() <= 1e-12 * r.abs().max(1.0) {
            r
        } else {
            s
        }
    }

    fn scaled(&self, x: f64, t: f64) -> RefValue {
        reference(x / self.p.length, self.scaled_time(t))
    }

    /// Whether this is the flying bar (contract §1.4) rather than the clamped one.
    pub fn is_flying(&self) -> bool {
        self.p.free_end
    }

    /// The flying bar's s = t − t_c, snapped onto 0 and 2L/c (the contact's ends) within
    /// 1e-12 of the time scale max(t, L/c): a step meant to land on an end must not fall on
    /// either side of the pressure jump by round-off.
    fn flight_time(&self, t: f64) -> f64 {
        let c = self.p.wave_speed();
        let v = -self.p.velocity;
        let s = t - self.p.gap / v;
        let tol = 1e-12 * t.abs().max(self.p.length / c);
        let end = 2.0 * self.p.length / c;
        if s.abs() <= tol {
            0.0
        } else if (s - end).abs() <= tol {
            end
        } else {
            s
        }
    }

    /// Flying bar: (u, u_x, u_t) at x for the flight time s, from
    /// u = −g − V·min(x/c, s, 2L/c − s).
    fn flying(&self, x: f64, s: f64) -> RefValue {
        let c = self.p.wave_speed();
        let v = -self.p.velocity;
        let back = 2.0 * self.p.length / c - s;
        let xc = x / c;
        let rv = |psi: f64, u_xi, u_s| RefValue {
            u: -self.p.gap - v * psi,
            u_xi,
            u_s,
        };
        if xc < s && xc < back {
            // Behind the compression front and before the unloading one: at rest, strained.
            rv(xc, -v / c, 0.0)
        } else if s <= back {
            // Ahead of the compression front (or before the impact): moving at −V.
            rv(s, 0.0, -v)
        } else {
            // Behind the unloading front (or after the bar has left): moving at +V.
            rv(back, 0.0, v)
        }
    }

    /// Period of the motion, 3L/c0 (clamped bar; the flying bar has one impact and no period).
    pub fn period(&self) -> f64 {
        3.0 * self.p.length / self.p.wave_speed()
    }

    /// The flying bar's first contact t_c = g/V and the contact's duration 2L/c (contract §1.4).
    pub fn contact_interval(&self) -> Option<(f64, f64)> {
        self.is_flying().then(|| {
            (
                self.p.gap / -self.p.velocity,
                2.0 * self.p.length / self.p.wave_speed(),
            )
        })
    }

    /// u(x, t).
    pub fn u(&self, x: f64, t: f64) -> f64 {
        if self.is_flying() {
            return self.flying(x, self.flight_time(t)).u;
        }
        2.0 * self.p.amplitude * self.scaled(x, t).u
    }

    /// ∂u/∂x (x, t).
    pub fn u_x(&self, x: f64, t: f64) -> f64 {
        if self.is_flying() {
            return self.flying(x, self.flight_time(t)).u_xi;
        }
        2.0 * self.p.amplitude / self.p.length * self.scaled(x, t).u_xi
    }

    /// ∂u/∂t (x, t).
    pub fn u_t(&self, x: f64, t: f64) -> f64 {
        if self.is_flying() {
            return self.flying(x, self.flight_time(t)).u_s;
        }
        2.0 * self.p.amplitude * self.p.wave_speed() / self.p.length * self.scaled(x, t).u_s
    }

    /// Contact stress σ(0, t) = E u_x(0, t): −aE/L in contact, 0 otherwise.
    pub fn contact_stress(&self, t: f64) -> f64 {
        self.p.young * self.u_x(0.0, t)
    }

    /// Exact (conserved) energy: E a² / (2L) for the clamped bar, ½ρLV² for the flying one.
    pub fn energy(&self) -> f64 {
        if self.is_flying() {
            let v = self.p.velocity;
            return 0.5 * self.p.density * self.p.length * v * v;
        }
        self.p.young * self.p.amplitude * self.p.amplitude / (2.0 * self.p.length)
    }

    /// Squared L2 norm and squared H1 seminorm of (u_h − u(·, t)) where u_h is the P1 field with
    /// the nodal values `nodal` on the uniform mesh of spacing `h`: nodes 0 … m−1 with node m
    /// clamped (value 0) for the clamped bar, nodes 0 … m for the free end. Exact: elements
    /// are split at the kinks of u(·, t).
    pub fn error_sq(&self, nodal: &[f64], h: f64, t: f64) -> (f64, f64) {
        if self.is_flying() {
            let c = self.p.wave_speed();
            let s = self.flight_time(t);
            let (a, b) = (c * s, 2.0 * self.p.length - c * s);
            let kinks = if a <= b { (a, b) } else { (b, a) };
            let m = nodal.len() - 1;
            return integrate_error(
                m,
                |i| nodal[i],
                h,
                &[kinks.0, kinks.1],
                |x| self.flying(x, s).u,
            );
        }
        let l = self.p.length;
        let inv_l = 1.0 / l;
        let (phase, f) = phase_of(self.scaled_time(t));
        let amp = 2.0 * self.p.amplitude;
        let exact = |x: f64| amp * reference_at(x * inv_l, phase, f).u;
        let kinks = if f <= 0.5 {
            (f * l, (1.0 - f) * l)
        } else {
            ((1.0 - f) * l, f * l)
        };
        let m = nodal.len();
        let node = |i: usize| if i < m { nodal[i] } else { 0.0 };
        integrate_error(m, node, h, &[kinks.0, kinks.1], exact)
    }
}

/// ∫(u_h − u)² and ∫(u_h' − u')² over `elements` P1 elements of size h with nodal values
/// `node(i)`, i = 0 … elements, against a continuous field `exact` that is affine between the
/// kinks, sorted ascending (only those inside an element matter; the layer of contract §1.7 has up
/// to four per component). On each affine piece the error is affine, so its values at the piece
/// ends determine both integrals: ∫ e² over a piece of length d is d (e_a² + e_a e_b + e_b²)/3,
/// ∫ e'² is (e_b − e_a)²/d.
pub(crate) fn integrate_error(
    elements: usize,
    node: impl Fn(usize) -> f64,
    h: f64,
    kinks: &[f64],
    exact: impl Fn(f64) -> f64,
) -> (f64, f64) {
    let (h3, inv_h) = (h / 3.0, 1.0 / h);
    let (mut l2, mut h1) = (0.0, 0.0);
    // Error at the left node of the element, carried from the previous element.
    let mut el = node(0) - exact(0.0);
    for i in 0..elements {
        let xa = i as f64 * h;
        let xb = (i + 1) as f64 * h;
        let ua = node(i);
        let ub = node(i + 1);
        let er_node = ub - exact(xb);
        if !kinks.iter().any(|k| *k > xa && *k < xb) {
            // No kink inside (all elements but at most two): one affine piece.
            l2 += h3 * (el * el + el * er_node + er_node * er_node);
            let de = er_node - el;
            h1 += de * de * inv_h;
        } else {
            let slope = (ub - ua) * inv_h;
            let (mut xl, mut e_l) = (xa, el);
            for (xr, er) in kinks
                .iter()
                .copied()
                .filter(|k| *k > xa && *k < xb)
                .map(|k| (k, ua + slope * (k - xa) - exact(k)))
                .chain(std::iter::once((xb, er_node)))
            {
                let d = xr - xl;
                if d > 0.0 {
                    l2 += d * (e_l * e_l + e_l * er + er * er) / 3.0;
                    let de = er - e_l;
                    h1 += de * de / d;
                    xl = xr;
                    e_l = er;
                }
            }
        }
        el = er_node;
    }
    (l2, h1)
}

#[cfg(test)]
mod tests {
    use super::*;

    // The reference solution is piecewise affine with rational breakpoints: values are exact in
    // binary floating point up to one rounding, hence the 1e-15 tolerances.
    #[test]
    fn reference_contact_phases() {
        let e = BarParams::default().exact().unwrap();
        assert!((e.u(0.0, 0.0) - 0.5).abs() < 1e-15);
        assert!((e.u(0.0, 0.5) - 0.25).abs() < 1e-15);
        assert_eq!(e.u(0.0, 1.5), 0.0);
        assert!((e.contact_stress(1.5) + 0.5).abs() < 1e-15);
        assert_eq!(e.contact_stress(0.5), 0.0);
        assert!((e.u(0.0, 2.5) - 0.25).abs() < 1e-15);
        assert!((e.u(0.0, 3.0) - 0.5).abs() < 1e-15);
    }
}
