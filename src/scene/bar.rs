//! The elastic bar dropped on an obstacle, 2D (plane strain) and 3D (contract §1.2; papers 000
//! Table 1 and 002).
//!
//! Ω = [0, 0.1] × [0, 1] or [0, 0.1]² × [0, 1], the last axis vertical; ρ = 1, λ = 0.25,
//! μ = 0.5; Q1 squares/cubes of side h. The top face x_d = 1 is clamped, the sides are
//! traction-free, the bottom face x_d = 0 is Γ_C, facing a rigid plane at distance g = 0.2:
//! u_d ≥ −g. Undeformed at t = 0 with v⁰ = −½ e_d on every node not on the clamped face; T = 2.
//! There is no closed form: errors are measured against a reference run of the same scene on a
//! nested finer mesh and step (contract §1.2, the sweep file's `reference = {…}`).
//!
//! `elements` counts the elements across the height (n_d = 1/h); the width 0.1 must hold a whole
//! number of elements too, so h ∈ {0.1, 0.05, 0.025, …, 0.1/k}.

use super::{
    ErrorSource, MeshChoice, MethodNames, Physics, PhysicsKey, Scene, SceneFacts, SceneSetup,
};

/// The finite-element geometry a scene asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum FeGeometry {
    /// A box [0, extent_0] × … meshed by Q1 elements, `cells` per axis; the last axis is
    /// vertical, its top face clamped, its bottom face the contact boundary.
    Box { extent: Vec<f64>, cells: Vec<usize> },
    /// The mapped disc (dim 2) or ball (dim 3) of radius `radius` centred at height
    /// `centre_height` above the rigid plane x_d = 0 ([`crate::space::fe::BallMesh`]): Q1 or
    /// Q2 (`degree`), `n_t` elements per side of the central block, `n_r` across the outer
    /// blocks; nothing clamped, Γ_C the boundary below the centre.
    Ball {
        dim: usize,
        degree: usize,
        radius: f64,
        centre_height: f64,
        n_t: usize,
        n_r: usize,
    },
    /// A Gmsh mesh file ([`crate::space::fe::GmshMesh`], scenes `mesh2d`/`mesh3d`): the engine
    /// reads it by `path` and checks `content_hash`; the counts size the run before it is read
    /// (memory estimate, unknowns).
    Mesh {
        path: std::path::PathBuf,
        content_hash: String,
        dim: usize,
        nodes: usize,
        /// Nodes of the `clamped` group (all their components fixed).
        clamped_nodes: usize,
        /// Nodes of Γ_C not clamped (one contact row each).
        contact_nodes: usize,
        nodes_per_element: usize,
        /// The body's vertical extent (max − min of x_d over the nodes).
        height: f64,
        /// Two bodies in the file (groups `body_a`, `body_b`; contract §1.10): B's keys.
        bodies: Option<super::mesh::MeshBodies>,
    },
    /// Two boxes, A above B (contract §1.10, [`super::blocks`]): node-to-node contact rows
    /// between A's bottom and B's top face, no obstacle.
    Blocks(super::blocks::Blocks),
}

impl FeGeometry {
    /// The body's size that mesh sizes are compared with: the box's or the mesh's vertical
    /// extent (the direction the impact travels), the disc's or ball's diameter.
    pub fn length_scale(&self) -> f64 {
        match self {
            FeGeometry::Box { extent, .. } => extent.last().copied().unwrap_or(1.0),
            FeGeometry::Ball { radius, .. } => 2.0 * radius,
            FeGeometry::Mesh { height, .. } => *height,
            FeGeometry::Blocks(b) => b.height_a + b.height_b,
        }
    }
}

/// How a volume load (gravity) enters the FE scenes (contract §1.3, key `load`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadModel {
    /// The body force F = ∫ρ f·φ, whatever the mass variant: the papers' model (GetFEM
    /// assembles the source term apart from the mass), the body's full weight.
    Body,
    /// F = M_run f e_d: the weight follows the run's (modified) inertia, so every mass variant
    /// falls rigidly — an option to measure what the choice does, the engine's load before
    /// issue 34.
    Inertial,
}

impl LoadModel {
    /// From the `load` physics key's index into [`crate::model::Key::Load`]'s choices.
    pub fn from_index(x: f64) -> LoadModel {
        if x == 1.0 {
            LoadModel::Inertial
        } else {
            LoadModel::Body
        }
    }

    /// Whether a scene's physics (keys `gravity`, `load`) put a load on its massless dofs: the
    /// body load under gravity (contract §1.3), which makes their quasi-static start differ from
    /// u⁰ = 0 and `contact_init` matter ([`super::Scene::contact_init_matters`]). The inertial
    /// load M_run f vanishes on the massless rows.
    pub fn loads_massless_dofs(p: &Physics) -> bool {
        p.get("gravity") != 0.0 && LoadModel::from_index(p.get("load")) == LoadModel::Body
    }
}

impl FeSetup {
    /// Lines added to the run id of a run whose numbers a definition change moved (issue 34),
    /// so a resumed folder never holds the numbers of two definitions under one id:
    /// - the load of contract §1.3 (F = ∫ρ f·φ, `energy_scale` with the body's mass): every run
    ///   with gravity;
    /// - exact quadrature on curved cells (contract §1.6): every run whose cells can be curved or
    ///   distorted — degree-2 cells and hexahedra of the mapped ball and of mesh files (the
    ///   bars' boxes are affine: their matrices did not change).
    pub fn id_revision(&self) -> String {
        let mut out = String::new();
        if self.gravity != 0.0 {
            out.push_str("revision=body-load\n");
        }
        let curved_cells = match &self.geometry {
            FeGeometry::Box { .. } | FeGeometry::Blocks(_) => false,
            FeGeometry::Ball { dim, degree, .. } => *degree == 2 || *dim == 3,
            FeGeometry::Mesh {
                dim,
                nodes_per_element,
                ..
            } => {
                matches!(nodes_per_element, 6 | 9 | 10 | 27)
                    || (*dim == 3 && *nodes_per_element == 8)
            }
        };
        if curved_cells {
            out.push_str("revision=curved-quadrature\n");
        }
        // The continuous energy scale (issue 42, [`FeSetup::energy_scale`]): it moved where a
        // body under gravity starts with a normal velocity (which did not enter) or rests on
        // the plane and is thrown along it (½mV_t² alone, without m·|f|·H).
        let resting_thrown = self.gap == 0.0 && self.v0_tangential != 0.0;
        if self.gravity != 0.0 && (self.v0 != 0.0 || resting_thrown) {
            out.push_str("revision=energy-scale-continuous\n");
        }
        out
    }

    /// The unit relative energies are measured in under gravity (contract §1.3):
    /// m·|f|·d + ½m|v⁰|², m = ∫ρ the body's mass (`body_mass`, the same for every mass
    /// variant), |f| = gravity (whatever the incline), v⁰ = (V_t, V_d) both components, d the
    /// gap — or, for a body that starts on the plane (gap 0), `height()`, its height along e_d.
    /// The work of the weight over the gap plus a thrown body's kinetic energy: continuous in
    /// v⁰, where a scale of ½mV_t² alone vanished as V_t → 0 and turned a resting block at
    /// V_t = 1e-6 into a `diverged` run. The terms are added in the order of the earlier
    /// definition (m·|f|·gap, then ½mV_t²), so the runs it did not change keep their bits.
    pub fn energy_scale(&self, body_mass: f64, height: impl FnOnce() -> f64) -> f64 {
        let d = if self.gap != 0.0 { self.gap } else { height() };
        let mut scale = body_mass * self.gravity.abs() * d;
        for v in [self.v0_tangential, self.v0] {
            if v != 0.0 {
                scale += 0.5 * body_mass * v * v;
            }
        }
        scale
    }
}

/// A finite-element scene as the sparse engine runs it.
#[derive(Debug, Clone, PartialEq)]
pub struct FeSetup {
    /// Scene name (for messages).
    pub scene: &'static str,
    pub dim: usize,
    pub geometry: FeGeometry,
    /// Nominal mesh size.
    pub h: f64,
    pub density: f64,
    pub lame_lambda: f64,
    pub lame_mu: f64,
    /// Distance from Γ_C to the rigid plane (the box's bottom face; the ball's lowest point,
    /// already in its geometry).
    pub gap: f64,
    /// Volume load per unit mass towards the obstacle (−gravity e_d).
    pub gravity: f64,
    /// How that load enters the equations (contract §1.3, key `load`).
    pub load: LoadModel,
    /// Initial vertical velocity of every node not on a clamped face.
    pub v0: f64,
    /// Initial e_1 velocity of every node not on a clamped face (contract §1.8
    /// `velocity_tangential`: the disc thrown obliquely, the sliding block; 0 on the bars).
    pub v0_tangential: f64,
    /// The plane's tilt α in degrees (contract §1.8 `incline`, mesh scenes): the volume load is
    /// ρ·gravity·(sin α e_1 − cos α e_d); 0 elsewhere.
    pub incline: f64,
    /// Whether the run starts from the static state under its loads (contract §1.8 `start =
    /// "static"`, mesh scenes; issue 43) instead of at rest with u⁰ = 0.
    pub static_start: bool,
}

/// The scenes `bar2d` (dim 2) and `bar3d` (dim 3).
#[derive(Debug, Clone, Copy)]
pub struct BarScene {
    pub dim: usize,
}

const BAR_PHYSICS: [PhysicsKey; 4] = [
    PhysicsKey {
        name: "density",
        default: 1.0,
    },
    PhysicsKey {
        name: "lame_lambda",
        default: 0.25,
    },
    PhysicsKey {
        name: "lame_mu",
        default: 0.5,
    },
    PhysicsKey {
        name: "gap",
        default: 0.2,
    },
];

/// Width and height of the bars.
const WIDTH: f64 = 0.1;
const HEIGHT: f64 = 1.0;

impl BarScene {
    fn check_width(h: f64) -> Result<usize, String> {
        let r = WIDTH / h;
        let n = r.round();
        if n < 1.0 || (r - n).abs() > 1e-9 * n.max(1.0) {
            return Err(format!(
                "h = {h} does not divide the bar's width {WIDTH} into a whole number of square elements (0.1/h = {r}); use h = 0.1/k"
            ));
        }
        Ok(n as usize)
    }
}

impl Scene for BarScene {
    fn fe_dim(&self) -> Option<usize> {
        Some(self.dim)
    }
    fn facts(&self) -> SceneFacts {
        SceneFacts {
            name: if self.dim == 2 { "bar2d" } else { "bar3d" },
            physics: &BAR_PHYSICS,
            default_t: 2.0,
        }
    }
    fn wave_speed(&self, p: &Physics) -> f64 {
        ((p.get("lame_lambda") + 2.0 * p.get("lame_mu")) / p.get("density")).sqrt()
    }
    fn mesh_from_h(&self, _p: &Physics, h: f64) -> Result<MeshChoice, String> {
        let n = Self::check_width(h)?;
        let h = WIDTH / n as f64;
        Ok(MeshChoice {
            elements: (HEIGHT / h).round() as usize,
            h,
        })
    }
    fn mesh_from_elements(&self, p: &Physics, elements: usize) -> Result<MeshChoice, String> {
        self.mesh_from_h(p, HEIGHT / elements as f64)
            .map_err(|e| format!("elements = {elements} (h = 1/{elements}): {e}"))
    }
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        super::fe_supports(self.name(), m)
    }
    fn error_source(&self, _p: &Physics) -> Option<ErrorSource> {
        Some(ErrorSource::ReferenceRun)
    }
    fn setup(&self, p: &Physics, mesh: MeshChoice) -> SceneSetup {
        let across = (WIDTH / mesh.h).round() as usize;
        let (extent, cells) = if self.dim == 2 {
            (vec![WIDTH, HEIGHT], vec![across, mesh.elements])
        } else {
            (
                vec![WIDTH, WIDTH, HEIGHT],
                vec![across, across, mesh.elements],
            )
        };
        SceneSetup::Fe(FeSetup {
            scene: self.name(),
            dim: self.dim,
            geometry: FeGeometry::Box { extent, cells },
            h: mesh.h,
            density: p.get("density"),
            lame_lambda: p.get("lame_lambda"),
            lame_mu: p.get("lame_mu"),
            gap: p.get("gap"),
            gravity: 0.0,
            load: LoadModel::Body,
            v0: -0.5,
            v0_tangential: 0.0,
            incline: 0.0,
            static_start: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn physics() -> Physics {
        Physics(BAR_PHYSICS.iter().map(|k| (k.name, k.default)).collect())
    }

    #[test]
    fn mesh_sizes_divide_the_width() {
        let s = BarScene { dim: 2 };
        let m = s.mesh_from_h(&physics(), 0.05).unwrap();
        assert_eq!(m.elements, 20);
        assert!(s.mesh_from_h(&physics(), 0.03).is_err());
        assert!(s.mesh_from_elements(&physics(), 25).is_err());
        assert_eq!(s.mesh_from_elements(&physics(), 40).unwrap().h, 0.025);
        // P-wave speed √((λ+2μ)/ρ) = √1.25 with the defaults.
        assert!((s.wave_speed(&physics()) - 1.25f64.sqrt()).abs() < 1e-15);
    }

    /// contract §1.3's unit m·|f|·d + ½m|v⁰|², continuous in v⁰: binary fractions, exact. A body
    /// of mass 2 under |f| = 0.5 (the sign of `gravity` aside) at gap 4, thrown with
    /// (V_t, V_d) = (0.5, −0.25): 4 + 0.3125. On the plane (gap 0) its height 8 takes the gap's
    /// place, whatever the throw; the height is not computed where the gap serves. The id
    /// revision marks exactly the runs whose unit moved.
    #[test]
    fn energy_scale_is_weight_over_the_gap_plus_the_throw() {
        let SceneSetup::Fe(mut s) = BarScene { dim: 2 }.setup(
            &physics(),
            MeshChoice {
                elements: 20,
                h: 0.05,
            },
        ) else {
            unreachable!()
        };
        (s.gravity, s.gap, s.v0_tangential, s.v0) = (-0.5, 4.0, 0.5, -0.25);
        let never = || -> f64 { panic!("the height is not needed with a gap") };
        assert_eq!(s.energy_scale(2.0, never), 4.0 + 0.3125);
        s.gap = 0.0;
        assert_eq!(s.energy_scale(2.0, || 8.0), 8.0 + 0.3125);
        let revised = |s: &FeSetup| s.id_revision().contains("energy-scale-continuous");
        assert!(revised(&s));
        // At rest on the plane: m·|f|·H as before, the same id.
        (s.v0_tangential, s.v0) = (0.0, 0.0);
        assert_eq!(s.energy_scale(2.0, || 8.0), 8.0);
        assert!(!revised(&s));
        // Continuous at V_t → 0 (the unit was ½mV_t² = 1e-18 at V_t = 1e-9).
        s.v0_tangential = 1e-9;
        assert_eq!(s.energy_scale(2.0, || 8.0), 8.0 + 1e-18);
        assert!(revised(&s));
        // Above the plane, thrown along it only: m·|f|·gap + ½mV_t² as before, the same id.
        s.gap = 4.0;
        s.v0_tangential = 0.5;
        assert_eq!(s.energy_scale(2.0, never), 4.0 + 0.25);
        assert!(!revised(&s));
    }
}
