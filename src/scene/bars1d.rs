//! Two elastic bars colliding (contract §1.9; Code_Aster's SDNL111): the first two-body scene.
//!
//! Bar A occupies (0, L_a), bar B (L_a + g, L_a + g + L_b); each obeys ρ_i u_tt − E_i u_xx = 0.
//! A's far end x = 0 is free, B's free or clamped (`far_end`); the interface is unilateral and
//! frictionless (contract §2.6: one node-to-node row in 1D). Both start unstrained, A at
//! `velocity` (towards B), B at `velocity_b`.
//!
//! The scene is data for the engine ([`crate::run::bars1d`]): a list of two bodies, each with its
//! material, mesh, mass variant (`mass_side` says which bodies the variant acts on) and
//! velocity, and one contact pair between them. Both bars are P1 with one h: A gets
//! `elements`, B round(elements·L_b/L_a) (at least 2). The Courant number uses
//! c0 = max(c_a, c_b). The engine carries the exact solution
//! ([`super::bars1d_exact`]); this file states the keys, the mesh and what the scene refuses.

use super::{
    ErrorSource, MassSide, MeshChoice, MethodNames, NitscheSides, Physics, PhysicsKey, Scene,
    SceneFacts, SceneSetup,
};

/// One bar of the pair: its length, modulus, density and initial velocity (along +x).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarMaterial {
    pub length: f64,
    pub young: f64,
    pub density: f64,
    pub velocity: f64,
}

impl BarMaterial {
    /// Wave speed c = √(E/ρ).
    pub fn wave_speed(&self) -> f64 {
        (self.young / self.density).sqrt()
    }
}

/// The physics of a `bars1d` run (contract §1.9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bars1dParams {
    pub a: BarMaterial,
    pub b: BarMaterial,
    pub gap: f64,
    /// B's far end x = L_a + g + L_b is clamped (else free).
    pub clamped: bool,
    pub mass_side: MassSide,
    pub nitsche_sides: NitscheSides,
}

impl Bars1dParams {
    /// c0 = max(c_a, c_b): the Courant number's wave speed (contract §1.9).
    pub fn wave_speed(&self) -> f64 {
        self.a.wave_speed().max(self.b.wave_speed())
    }

    /// The exact solution's description (contract §1.9, [`super::bars1d_exact`]).
    pub fn exact_spec(&self) -> super::bars1d_exact::TwoBarsSpec {
        use super::bars1d_exact::{BarSpec, FarEnd, TwoBarsSpec};
        let bar = |m: BarMaterial| BarSpec {
            length: m.length,
            young: m.young,
            density: m.density,
            velocity: m.velocity,
        };
        TwoBarsSpec {
            a: bar(self.a),
            b: bar(self.b),
            gap: self.gap,
            far_end: if self.clamped {
                FarEnd::Clamped
            } else {
                FarEnd::Free
            },
        }
    }

    /// B's element count for A's `elements`: one h on both bars, round(elements·L_b/L_a).
    pub fn elements_b(&self, elements: usize) -> usize {
        (elements as f64 * self.b.length / self.a.length).round() as usize
    }
}

/// The scene `bars1d`.
#[derive(Debug, Clone, Copy)]
pub struct Bars1dScene;

const fn key(name: &'static str, default: f64) -> PhysicsKey {
    PhysicsKey { name, default }
}

/// The physics keys (contract §7). The choice keys hold indices into `Key::choices()`:
/// `far_end` 0 = free, `mass_side` 0 = both, `nitsche_sides` 0 = unbiased. B's material keys
/// default to A's values (NaN here, resolved by [`super::two_body::b_value`]).
const BARS1D_PHYSICS: [PhysicsKey; 12] = [
    key("length", 1.0),
    key("young", 1.0),
    key("density", 1.0),
    key("velocity", 1.0),
    key("gap", 0.0),
    key("length_b", f64::NAN),
    key("young_b", f64::NAN),
    key("density_b", f64::NAN),
    key("velocity_b", 0.0),
    key("far_end", 0.0),
    key("mass_side", 0.0),
    key("nitsche_sides", 0.0),
];

const FACTS: SceneFacts = SceneFacts {
    name: "bars1d",
    physics: &BARS1D_PHYSICS,
    default_t: 4.0,
};

/// The schemes the two-bar engine steps (contract §3, §3.2 where they apply to two bodies).
const SCHEMES: [&str; 8] = [
    "newmark",
    "theta",
    "hybrid",
    "kane",
    "contact-stabilized-newmark",
    "generalized-alpha",
    "hht",
    "moreau-jean",
];

impl Bars1dScene {
    /// The run's physics as the engine takes them.
    pub fn params(physics: &Physics) -> Bars1dParams {
        let value = |name: &str, b: bool| {
            if b {
                super::two_body::b_value(physics, name)
            } else {
                physics.get(name)
            }
        };
        let bar = |b: bool| BarMaterial {
            length: value("length", b),
            young: value("young", b),
            density: value("density", b),
            velocity: physics.get(if b { "velocity_b" } else { "velocity" }),
        };
        Bars1dParams {
            a: bar(false),
            b: bar(true),
            gap: physics.get("gap"),
            clamped: physics.get("far_end") == 1.0,
            mass_side: MassSide::from_index(physics.get("mass_side")),
            nitsche_sides: NitscheSides::from_index(physics.get("nitsche_sides")),
        }
    }

    /// B's mesh for A's, or why it has too few elements.
    fn check_b(physics: &Physics, mesh: MeshChoice) -> Result<MeshChoice, String> {
        let p = Self::params(physics);
        if p.elements_b(mesh.elements) < 2 {
            return Err(format!(
                "bar B gets round(elements·length_b/length) = {} elements with A's {} (at least 2 needed): refine the mesh or lengthen B",
                p.elements_b(mesh.elements),
                mesh.elements
            ));
        }
        Ok(mesh)
    }
}

impl Scene for Bars1dScene {
    fn facts(&self) -> SceneFacts {
        FACTS
    }
    fn wave_speed(&self, physics: &Physics) -> f64 {
        Self::params(physics).wave_speed()
    }
    fn mesh_from_h(&self, physics: &Physics, h: f64) -> Result<MeshChoice, String> {
        let mesh = super::bar1d::uniform_mesh(("length", "L", physics.get("length")), h)?;
        Self::check_b(physics, mesh)
    }
    fn mesh_from_elements(&self, physics: &Physics, elements: usize) -> Result<MeshChoice, String> {
        let mesh = super::bar1d::uniform_elements(physics.get("length"), elements);
        Self::check_b(physics, mesh)
    }
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        let MethodNames { space, scheme, .. } = m;
        super::require("scheme", scheme, &SCHEMES, || {
            format!(
                "scheme = {scheme} is not available for scene bars1d (newmark with β > 0, theta, hybrid with nitsche or penalty, kane, contact-stabilized-newmark, generalized-alpha, hht, moreau-jean): paoli-schatzman's two-step contact row and discrete-gradient's difference quotients are stated for one body against an obstacle, and the two-bar engine does not step them yet (issue 44)"
            )
        })?;
        if scheme == "hybrid" {
            super::require("space", space, &["nitsche", "penalty"], || {
                "scheme = hybrid on bars1d takes nitsche or penalty: with mixed it is 000 §5's scheme on the reduced system of one bar against an obstacle, which has no two-body form".into()
            })?;
        }
        Ok(())
    }
    fn supports_friction(&self) -> Result<(), String> {
        Err("scene bars1d has no tangential direction: the two bars' one displacement is normal to their contact (contract §2.6's friction acts on a relative tangential slip, in 2D/3D)".into())
    }
    fn error_source(&self, _physics: &Physics) -> Option<ErrorSource> {
        Some(ErrorSource::Exact)
    }
    fn supports_physics(
        &self,
        physics: &Physics,
        _scheme: &crate::time::Scheme,
    ) -> Result<(), (&'static str, String)> {
        let p = Self::params(physics);
        if p.clamped && p.b.velocity != 0.0 {
            return Err((
                "velocity_b",
                format!(
                    "velocity_b = {} with far_end = \"clamped\": a clamped bar starts at rest (its far end cannot move); give velocity_b = 0 or far_end = \"free\"",
                    p.b.velocity
                ),
            ));
        }
        Ok(())
    }
    fn setup(&self, physics: &Physics, mesh: MeshChoice) -> SceneSetup {
        SceneSetup::Bars1d {
            bars: Self::params(physics),
            elements: mesh.elements,
            b_follows_a: super::two_body::b_follows_a_off_one(
                physics,
                &["length", "young", "density"],
            ),
        }
    }
}
