//! Two elastic blocks, one falling on the other: `blocks2d` (plane strain) and `blocks3d`
//! (contract §1.10, §2.6; issue 44).
//!
//! B = [0, W]^{d−1} × [0, H_b] below A = [0, W]^{d−1} × [H_b + g, H_b + g + H_a], Q1 cells;
//! A has W/h elements across and H_a/h up (squares or cubes of side h), B round(`mesh_ratio`·W/h)
//! across (`mesh_ratio` = 1: a matching interface, every node of A's bottom face above a node of
//! B's top face; 4/3, 7/5: a non-matching one, issue 45) and round(H_b/h) up. A moves with
//! `velocity` e_d (+ `velocity_tangential` e_1), B with `velocity_b` e_d; B's base is free or
//! clamped (`far_end`); a traction −p e_d acts on A's top (`pressure`) and the weight
//! −ρ_i·gravity e_d on both (`gravity`). There is no obstacle: the contact rows pair the two
//! faces (`pairing`: node-to-node, δ_i = (u^a_i − u^b_{π(i)})·n ≤ g with n = −e_d; node-to-segment;
//! mortar with its `mortar_basis` and `interface_quadrature`; [`crate::run::fe`]'s rows), or
//! Nitsche's points of both faces (`nitsche_sides` unbiased or one-sided). With no clamp and
//! no load the total momentum is an exact invariant of every scheme (contract §2.6).
//!
//! Why a scene of its own rather than a mesh file: the matching interface, the per-body
//! materials and the patch test's exact static solution are known by construction; the
//! two-body Gmsh meshes reuse the same engine data (bodies and rows).

use super::{
    ErrorSource, FeGeometry, FeSetup, InterfaceQuadrature, InterfaceUse, LoadModel, MassSide,
    MeshChoice, MethodNames, NitscheSides, Pairing, Physics, PhysicsKey, Scene, SceneFacts,
    SceneSetup, mortar_basis_from_index,
};
use crate::space::fe::interface::Basis;

/// The two blocks as the engine meshes them (A's material, gap and velocities are the
/// [`FeSetup`]'s own fields).
#[derive(Debug, Clone, PartialEq)]
pub struct Blocks {
    pub width: f64,
    pub height_a: f64,
    pub height_b: f64,
    /// A's elements across (each horizontal axis), B's (round(`mesh_ratio`·W/h): `across`
    /// on a matching interface), up A and up B.
    pub across: usize,
    pub across_b: usize,
    pub cells_a: usize,
    pub cells_b: usize,
    /// B's base x_d = 0 held at u = 0 (`far_end = "clamped"`).
    pub base_clamped: bool,
    pub density_b: f64,
    pub lame_lambda_b: f64,
    pub lame_mu_b: f64,
    /// B's initial e_d velocity.
    pub velocity_b: f64,
    /// The traction −p e_d on A's top face.
    pub pressure: f64,
    pub mass_side: MassSide,
    /// The weights of Nitsche's two sides (contract §2.6 `nitsche_sides`).
    pub nitsche_sides: NitscheSides,
    /// How `mixed` and `penalty` pair the faces, the mortar multiplier's basis and where the
    /// interface integrals are computed (contract §2.6 `pairing`, `mortar_basis`,
    /// `interface_quadrature`; issue 45).
    pub pairing: Pairing,
    pub mortar_basis: Basis,
    pub interface_quadrature: InterfaceQuadrature,
}

/// The scenes `blocks2d` (dim 2) and `blocks3d` (dim 3).
#[derive(Debug, Clone, Copy)]
pub struct BlocksScene {
    pub dim: usize,
}

const fn key(name: &'static str, default: f64) -> PhysicsKey {
    PhysicsKey { name, default }
}

/// contract §1.10's keys and defaults; B's material keys default to A's (NaN here, resolved in
/// [`BlocksScene::setup`]), `far_end`, `mass_side`, `nitsche_sides`, `pairing`, `mortar_basis`
/// and `interface_quadrature` are indices into their words (default: the first, which keeps
/// every id of the matching blocks).
const BLOCKS_PHYSICS: [PhysicsKey; 22] = [
    key("width", 1.0),
    key("height", 1.0),
    key("height_b", 1.0),
    key("density", 1.0),
    key("lame_lambda", 1.0),
    key("lame_mu", 1.0),
    key("density_b", f64::NAN),
    key("lame_lambda_b", f64::NAN),
    key("lame_mu_b", f64::NAN),
    key("gap", 0.1),
    key("velocity", -1.0),
    key("velocity_tangential", 0.0),
    key("velocity_b", 0.0),
    key("far_end", 0.0),
    key("gravity", 0.0),
    key("pressure", 0.0),
    key("mass_side", 0.0),
    key("mesh_ratio", 1.0),
    key("nitsche_sides", 0.0),
    key("pairing", 0.0),
    key("mortar_basis", 0.0),
    key("interface_quadrature", 0.0),
];

impl BlocksScene {
    /// Elements across W for a size h (a whole number), or why not.
    fn across(p: &Physics, h: f64) -> Result<usize, String> {
        let w = p.get("width");
        let r = w / h;
        let n = r.round();
        if n < 1.0 || (r - n).abs() > 1e-9 * n.max(1.0) {
            return Err(format!(
                "h = {h} does not divide the blocks' width {w} into a whole number of square elements (width/h = {r}); use h = width/k"
            ));
        }
        Ok(n as usize)
    }

    /// B's elements across: round(`mesh_ratio`·W/h) (contract §1.10), at least one.
    fn across_b(p: &Physics, across: usize) -> usize {
        (p.get("mesh_ratio") * across as f64).round().max(1.0) as usize
    }
}

impl Scene for BlocksScene {
    /// The weight on both bodies loads their massless dofs (contract §1.3's quasi-static start).
    fn contact_init_matters(&self, p: &Physics) -> bool {
        p.get("gravity") != 0.0
    }
    fn fe_dim(&self) -> Option<usize> {
        Some(self.dim)
    }
    fn facts(&self) -> SceneFacts {
        SceneFacts {
            name: if self.dim == 2 {
                "blocks2d"
            } else {
                "blocks3d"
            },
            physics: &BLOCKS_PHYSICS,
            default_t: 4.0,
        }
    }
    /// The larger P-wave speed of the two bodies.
    fn wave_speed(&self, p: &Physics) -> f64 {
        let c = |l: f64, m: f64, r: f64| ((l + 2.0 * m) / r).sqrt();
        let a = c(p.get("lame_lambda"), p.get("lame_mu"), p.get("density"));
        let b = c(
            super::two_body::b_value(p, "lame_lambda"),
            super::two_body::b_value(p, "lame_mu"),
            super::two_body::b_value(p, "density"),
        );
        a.max(b)
    }
    fn mesh_from_h(&self, p: &Physics, h: f64) -> Result<MeshChoice, String> {
        let n = Self::across(p, h)?;
        let h = p.get("width") / n as f64;
        let up = (p.get("height") / h).round().max(1.0);
        Ok(MeshChoice {
            elements: up as usize,
            h,
        })
    }
    fn mesh_from_elements(&self, p: &Physics, elements: usize) -> Result<MeshChoice, String> {
        let h = p.get("height") / elements as f64;
        self.mesh_from_h(p, h)
            .map_err(|e| format!("elements = {elements} (h = height/{elements}): {e}"))
    }
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        super::fe_supports(self.name(), m)?;
        super::require("space", m.space, &["mixed", "penalty", "nitsche"], || {
            format!(
                "space = {} is not available for scene {} (mixed and penalty with a pairing, nitsche unbiased or one-sided)",
                m.space,
                self.name()
            )
        })
    }
    /// Friction (contract §2.5) acts on the relative slip (u^a − u^b∘π)_t: through the
    /// tangential rows e_{a,i,t} − e_{b,π(i),t} for `mixed` and `penalty`, through the pair
    /// points' slip rows for `nitsche` (`run::fe`).
    fn supports_friction(&self) -> Result<(), String> {
        Ok(())
    }
    fn supports_physics(
        &self,
        p: &Physics,
        _scheme: &crate::time::Scheme,
    ) -> Result<(), (&'static str, String)> {
        if p.get("far_end") == 1.0 && p.get("velocity_b") != 0.0 {
            return Err((
                "velocity_b",
                format!(
                    "velocity_b = {} with far_end = \"clamped\": a clamped body B cannot move rigidly",
                    p.get("velocity_b")
                ),
            ));
        }
        Ok(())
    }
    /// contract §2.6: `pairing` and `mortar_basis` are the rows of `mixed` and `penalty`;
    /// `interface_quadrature` integrates mortar's and Nitsche's interface terms; a
    /// non-matching interface (`mesh_ratio` ≠ 1) needs a pairing that projects.
    fn supports_interface(
        &self,
        p: &Physics,
        m: InterfaceUse<'_>,
    ) -> Result<(), (&'static [&'static str], String)> {
        super::two_body::check_interface(p, p.get("mesh_ratio"), m)
    }
    /// Errors against a finer reference run (contract §1.10, as §1.2), evaluated as §1.6's: the
    /// two bodies make one mesh that is no box, so the reference stores it whole and each run
    /// node is located in it (with a gap the bodies do not touch, so a node's element is its
    /// own body's).
    fn error_source(&self, _p: &Physics) -> Option<ErrorSource> {
        Some(ErrorSource::ReferenceRun)
    }
    /// The run's and the reference's meshes are read through the interpolation (above), whether
    /// or not their lattices nest (B's round(mesh_ratio·W/h) across does not, in general).
    fn nested_meshes(&self) -> bool {
        false
    }
    fn setup(&self, p: &Physics, mesh: MeshChoice) -> SceneSetup {
        let across = (p.get("width") / mesh.h).round() as usize;
        let blocks = Blocks {
            across_b: Self::across_b(p, across),
            pairing: Pairing::from_index(p.get("pairing")),
            mortar_basis: mortar_basis_from_index(p.get("mortar_basis")),
            interface_quadrature: InterfaceQuadrature::from_index(p.get("interface_quadrature")),
            width: p.get("width"),
            height_a: p.get("height"),
            height_b: p.get("height_b"),
            across,
            cells_a: mesh.elements,
            cells_b: (p.get("height_b") / mesh.h).round().max(1.0) as usize,
            base_clamped: p.get("far_end") == 1.0,
            density_b: super::two_body::b_value(p, "density"),
            lame_lambda_b: super::two_body::b_value(p, "lame_lambda"),
            lame_mu_b: super::two_body::b_value(p, "lame_mu"),
            velocity_b: p.get("velocity_b"),
            pressure: p.get("pressure"),
            mass_side: MassSide::from_index(p.get("mass_side")),
            nitsche_sides: NitscheSides::from_index(p.get("nitsche_sides")),
        };
        SceneSetup::Fe(FeSetup {
            scene: self.name(),
            dim: self.dim,
            geometry: FeGeometry::Blocks(blocks),
            h: mesh.h,
            density: p.get("density"),
            lame_lambda: p.get("lame_lambda"),
            lame_mu: p.get("lame_mu"),
            gap: p.get("gap"),
            gravity: p.get("gravity"),
            load: LoadModel::Body,
            v0: p.get("velocity"),
            v0_tangential: p.get("velocity_tangential"),
            incline: 0.0,
            static_start: false,
        })
    }
}
