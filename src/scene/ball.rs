//! Impacts of a disc (2D, plane strain) and a ball (3D) under gravity on a rigid plane
//! (contract §1.3, paper 003 §4.2): `disc2d` and `sphere3d`.
//!
//! Diameter 40 (R = 20), λ = μ = 20, ρ = 1, volume load f = −0.1 e_d per unit mass, the lowest
//! point 5 above the plane x_d = 0 (centre at height R + 5), at rest and unloaded at t = 0,
//! T = 40. Nothing is clamped; Γ_C is the boundary below the centre. The mesh is the
//! block-structured mapped disc/ball of [`crate::space::fe::BallMesh`] with elements of degree
//! `degree` (1 or 2, default 2 — the paper's setting) and nominal size h (the paper: h = 4 in
//! 2D, h ≈ 8 in 3D). `elements` is the number n_t of elements along a quarter of the boundary
//! circle (even); h and n_t are linked by n_t = 2·round(πR/(4h)).
//!
//! `velocity_tangential` (default 0; contract §1.8) gives every node the initial velocity V_t e_1:
//! the disc thrown obliquely, for friction; `velocity` (default 0) the initial V_d e_d
//! (negative towards the plane).
//!
//! Energies are measured in `energy_scale` = m·|f|·gap + ½m(V_t² + V_d²), the kinetic energy
//! of the body reaching the plane in free fall (E⁰ = 0 at rest) plus that of a throw
//! ([`super::FeSetup::energy_scale`], contract §1.3). There is no closed form: errors are
//! measured against a reference run.
//!
//! Implemented so far (issue 8, in stages): `mixed`, `nitsche` and `penalty` (κ = E·γ0/h_K)
//! contact with every mass variant of contract §2.2 but the 1D-only two (`singular-dynamic`,
//! `node-neighbour`), the Newmark / θ schemes, and the hybrid scheme with `nitsche` or
//! `penalty` (000 §5's reduced hybrid of `mixed` with a massless contact is 1D only).
//!
//! Mass variants on the disc/ball: layer 0 = the elements with a node on Γ_C, layer k + 1 their
//! neighbours (by shared nodes); the layers' masses differ, so `mod2` scales every other
//! element by m/(m − m₀) and `mod3` gives layer 1 the weight 1 + m₀/m₁ (total mass conserved);
//! `zero-contact` zeroes the rows and columns of every dof of the Γ_C nodes (003 §4.1.2d, the
//! paper's "modified mass"). Gravity is the body force F = ∫ρ f·φ whatever the variant
//! (contract §1.3, `load = "body"`), so the massless dofs carry load: they start quasi-static,
//! K̃_cc u⁰_c = F_c (`contact_init = "consistent"`, the default; E⁰ = −½F_cᵀK̃_cc⁻¹F_c), or at
//! u⁰ = 0 (`"interpolant"`) — [`crate::run`]'s FE engine, `start.rs`. With `load = "inertial"`
//! (F = M_run f e_d) the rigid fall solves M ü + K u = F for every variant, E⁰ = 0 and
//! `contact_init` changes nothing.

use super::{
    ErrorSource, FeGeometry, FeSetup, LoadModel, MeshChoice, MethodNames, Physics, PhysicsKey,
    Scene, SceneFacts, SceneSetup,
};
use crate::space::fe::BallMesh;

/// Radius of the disc and the ball (diameter 40, contract §1.3).
pub const RADIUS: f64 = 20.0;

/// The scenes `disc2d` (dim 2) and `sphere3d` (dim 3).
#[derive(Debug, Clone, Copy)]
pub struct BallScene {
    pub dim: usize,
}

const BALL_PHYSICS: [PhysicsKey; 9] = [
    PhysicsKey {
        name: "density",
        default: 1.0,
    },
    PhysicsKey {
        name: "lame_lambda",
        default: 20.0,
    },
    PhysicsKey {
        name: "lame_mu",
        default: 20.0,
    },
    PhysicsKey {
        name: "gap",
        default: 5.0,
    },
    PhysicsKey {
        name: "gravity",
        default: 0.1,
    },
    PhysicsKey {
        name: "degree",
        default: 2.0,
    },
    // A choice key: the index into `Key::Load.choices()`, 0 = body (contract §1.3).
    PhysicsKey {
        name: "load",
        default: 0.0,
    },
    // The disc thrown obliquely (contract §1.8): the initial e_1 velocity of every node (nothing
    // is clamped). Default 0: the runs of contract §1.3 keep their ids.
    PhysicsKey {
        name: "velocity_tangential",
        default: 0.0,
    },
    // The initial e_d velocity of every node (negative towards the plane): the disc thrown
    // with (V_t, V_d), whose energy scale has both (contract §1.3). Default 0: ids unchanged.
    PhysicsKey {
        name: "velocity",
        default: 0.0,
    },
];

impl Scene for BallScene {
    fn contact_init_matters(&self, p: &Physics) -> bool {
        LoadModel::loads_massless_dofs(p)
    }
    fn fe_dim(&self) -> Option<usize> {
        Some(self.dim)
    }
    fn facts(&self) -> SceneFacts {
        SceneFacts {
            name: if self.dim == 2 { "disc2d" } else { "sphere3d" },
            physics: &BALL_PHYSICS,
            default_t: 40.0,
        }
    }
    fn wave_speed(&self, p: &Physics) -> f64 {
        ((p.get("lame_lambda") + 2.0 * p.get("lame_mu")) / p.get("density")).sqrt()
    }
    fn mesh_from_h(&self, _p: &Physics, h: f64) -> Result<MeshChoice, String> {
        if !(h.is_finite() && h > 0.0 && h <= RADIUS) {
            return Err(format!(
                "h = {h}: the element size must be in (0, R] with R = {RADIUS}"
            ));
        }
        let (n_t, _) = BallMesh::counts_for_size(RADIUS, h);
        Ok(MeshChoice { elements: n_t, h })
    }
    fn mesh_from_elements(&self, p: &Physics, elements: usize) -> Result<MeshChoice, String> {
        if elements < 2 || !elements.is_multiple_of(2) {
            return Err(format!(
                "elements = {elements}: the number of elements along a quarter circle must be even and ≥ 2"
            ));
        }
        self.mesh_from_h(p, std::f64::consts::PI * RADIUS / (2.0 * elements as f64))
    }
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        super::fe_supports(self.name(), m)
    }
    /// No closed form; a reference run on the same mesh with a finer step (the mapped meshes
    /// of different sizes are not nested, `run::fe::ball_ref_map`).
    fn error_source(&self, _p: &Physics) -> Option<ErrorSource> {
        Some(ErrorSource::ReferenceRun)
    }
    /// The mapped meshes of two sizes are not nested (`BallMesh::counts_for_size`).
    fn nested_meshes(&self) -> bool {
        false
    }
    fn setup(&self, p: &Physics, mesh: MeshChoice) -> SceneSetup {
        let (n_t, n_r) = BallMesh::counts_for_size(RADIUS, mesh.h);
        let gap = p.get("gap");
        SceneSetup::Fe(FeSetup {
            scene: self.name(),
            dim: self.dim,
            geometry: FeGeometry::Ball {
                dim: self.dim,
                degree: p.get("degree") as usize,
                radius: RADIUS,
                centre_height: RADIUS + gap,
                n_t,
                n_r,
            },
            h: mesh.h,
            density: p.get("density"),
            lame_lambda: p.get("lame_lambda"),
            lame_mu: p.get("lame_mu"),
            gap,
            gravity: p.get("gravity"),
            load: LoadModel::from_index(p.get("load")),
            v0: p.get("velocity"),
            v0_tangential: p.get("velocity_tangential"),
            incline: 0.0,
            static_start: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names<'a>(space: &'a str, mass: &'a str, scheme: &'a str) -> MethodNames<'a> {
        MethodNames {
            space,
            mass,
            scheme,
        }
    }

    fn physics() -> Physics {
        Physics(BALL_PHYSICS.iter().map(|k| (k.name, k.default)).collect())
    }

    #[test]
    fn paper_meshes_and_wave_speed() {
        let s = BallScene { dim: 2 };
        // h = 4: 8 elements per quarter circle (module header of space::fe::ball).
        assert_eq!(s.mesh_from_h(&physics(), 4.0).unwrap().elements, 8);
        assert_eq!(s.mesh_from_elements(&physics(), 8).unwrap().elements, 8);
        assert!(s.mesh_from_elements(&physics(), 7).is_err());
        assert!(s.mesh_from_h(&physics(), 0.0).is_err());
        // P-wave speed √((λ+2μ)/ρ) = √60.
        assert!((s.wave_speed(&physics()) - 60f64.sqrt()).abs() < 1e-14);
        assert!(s.supports(names("penalty", "consistent", "hybrid")).is_ok());
        assert!(s.supports(names("mixed", "consistent", "hybrid")).is_err());
        assert!(s.supports(names("nitsche", "mod1", "newmark")).is_ok());
        assert!(
            s.supports(names("mixed", "zero-contact", "newmark"))
                .is_ok()
        );
        assert!(
            s.supports(names("mixed", "zero-contact", "hybrid"))
                .is_err()
        );
        assert!(
            s.supports(names("mixed", "singular-dynamic", "newmark"))
                .is_err()
        );
        assert!(s.supports(names("mixed", "lumped", "theta")).is_ok());
    }
}
