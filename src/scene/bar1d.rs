//! The impacting elastic bar of 000 §4 / 003 §4.1 and its closed-form solution.
//!
//! ρ u_tt − E u_xx = 0 on (0, L), clamped at x = L, Signorini at x = 0 with gap g,
//! u(x, 0) = a (1 − x/L), u_t(x, 0) = 0.
//!
//! For g = 0 the solution is u(x, t) = 2a · U(x/L, c0 t/L) with U the reference solution for
//! L = E = ρ = 1, a = ½ (SPEC §1.1): period 3, contact during s mod 3 ∈ [1, 2]. U is piecewise
//! affine in (ξ, s); its kinks at a given time lie at ξ = f and ξ = 1 − f (f = s mod 1). Error
//! norms are therefore integrated *exactly*: every element is split at those kinks and the
//! difference between the P1 field and the exact field is affine on each piece.

use super::{ErrorSource, MeshChoice, Physics, PhysicsKey, Scene, SceneSetup};

/// The scene `bar1d` (SPEC §1.1): physics keys, mesh from h, closed form for a zero gap.
#[derive(Debug, Clone, Copy)]
pub struct Bar1dScene;

const BAR1D_PHYSICS: [PhysicsKey; 5] = [
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
];

impl Bar1dScene {
    fn bar(physics: &Physics) -> BarParams {
        BarParams {
            length: physics.get("length"),
            young: physics.get("young"),
            density: physics.get("density"),
            amplitude: physics.get("amplitude"),
            gap: physics.get("gap"),
        }
    }
}

impl Scene for Bar1dScene {
    fn contact_init_matters(&self) -> bool {
        true
    }

    fn name(&self) -> &'static str {
        "bar1d"
    }
    fn physics(&self) -> &'static [PhysicsKey] {
        &BAR1D_PHYSICS
    }
    fn default_t(&self) -> f64 {
        12.0
    }
    fn wave_speed(&self, physics: &Physics) -> f64 {
        Self::bar(physics).wave_speed()
    }
    fn mesh_from_h(&self, physics: &Physics, h: f64) -> Result<MeshChoice, String> {
        let length = physics.get("length");
        let ratio = length / h;
        let m = ratio.round();
        if (ratio - m).abs() > 1e-9 * m.max(1.0) || m < 2.0 {
            return Err(format!(
                "h = {h} does not divide length = {length} into at least 2 elements (L/h = {ratio}); use `elements` or an h with L/h a whole number"
            ));
        }
        Ok(MeshChoice {
            elements: m as usize,
            h: length / m,
        })
    }
    fn mesh_from_elements(&self, physics: &Physics, elements: usize) -> Result<MeshChoice, String> {
        Ok(MeshChoice {
            elements,
            h: physics.get("length") / elements as f64,
        })
    }
    fn supports(
        &self,
        _space: &str,
        _mass: &str,
        _scheme: &str,
    ) -> Result<(), (&'static str, String)> {
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

/// Physical parameters of the bar (SPEC §1.1 defaults: L = E = ρ = 1, a = ½, g = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarParams {
    pub length: f64,
    pub young: f64,
    pub density: f64,
    pub amplitude: f64,
    pub gap: f64,
}

impl Default for BarParams {
    fn default() -> Self {
        Self {
            length: 1.0,
            young: 1.0,
            density: 1.0,
            amplitude: 0.5,
            gap: 0.0,
        }
    }
}

impl BarParams {
    /// Wave speed c0 = sqrt(E/ρ).
    pub fn wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }

    /// Initial displacement u0(x) = a (1 − x/L).
    pub fn initial_displacement(&self, x: f64) -> f64 {
        self.amplitude * (1.0 - x / self.length)
    }

    /// The closed form exists for a zero gap only.
    pub fn exact(&self) -> Option<BarExact> {
        (self.gap == 0.0).then_some(BarExact { p: *self })
    }
}

/// Value and partial derivatives (∂ξ, ∂s) of the reference solution U.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RefValue {
    u: f64,
    u_xi: f64,
    u_s: f64,
}

/// Reference solution U(ξ, s) for L = E = ρ = 1, a = ½ (table of SPEC §1.1).
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

    /// Period of the motion, 3L/c0.
    pub fn period(&self) -> f64 {
        3.0 * self.p.length / self.p.wave_speed()
    }

    /// u(x, t).
    pub fn u(&self, x: f64, t: f64) -> f64 {
        2.0 * self.p.amplitude * self.scaled(x, t).u
    }

    /// ∂u/∂x (x, t).
    pub fn u_x(&self, x: f64, t: f64) -> f64 {
        2.0 * self.p.amplitude / self.p.length * self.scaled(x, t).u_xi
    }

    /// ∂u/∂t (x, t).
    pub fn u_t(&self, x: f64, t: f64) -> f64 {
        2.0 * self.p.amplitude * self.p.wave_speed() / self.p.length * self.scaled(x, t).u_s
    }

    /// Contact stress σ(0, t) = E u_x(0, t): −aE/L in contact, 0 otherwise.
    pub fn contact_stress(&self, t: f64) -> f64 {
        self.p.young * self.u_x(0.0, t)
    }

    /// Exact (conserved) energy E a² / (2L).
    pub fn energy(&self) -> f64 {
        self.p.young * self.p.amplitude * self.p.amplitude / (2.0 * self.p.length)
    }

    /// Squared L2 norm and squared H1 seminorm of (u_h − u(·, t)) where u_h is the P1 field with
    /// the nodal values `nodal` on the uniform mesh of spacing `h` (node `nodal.len()` is the
    /// clamped end, value 0). Exact: elements are split at the kinks of u(·, t).
    pub fn error_sq(&self, nodal: &[f64], h: f64, t: f64) -> (f64, f64) {
        let l = self.p.length;
        let inv_l = 1.0 / l;
        let (phase, f) = phase_of(self.scaled_time(t));
        let amp = 2.0 * self.p.amplitude;
        let exact = |x: f64| amp * reference_at(x * inv_l, phase, f).u;
        let (k1, k2) = if f <= 0.5 {
            (f * l, (1.0 - f) * l)
        } else {
            ((1.0 - f) * l, f * l)
        };
        let (h3, inv_h) = (h / 3.0, 1.0 / h);
        let m = nodal.len();
        let (mut l2, mut h1) = (0.0, 0.0);
        // The exact field is continuous, so its values at the piece ends determine the affine
        // error on each piece; ∫ e² over a piece of length d is d (e_a² + e_a e_b + e_b²)/3.
        // Exact value at the left node of the element, carried from the previous element.
        let mut el = nodal[0] - exact(0.0);
        for i in 0..m {
            let xa = i as f64 * h;
            let xb = (i + 1) as f64 * h;
            let ua = nodal[i];
            let ub = if i + 1 < m { nodal[i + 1] } else { 0.0 };
            let er_node = ub - exact(xb);
            if !((k1 > xa && k1 < xb) || (k2 > xa && k2 < xb)) {
                // No kink inside (all elements but at most two): one affine piece.
                l2 += h3 * (el * el + el * er_node + er_node * er_node);
                let de = er_node - el;
                h1 += de * de * inv_h;
            } else {
                let slope = (ub - ua) * inv_h;
                let (mut xl, mut e_l) = (xa, el);
                for (xr, er) in [k1, k2]
                    .into_iter()
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
