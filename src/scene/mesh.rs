//! The user's own body from a Gmsh mesh file (contract §1.6, issue 22): `mesh2d` (plane strain) and
//! `mesh3d`.
//!
//! Why a scene of its own: every other scene knows its geometry; here the geometry, `h` and the
//! identity of the body come from the file named by the `mesh` key (a path relative to the sweep
//! file; a list is an axis). The file is read and validated by the planner
//! ([`crate::space::fe::GmshMesh::read_shared`]) so a bad mesh is refused before anything runs,
//! and a run's id holds the file's SHA-256 (moving or renaming the file keeps the id, editing it
//! changes it).
//!
//! Physics: physical group `clamped` (optional) has u = 0, `contact` is Γ_C, every other boundary
//! is traction-free. The rigid plane is x_d = (lowest x_d of Γ_C) − `gap`, normal −e_d, gap
//! function g(x) = x_d − obstacle (contract §1.3's conventions): the engine's contact rows are the
//! vertical dofs of the Γ_C nodes (`mixed`), each with its own initial gap. The plane may be
//! given by its height instead, `obstacle` (exclusive with `gap`): the planner turns it into
//! the gap it names, so both spellings of one plane are one run with one id. Loads: `gravity`
//! (per unit mass, towards the obstacle, default 0) and the initial velocity `velocity` e_d on
//! every node not clamped (default 0; negative moves towards the obstacle). Contract §1.8 adds
//! `velocity_tangential` (the initial e_1 velocity of every node not clamped) and `incline`
//! (α in degrees, |α| < 90: the plane tilted by α, the volume load ρ·gravity·(sin α e_1 −
//! cos α e_d), so the body slides down +e_1), both default 0. Material defaults
//! are the bars' (ρ = 1, λ = 0.25, μ = 0.5) and `gap` defaults to the bars' 0.2, so the 002 bar
//! meshed by Gmsh with `velocity = -0.5` is `bar2d`.
//!
//! `h` is the mesh's largest element diameter (reported, it orders refinement paths) and
//! `elements` its number of cells. Methods: `mixed` contact with every mass variant of contract §2.2
//! but the 1D-only two (layers by topology: layer 0 = the cells with a node on Γ_C, layer k + 1
//! their neighbours by shared nodes), `nitsche` and `penalty` on the `contact` group's faces,
//! and the schemes of every finite-element scene ([`super::fe_supports`]: Newmark, θ, contract
//! §3.2's methods, hybrid with Nitsche or the penalty) — the engines act on the assembled
//! operators and the Γ_C rows or quadrature points, whatever the mesh.
//!
//! Errors are measured against a reference run at least as fine (contract §1.6): on the same file
//! with a finer step, on another (finer) mesh file of the same body, or — `reference = { scene
//! = "bar2d", h = …, dt = … }` — on the built-in scene the file meshes, with the same physics
//! (the planner checks it). The reference stores its whole mesh (a mesh file's clamped nodes
//! as zeros) and each run node is located in it ([`crate::space::fe::locate`]); the
//! reference's finite-element function is evaluated there, so the errors are those of the run
//! against I_h u_ref on the run's own mesh, whatever the two meshes' element kinds.

use std::path::Path;

use super::{
    ErrorSource, FeGeometry, FeSetup, InterfaceQuadrature, InterfaceUse, LoadModel, MassSide,
    MeshChoice, MethodNames, NitscheSides, Pairing, Physics, PhysicsKey, Scene, SceneFacts,
    SceneSetup, mortar_basis_from_index,
};
use crate::space::fe::interface::Basis;
use crate::space::fe::{GmshMesh, Mesh, file_interface};

/// The scenes `mesh2d` (dim 2) and `mesh3d` (dim 3).
#[derive(Debug, Clone, Copy)]
pub struct MeshScene {
    pub dim: usize,
}

/// B's keys of a two-body file (contract §1.10), as the blocks': its material (default A's), its
/// initial e_d velocity, the traction on A's `loaded` face and the side of the mass variant.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshBodies {
    pub density_b: f64,
    pub lame_lambda_b: f64,
    pub lame_mu_b: f64,
    pub velocity_b: f64,
    pub pressure: f64,
    pub mass_side: MassSide,
    /// The weights of Nitsche's two sides (contract §2.6 `nitsche_sides`).
    pub nitsche_sides: NitscheSides,
    /// The rows of `mixed` and `penalty`, the mortar basis and the interface quadrature
    /// (contract §2.6 `pairing`, `mortar_basis`, `interface_quadrature`; issue 45).
    pub pairing: Pairing,
    pub mortar_basis: Basis,
    pub interface_quadrature: InterfaceQuadrature,
}

/// The two-body keys (contract §1.10), all NaN by default — "not given": the column is null
/// and the id unchanged, so the one-body files' runs keep their ids and columns, and a
/// one-body file refuses any of them ([`two_body_keys_on_one_body`]).
const TWO_BODY_KEYS: [&str; 10] = [
    "density_b",
    "lame_lambda_b",
    "lame_mu_b",
    "velocity_b",
    "pressure",
    "mass_side",
    "nitsche_sides",
    "pairing",
    "mortar_basis",
    "interface_quadrature",
];

const MESH_PHYSICS: [PhysicsKey; 20] = [
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
    PhysicsKey {
        name: "gravity",
        default: 0.0,
    },
    PhysicsKey {
        name: "velocity",
        default: 0.0,
    },
    // A choice key: the index into `Key::Load.choices()`, 0 = body (contract §1.3); it applies
    // only with gravity (the planner drops it otherwise).
    PhysicsKey {
        name: "load",
        default: 0.0,
    },
    // contract §1.8: the initial e_1 velocity of every node not clamped (the sliding block) and
    // the plane's tilt α in degrees (the volume load ρ·gravity·(sin α e_1 − cos α e_d)). Both
    // default to 0, so the runs of contract §1.6 keep their ids.
    PhysicsKey {
        name: "velocity_tangential",
        default: 0.0,
    },
    PhysicsKey {
        name: "incline",
        default: 0.0,
    },
    // A choice key (issue 43): the index into `Key::Start.choices()`, 0 = rest (u⁰ = 0, every
    // existing id unchanged), 1 = static (u⁰ the static state under the loads with contact).
    PhysicsKey {
        name: "start",
        default: 0.0,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[0],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[1],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[2],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[3],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[4],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[5],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[6],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[7],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[8],
        default: f64::NAN,
    },
    PhysicsKey {
        name: TWO_BODY_KEYS[9],
        default: f64::NAN,
    },
];

/// A key's value, `or` where the sweep gives none (NaN).
fn given_or(p: &Physics, name: &str, or: f64) -> f64 {
    let v = p.get(name);
    if v.is_nan() { or } else { v }
}

/// The first two-body key a sweep gives for a one-body file, with its value.
fn two_body_keys_on_one_body(p: &Physics) -> Option<(&'static str, f64)> {
    TWO_BODY_KEYS
        .iter()
        .map(|&k| (k, p.get(k)))
        .find(|(_, v)| !v.is_nan())
}

/// B's keys of a two-body run, A's material where B's is not given; `gravity` (not yet) and
/// `incline` (no plane) are refused.
fn mesh_bodies(p: &Physics, path: &Path) -> Result<MeshBodies, String> {
    for (key, why) in [
        (
            "gravity",
            "gravity on a two-body file is not implemented yet (the blocks take it)",
        ),
        ("incline", "there is no plane to tilt between two bodies"),
    ] {
        if p.get(key) != 0.0 {
            return Err(format!(
                "{}: {key} = {} on a two-body mesh: {why}",
                path.display(),
                p.get(key)
            ));
        }
    }
    Ok(MeshBodies {
        density_b: given_or(p, "density_b", p.get("density")),
        lame_lambda_b: given_or(p, "lame_lambda_b", p.get("lame_lambda")),
        lame_mu_b: given_or(p, "lame_mu_b", p.get("lame_mu")),
        velocity_b: given_or(p, "velocity_b", 0.0),
        pressure: given_or(p, "pressure", 0.0),
        mass_side: MassSide::from_index(given_or(p, "mass_side", 0.0)),
        nitsche_sides: NitscheSides::from_index(given_or(p, "nitsche_sides", 0.0)),
        pairing: Pairing::from_index(given_or(p, "pairing", 0.0)),
        mortar_basis: mortar_basis_from_index(given_or(p, "mortar_basis", 0.0)),
        interface_quadrature: InterfaceQuadrature::from_index(given_or(
            p,
            "interface_quadrature",
            0.0,
        )),
    })
}

/// The contact rows of a two-body file: its matched pairs, or — a non-matching interface or a
/// pairing that projects (issue 45) — its Γ^a vertices not clamped, once the faces are checked
/// to face each other ([`file_interface`]) and the pairing takes the faces' degree.
fn two_body_contact(
    path: &Path,
    mesh: &GmshMesh,
    b: &crate::space::fe::GmshBodies,
    keys: &MeshBodies,
) -> Result<usize, String> {
    if b.unmatched.is_none() && keys.pairing == Pairing::NodeToNode {
        return Ok(b.pairs.len());
    }
    let i = file_interface(mesh)?;
    if i.curved && keys.pairing != Pairing::NodeToNode {
        return Err(format!(
            "{}: pairing = {} on degree-2 cells: its rows are built on the faces' vertices (2-node segments, 3-node triangles, 4-node quadrilaterals); use space = nitsche, or a mesh of degree-1 cells",
            path.display(),
            if keys.pairing == Pairing::Mortar {
                "mortar"
            } else {
                "node-to-segment"
            }
        ));
    }
    let clamped = mesh.group("clamped").map_or(&[][..], |g| &g.nodes[..]);
    Ok(i.sides[0]
        .nodes
        .iter()
        .filter(|n| clamped.binary_search(n).is_err())
        .count())
}

/// `start = "static"` (contract §1.8) where a static state under the run's loads can exist: one
/// body (two bodies: not yet), a load (gravity; without one the static state is u⁰ = 0, the rest
/// start), and a support (the plane at gap 0 or a clamp: a body off the plane and clamped nowhere
/// falls). Whether contact alone holds it tangentially (friction) is the start's own check.
fn static_start_applies(p: &Physics, path: &Path, two: bool, free: bool) -> Result<(), String> {
    let why = if two {
        "a static start of two bodies is not implemented yet"
    } else if p.get("gravity") == 0.0 {
        "without gravity the static state is u⁰ = 0, the rest start (drop start or set gravity)"
    } else if free && p.get("gap") > 0.0 {
        "the body is clamped nowhere and off the plane (gap > 0): it falls, there is no static state"
    } else {
        return Ok(());
    };
    Err(format!("{}: start = \"static\": {why}", path.display()))
}

impl MeshScene {
    fn file_only(&self, what: &str) -> String {
        format!(
            "scene {} takes its mesh from the `mesh` key (a Gmsh file; h is its largest element diameter), not from `{what}`",
            self.name()
        )
    }
}

impl Scene for MeshScene {
    fn contact_init_matters(&self, p: &Physics) -> bool {
        LoadModel::loads_massless_dofs(p)
    }
    fn fe_dim(&self) -> Option<usize> {
        Some(self.dim)
    }
    fn facts(&self) -> SceneFacts {
        SceneFacts {
            name: if self.dim == 2 { "mesh2d" } else { "mesh3d" },
            physics: &MESH_PHYSICS,
            // The bars' T: a body of unit size at the bars' wave speed.
            default_t: 2.0,
        }
    }
    /// The P-wave speed; of two bodies, the larger (B's keys default to A's, NaN when not
    /// given: the one-body speed).
    fn wave_speed(&self, p: &Physics) -> f64 {
        let c = |l: f64, m: f64, r: f64| ((l + 2.0 * m) / r).sqrt();
        let a = c(p.get("lame_lambda"), p.get("lame_mu"), p.get("density"));
        let b = c(
            given_or(p, "lame_lambda_b", p.get("lame_lambda")),
            given_or(p, "lame_mu_b", p.get("lame_mu")),
            given_or(p, "density_b", p.get("density")),
        );
        a.max(b)
    }
    fn mesh_from_h(&self, _p: &Physics, _h: f64) -> Result<MeshChoice, String> {
        Err(self.file_only("h"))
    }
    fn mesh_from_elements(&self, _p: &Physics, _elements: usize) -> Result<MeshChoice, String> {
        Err(self.file_only("elements"))
    }
    fn takes_mesh_file(&self) -> bool {
        true
    }
    /// Two mesh files are not nested in general: a reference stores its whole mesh and the run
    /// locates its nodes in it, whatever the files (the same file included: exact at the nodes).
    fn nested_meshes(&self) -> bool {
        false
    }
    fn supports(&self, m: MethodNames<'_>) -> Result<(), (&'static str, String)> {
        super::fe_supports(self.name(), m)
    }
    /// A two-body file's interface keys as the blocks' (contract §2.6; a one-body file refuses
    /// them as every two-body key).
    fn supports_interface(
        &self,
        p: &Physics,
        m: InterfaceUse<'_>,
    ) -> Result<(), (&'static [&'static str], String)> {
        super::two_body::check_interface(p, 1.0, m)
    }
    fn error_source(&self, _p: &Physics) -> Option<ErrorSource> {
        Some(ErrorSource::ReferenceRun)
    }
    fn setup(&self, _p: &Physics, _mesh: MeshChoice) -> SceneSetup {
        unreachable!("scene {} is set up from its mesh file", self.name())
    }
    fn setup_from_file(
        &self,
        p: &Physics,
        path: &Path,
        mesh: &GmshMesh,
    ) -> Result<(MeshChoice, SceneSetup), String> {
        if mesh.dim != self.dim {
            return Err(format!(
                "{}: a {}D mesh, scene {} needs a {}D one",
                path.display(),
                mesh.dim,
                self.name(),
                self.dim
            ));
        }
        let clamped = mesh.group("clamped").map_or(&[][..], |g| &g.nodes[..]);
        let bodies = match &mesh.bodies {
            Some(_) => Some(mesh_bodies(p, path)?),
            None => {
                if let Some((key, v)) = two_body_keys_on_one_body(p) {
                    return Err(format!(
                        "{}: {key} = {v} applies to a two-body mesh (physical groups \"body_a\" and \"body_b\", contract §1.10); this file holds one body",
                        path.display()
                    ));
                }
                None
            }
        };
        let contact = match (&mesh.bodies, &bodies) {
            (Some(b), Some(keys)) => two_body_contact(path, mesh, b, keys)?,
            _ => mesh.contact_nodes().len(),
        };
        if contact == 0 {
            return Err(format!(
                "{}: every node of the group \"contact\" is in \"clamped\": no contact dof is left",
                path.display()
            ));
        }
        let static_start = p.get("start") == 1.0;
        if static_start {
            static_start_applies(p, path, bodies.is_some(), clamped.is_empty())?;
        }
        let choice = MeshChoice {
            elements: mesh.num_elements(),
            h: mesh.h,
        };
        let geometry = FeGeometry::Mesh {
            path: path.to_path_buf(),
            content_hash: mesh.content_hash.clone(),
            dim: mesh.dim,
            nodes: mesh.num_nodes(),
            clamped_nodes: clamped.len(),
            contact_nodes: contact,
            nodes_per_element: mesh.nodes_per_element(),
            // Two bodies: H_a + H_b, each body's own extent (the blocks' length scale),
            // whatever the file's distance between them.
            height: match &mesh.bodies {
                None => mesh.extent(|_| true),
                Some(b) => (0..2u8)
                    .map(|body| mesh.extent(|n| b.node_body[n] == body))
                    .sum(),
            },
            bodies,
        };
        Ok((
            choice,
            SceneSetup::Fe(FeSetup {
                scene: self.name(),
                dim: self.dim,
                geometry,
                h: mesh.h,
                density: p.get("density"),
                lame_lambda: p.get("lame_lambda"),
                lame_mu: p.get("lame_mu"),
                gap: p.get("gap"),
                gravity: p.get("gravity"),
                load: LoadModel::from_index(p.get("load")),
                v0: p.get("velocity"),
                v0_tangential: p.get("velocity_tangential"),
                incline: p.get("incline"),
                static_start,
            }),
        ))
    }
}
