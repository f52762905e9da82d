//! The sparse finite-element engine: every FE scene × mass variant × implicit scheme with nodal
//! (`mixed`) Signorini contact (SPEC §1.2, §2.1–2.2, §3, §4).
//!
//! Semi-discrete system M ü + K u = F + Bᵀλ on the free dofs (the clamped face removed), with
//! λ ≥ 0 the upward nodal contact forces on the vertical dofs of Γ_C and u_d + g ≥ 0 there.
//! Newmark(β, γ) and the θ-scheme share one form,
//!
//!   u^{n+1} = p^n + c τ² a^{n+1},   p^n = u^n + τ v^n + c₁ τ² a^n,
//!   v^{n+1} = v^n + τ((1−γ) a^n + γ a^{n+1}),   equation at t^{n+1},
//!
//! with (c₁, c, γ) = ((1−2β)/2, β, γ) for Newmark and (θ(1−θ), θ², θ) for the θ-scheme. So every
//! step solves (M + c τ² K) u^{n+1} = M p^n + c τ² (F + Bᵀλ^{n+1}): A = M + cτ²K is constant —
//! factored once per run (sparse Cholesky, symbolic analysis once per mesh) and shared between
//! runs with the same matrix. The contact is condensed onto the contact dofs: Z = A⁻¹Bᵀ and
//! W = B Z are computed once per run; a step is one sparse solve y = A⁻¹(M p^n + cτ²F), the exact
//! LCP λ ≥ 0 ⊥ By + g + cτ²Wλ ≥ 0 ([`crate::contact::lcp`], warm-started from the previous
//! step), and u^{n+1} = y + cτ² Z λ over the active contact dofs. Never a refactorisation.
//! With `solver = "cg"` ([`crate::space::step_solver`]) nothing is factored: the same solves
//! (the step's and Z's columns) are made by preconditioned conjugate gradient on A itself,
//! each step warm-started from the previous one; a CG failure ends the run `solver-failed`.
//!
//! Massless dofs (the bottom nodes with mod1/mod2/mod3/weights/zero-contact) need no special
//! case: their rows of M are zero, so their row of the step system is c τ² (K u − F − Bᵀλ) = 0,
//! the quasi-static equation at t^{n+1} (SPEC §1.2). Their a and v are never used (their M rows
//! and columns vanish), the energy E = ½vᵀMv + ½uᵀKu − Fᵀu is the run's own.
//!
//! Errors against a reference run (nested mesh and step): e^n = u^n − I_h u_ref(t^n) at the
//! coarse nodes, ‖e‖²_L2 = eᵀ G e with the unweighted Gram matrix, H1 = L2 + eᵀ D e with
//! D = ∫∇e:∇e (SPEC §1.2). The disc/ball's and the mesh files' references may be on another
//! mesh (the mapped meshes of different sizes are not nested; another mesh file; the bars' box
//! for a mesh file of the bar): the reference's function is interpolated at the run's nodes
//! ([`ball_ref_map`]).
//!
//! Observables per step (SPEC §1.3): the parts ½vᵀMv, ½uᵀKu, −Fᵀu of E^h, the lowest Γ_C
//! node's u_d (disc/ball), and the penetration max (u_n − g)_+ = max(−u_d − g)_+ over the Γ_C
//! nodes (the run's `max_penetration` is its maximum over the steps; Nitsche and the penalty
//! are measured at the same nodes). Nothing is allocated in the time loop.

use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use super::fe_nitsche::{FrictionState, NewtonWork, NitscheOps, newton, newton_friction};
use super::friction_tally::{FrictionTally, MeanVelocity};
use super::observe::{Divergence, ExactValues, Observer, SampledTimer, StepValues};
use super::reference::ReferenceData;
use super::{Metrics, Outcome, RunContext, RunOptions, Series, Status, Stop};
use crate::contact::friction::FrictionLaw;
use crate::contact::{FrictionalContact, Lcp};
use crate::scene::{FeGeometry, FeSetup, LoadModel};
use crate::space::cg::{CgOptions, CgWork, jacobi, pcg_into};
use crate::space::fe::locate::{PlainMesh, PointLocator};
use crate::space::fe::mesh::mesh_layers;
use crate::space::fe::nitsche::{
    ContactPoint, box_contact_faces, contact_points, face_contact_points, gmsh_contact_faces,
};
use crate::space::fe::{
    BallMesh, BoxMesh, DofMap, ElementOp, GmshMesh, Mesh, Pattern, SymMatrix, assemble,
    assemble_load, fe_pattern,
};
use crate::space::linalg::{CholeskyOptions, FactorKind, LinalgError, Ordering, SymbolicCholesky};
use crate::space::step_solver::{Solver, StepSolver, StepWork};
use crate::space::{ContactMethod, MassVariant};
use crate::time::Scheme;

// The methods of SPEC §3.2 (kane, contact-stabilized Newmark, generalized-α, Moreau–Jean, the
// discrete gradient, kinematic central difference): a child module, so it reuses this engine's
// geometry, factors and caches as they are.
#[path = "fe_methods.rs"]
mod methods;

// Lockstep groups: runs sharing the step matrix make their solves together (issue 24).
#[path = "fe_lockstep.rs"]
mod lockstep;
pub use lockstep::{lockstep_key, simulate_group};

/// Steps between two checks of the clock and of an interruption.
const CLOCK_EVERY: usize = 64;
/// The contact LCP: tolerance relative to the largest gap, and the iteration cap (SPEC §4).
const LCP_TOL: f64 = 1e-12;
const LCP_MAX_ITER: usize = 100;

/// A validated finite-element run.
#[derive(Debug, Clone, PartialEq)]
pub struct FeConfig {
    pub setup: FeSetup,
    pub method: ContactMethod,
    pub mass: MassVariant,
    pub scheme: Scheme,
    pub dt: f64,
    pub steps: usize,
    /// Direct (Cholesky) or iterative (CG) step solves (`solver`, `cg_tol`).
    pub solver: Solver,
    /// Ensemble member: relative amplitude of a uniform perturbation of v⁰ (u⁰ = 0 here) and
    /// its seed.
    pub perturbation: Option<(f64, u64)>,
    /// The friction law on Γ_C (SPEC §2.5; `None`: today's frictionless engine).
    pub friction: FrictionLaw,
}

impl FeConfig {
    /// Free unknowns (nodes off the clamped face × d).
    pub fn unknowns(&self) -> usize {
        match &self.setup.geometry {
            FeGeometry::Box { cells, .. } => {
                let d = cells.len();
                // Saturating: the planner sizes runs before refusing the huge ones.
                let count = |cs: &[usize]| cs.iter().fold(1usize, |p, c| p.saturating_mul(c + 1));
                let (nodes, top) = (count(cells), count(&cells[..d - 1]));
                (nodes - top).saturating_mul(d)
            }
            FeGeometry::Mesh {
                dim,
                nodes,
                clamped_nodes,
                ..
            } => nodes.saturating_sub(*clamped_nodes).saturating_mul(*dim),
            FeGeometry::Ball {
                dim,
                degree,
                n_t,
                n_r,
                ..
            } => {
                // The central block's lattice, then n_r·p shells of the outer blocks: a shell is
                // a square's perimeter (2D) or a cubed sphere's surface lattice (3D).
                let (t, r) = (n_t * degree, n_r * degree);
                let nodes = if *dim == 2 {
                    (t + 1).pow(2) + 4 * t * r
                } else {
                    (t + 1).pow(3) + r * (6 * t * t + 2)
                };
                nodes * dim
            }
        }
    }

    /// The CFL step of kinematic central difference (mixed + lumped, [`methods`]); every other
    /// explicit scheme is refused.
    pub fn explicit_dt_limit(&self) -> Result<Option<f64>, (&'static str, String)> {
        if methods::kinematic(self) {
            return methods::kinematic_dt_limit(self).map(Some);
        }
        if self.scheme.is_explicit() {
            return Err((
                "scheme",
                format!(
                    "scheme {} is explicit: with the nodal multiplier the contact dofs must be massless, whose quasi-static rows make the step implicit; scene {} takes implicit newmark and theta schemes",
                    self.scheme.label(),
                    self.setup.scene
                ),
            ));
        }
        Ok(None)
    }

    /// (c₁, c, γ) of the common scheme form (module header).
    fn coefficients(&self) -> Result<(f64, f64, f64), String> {
        match self.scheme {
            Scheme::Newmark(p) if p.beta > 0.0 => Ok((0.5 - p.beta, p.beta, p.gamma)),
            Scheme::Theta(p) if p.theta > 0.0 => {
                Ok((p.theta * (1.0 - p.theta), p.theta * p.theta, p.theta))
            }
            // The hybrid scheme has its own loop with Crank–Nicolson's step matrix (c = ¼).
            Scheme::Hybrid
                if matches!(
                    self.method,
                    ContactMethod::Nitsche { .. } | ContactMethod::Penalty { .. }
                ) =>
            {
                Ok((0.25, 0.25, 0.5))
            }
            s => Err(format!(
                "scheme {} is not available for scene {}",
                s.label(),
                self.setup.scene
            )),
        }
    }
}

/// The mesh of a geometry: the bars' box, the mapped disc/ball, or a Gmsh mesh with its mass
/// layers (SPEC §1.6).
#[derive(Debug)]
enum FeMesh {
    Box(BoxMesh),
    Ball(BallMesh),
    Gmsh {
        mesh: Arc<GmshMesh>,
        layers: Vec<usize>,
    },
}

impl FeMesh {
    fn mesh(&self) -> &dyn Mesh {
        match self {
            FeMesh::Box(m) => m,
            FeMesh::Ball(m) => m,
            FeMesh::Gmsh { mesh, .. } => &**mesh,
        }
    }
    fn dim(&self) -> usize {
        self.mesh().dim()
    }
    /// Mass layer of element e (SPEC §2.2; layer 0 touches Γ_C).
    fn element_layer(&self, e: usize) -> usize {
        match self {
            FeMesh::Box(m) => m.element_layer(e),
            FeMesh::Ball(m) => m.layers[e],
            FeMesh::Gmsh { layers, .. } => layers[e],
        }
    }
    fn num_layers(&self) -> usize {
        match self {
            FeMesh::Box(m) => m.num_layers(),
            FeMesh::Ball(m) => m.layers.iter().max().map_or(0, |l| l + 1),
            FeMesh::Gmsh { layers, .. } => layers.iter().max().map_or(0, |l| l + 1),
        }
    }
    /// The bars' box (reference lattices are defined on it only).
    fn as_box(&self) -> Option<&BoxMesh> {
        match self {
            FeMesh::Box(m) => Some(m),
            FeMesh::Ball(_) | FeMesh::Gmsh { .. } => None,
        }
    }
}

/// The operators of one geometry and material, shared by every run on it.
#[derive(Debug)]
struct Geometry {
    mesh: FeMesh,
    dofs: DofMap,
    pattern: Arc<Pattern>,
    /// The symbolic Cholesky analysis with these choices, made on first use: a `cg` run never
    /// asks for it (at 3·10⁵ dofs in 3D its supernodal structure alone is hundreds of MB).
    cholesky: CholeskyOptions,
    symbolic: OnceLock<Result<Arc<SymbolicCholesky>, LinalgError>>,
    k: SymMatrix,
    /// Unweighted Gram matrix (ρ = 1) and ∫∇u:∇v, for the error norms.
    gram: SymMatrix,
    grad: SymMatrix,
    /// Reduced index of the vertical dof of each Γ_C node, and the node.
    contact: Vec<usize>,
    /// Height x_d of each Γ_C node in the reference configuration, measured from the bottom
    /// face (box: 0, the run's `gap` is added) or from the rigid plane (ball: the gap is in it).
    contact_height: Vec<f64>,
    /// Whether the gap is already in `contact_height` (ball) or is the run's `gap` (box).
    gap_in_geometry: bool,
    /// Whether each node is on Γ_C (all nodes, clamped ones included).
    contact_node: Vec<bool>,
    /// Nitsche's quadrature points of Γ_C with γ0 = 1 (their `gamma` is h_K), dofs reduced; or
    /// why the mesh has none (a Gmsh `contact` group without boundary faces: `mixed` still runs).
    points: Result<Vec<ContactPoint>, String>,
    /// Trapezoidal weights of the Γ_C nodes (sum 1): the mean of a nodal field over Γ_C.
    contact_weight: Vec<f64>,
    /// |Γ_C|, the measure the weights were normalised by: contact_weight_i·|Γ_C| = ∫_ΓC φ_i,
    /// Tresca's node weight w_i (SPEC §2.5).
    contact_measure: f64,
    /// Reduced dofs that belong to a Γ_C node (all components).
    on_contact_node: Vec<bool>,
    /// Reduced indices of the vertical component.
    vertical: Vec<usize>,
    /// Reduced indices of the e_1 component (the tangential direction of `velocity_tangential`,
    /// SPEC §1.8).
    tangential: Vec<usize>,
}

impl Geometry {
    /// The symbolic analysis of the pattern (made once, by the first direct run).
    fn symbolic(&self) -> Result<Arc<SymbolicCholesky>, LinalgError> {
        self.symbolic
            .get_or_init(|| SymbolicCholesky::with_options(&self.pattern, &self.cholesky))
            .clone()
    }
}

/// The status of a run whose matrices could not be made: a mass variant the mesh cannot take
/// ("mass = …", [`mass_matrix`]) is the input's fault, anything else the solver's.
pub(super) fn factor_failure(message: &str) -> Status {
    if message.starts_with("mass = ") {
        Status::Invalid
    } else {
        Status::SolverFailed
    }
}

/// The matrices of one run: its mass variant and the factored (or, with `cg`, the iterated)
/// condensed step matrix.
#[derive(Debug)]
struct Factored {
    m: SymMatrix,
    /// M without its stored zeros, for the products of the time loop ([`SymMatrix::without_zeros`]:
    /// the same numbers, half the entries of the 2D vector mass).
    m_products: SymMatrix,
    mass_total: f64,
    /// The step solves: the Cholesky factor of A, or A itself for CG.
    chol: StepSolver,
    /// Z = A⁻¹Bᵀ, column-major (n × n_c).
    z: Vec<f64>,
    /// Mixed: H = cτ² B Z (n_c × n_c, row-major). Nitsche: W = P Z (Q × Q, row-major).
    h: Vec<f64>,
    /// Nitsche's rows of the run (Θ, γ0 applied); Z's columns are then A⁻¹(−t_q).
    nitsche: Option<NitscheOps>,
    /// Mixed with friction (SPEC §2.5): the tangential rows; Z then holds the tangential
    /// columns after the normal ones.
    friction: Option<FrictionFactor>,
}

/// The mixed method's condensation over the normal and tangential rows C of Γ_C.
#[derive(Debug)]
struct FrictionFactor {
    /// Reduced index of each Γ_C node's tangential dofs, node-major (d − 1 per node, e_1 then
    /// e_2): Z's column nc + i(d − 1) + c is A⁻¹ of the unit vector there.
    tangential: Vec<usize>,
    /// W = cτ² C Z (dm × dm, row-major), rows and columns node-major [normal, tangential…].
    w: Vec<f64>,
}

/// A process-wide cache: entries shared by concurrent runs (a second run waits for the first to
/// finish building) and kept for the next `CAP` distinct keys, so serial runs reuse them too.
struct Cache<T> {
    entries: Mutex<Vec<(String, Slot<T>)>>,
}

/// One cache entry: built once, by the first run that asks for it.
type Slot<T> = Arc<OnceLock<Result<Arc<T>, String>>>;

impl<T> Cache<T> {
    const CAP: usize = 4;

    const fn new() -> Self {
        Cache {
            entries: Mutex::new(Vec::new()),
        }
    }

    /// The value for `key`, built by `make` if absent; the flag says whether it was a hit.
    fn get(
        &self,
        key: String,
        make: impl FnOnce() -> Result<T, String>,
    ) -> (Result<Arc<T>, String>, bool) {
        let cell = {
            let mut e = self.entries.lock().unwrap_or_else(|p| p.into_inner());
            match e.iter().position(|(k, _)| *k == key) {
                Some(i) => {
                    let entry = e.remove(i);
                    let cell = Arc::clone(&entry.1);
                    e.push(entry);
                    cell
                }
                None => {
                    let cell = Arc::new(OnceLock::new());
                    e.push((key, Arc::clone(&cell)));
                    if e.len() > Self::CAP {
                        e.remove(0);
                    }
                    cell
                }
            }
        };
        let mut built = false;
        let r = cell
            .get_or_init(|| {
                built = true;
                make().map(Arc::new)
            })
            .clone();
        (r, !built)
    }
}

static GEOMETRIES: Cache<Geometry> = Cache::new();
static FACTORS: Cache<Factored> = Cache::new();

fn geometry_key(s: &FeSetup) -> String {
    format!(
        "{:?}|{:e}|{:e}|{:e}",
        s.geometry, s.density, s.lame_lambda, s.lame_mu
    )
}

/// The factor kind of a 2D step matrix: column by column (simplicial) at every size.
///
/// Why: faer's simplicial solve treats each right-hand side with the same scalar operations
/// whatever the number of columns, so a lockstep member ([`lockstep`]) equals its run alone bit
/// for bit through faer's own blocked solve; a supernodal factor needs the engine's
/// column-by-column sweep ([`crate::space::linalg::Cholesky::solve_columns_in_place`]), which in
/// 2D (thousands of supernodes of a few columns each) costs 1.4–1.7× faer's blocked solve. And
/// the supernodal factor buys nothing here. `cargo bench --bench solves` (faer 0.24, AMD, ms for
/// 8 right-hand sides: one at a time / faer's block / the column sweep, medians of 15
/// interleaved): 21 120 dofs simplicial 13.2 / 6.2 / 6.0, supernodal 23.3 / 8.5 / 13.9;
/// 83 200 dofs simplicial 60.5 / 26.6 / 26.8, supernodal 117.7 / 33.6 / 46.1. (An earlier
/// series on a quiet machine had the supernodal factor ahead at 83 200 dofs, 6.4 against
/// 7.6 ms for one solve: docs/performance.md.)
const FACTOR_KIND_2D: FactorKind = FactorKind::Simplicial;

/// The engine's fill-reducing ordering and factor kind, measured on M + τ²/4 K of the bars (one
/// solve): 2D: AMD ([`FACTOR_KIND_2D`]; nested dissection gives 5.3–6.9 M entries in L at 65 × 641
/// nodes against AMD's 4.9–6.2 M); 3D 9 × 9 × 81: the geometric nested dissection of the box
/// with supernodes, 6.6 M, 9.5 ms (AMD supernodal 10.0 M, 13.5 ms).
pub fn cholesky_options(mesh: &BoxMesh, dofs: &DofMap) -> CholeskyOptions {
    let d = mesh.dim;
    if d == 2 {
        CholeskyOptions {
            ordering: Ordering::Amd,
            kind: FACTOR_KIND_2D,
        }
    } else {
        CholeskyOptions {
            ordering: Ordering::Custom(dofs.order_by_nodes(&mesh.nested_dissection(), d)),
            kind: FactorKind::Supernodal,
        }
    }
}

fn build_geometry(s: &FeSetup) -> Result<Geometry, String> {
    match &s.geometry {
        FeGeometry::Box { extent, cells } => build_box(s, extent, cells),
        FeGeometry::Ball {
            dim,
            degree,
            radius,
            centre_height,
            n_t,
            n_r,
        } => {
            let mut centre = [0.0; 3];
            centre[dim - 1] = *centre_height;
            let mesh = BallMesh::new(*dim, *degree, *radius, centre, *n_t, *n_r)
                .map_err(|e| e.to_string())?;
            build_ball(s, mesh)
        }
        FeGeometry::Mesh {
            path, content_hash, ..
        } => {
            let mesh = GmshMesh::read_shared(path).map_err(|e| e.to_string())?;
            if mesh.content_hash != *content_hash {
                return Err(format!(
                    "{}: the mesh file changed after the sweep was planned (SHA-256 {} then, {} now); plan the sweep again",
                    path.display(),
                    content_hash,
                    mesh.content_hash
                ));
            }
            build_gmsh(s, mesh)
        }
    }
}

/// A Gmsh mesh (SPEC §1.6): the `clamped` group's nodes fixed (every component), contact on the
/// vertical dofs of the other `contact` nodes, each with its height above the lowest of them
/// (the run's `gap` is added: the plane is x_d = lowest − gap), Γ_C's mean weighting each node
/// by its faces' measures, mass layers by topology ([`mesh_layers`]).
fn build_gmsh(s: &FeSetup, mesh: Arc<GmshMesh>) -> Result<Geometry, String> {
    let d = mesh.dim;
    let nn = mesh.num_nodes();
    let mut clamped = vec![false; nn];
    if let Some(g) = mesh.group("clamped") {
        for &n in &g.nodes {
            clamped[n] = true;
        }
    }
    let dofs = DofMap::new(nn * d, |g| clamped[g / d]);
    let pattern = fe_pattern(&*mesh, &dofs);
    // AMD: an unstructured mesh has no lattice to dissect; simplicial in 2D, supernodal in 3D
    // (the bars' measurements, `cholesky_options`).
    let opts = CholeskyOptions {
        ordering: Ordering::Amd,
        kind: if d == 2 {
            FACTOR_KIND_2D
        } else {
            FactorKind::Supernodal
        },
    };
    let (k, gram, grad) = operators(s, &*mesh, &dofs, &pattern);
    let group = mesh
        .group("contact")
        .ok_or_else(|| format!("{}: no physical group \"contact\"", mesh.file))?;
    let cnodes = mesh.contact_nodes();
    let Some(lowest) = mesh.contact_floor() else {
        return Err(format!(
            "{}: every node of the group \"contact\" is clamped",
            mesh.file
        ));
    };
    let free = |g: usize| dofs.free_index(g).expect("Γ_C nodes are not clamped here");
    let contact: Vec<usize> = cnodes.iter().map(|&n| free(n * d + d - 1)).collect();
    let contact_height = cnodes
        .iter()
        .map(|&n| mesh.coords[n][d - 1] - lowest)
        .collect();
    // Each Γ_C face spreads its measure (of its vertices' straight line or flat polygon) evenly
    // over its nodes: the trapezoidal weights of the bars' bottom face for 2-node lines.
    let mut node_weight = vec![0.0; nn];
    for face in &group.elements {
        let c = |i: usize| mesh.coords[face[i]];
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            let x = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
        };
        let measure = match (d, face.len()) {
            (2, _) => {
                let v = sub(c(1), c(0));
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            }
            (_, 3 | 6) => 0.5 * cross(sub(c(1), c(0)), sub(c(2), c(0))),
            // Quadrilateral faces, Gmsh order (vertices around the face first): two triangles.
            _ => {
                0.5 * cross(sub(c(1), c(0)), sub(c(2), c(0)))
                    + 0.5 * cross(sub(c(2), c(0)), sub(c(3), c(0)))
            }
        };
        for &n in face {
            node_weight[n] += measure / face.len() as f64;
        }
    }
    let mut contact_weight: Vec<f64> = cnodes.iter().map(|&n| node_weight[n]).collect();
    let total: f64 = contact_weight.iter().sum();
    if total.is_nan() || total <= 0.0 {
        return Err(format!(
            "{}: the group \"contact\" has no boundary faces of positive measure",
            mesh.file
        ));
    }
    contact_weight.iter_mut().for_each(|w| *w /= total);
    let contact_measure = total;
    let mut contact_node = vec![false; nn];
    for &n in &cnodes {
        contact_node[n] = true;
    }
    let mut on_contact_node = vec![false; dofs.n_free()];
    for &n in &cnodes {
        for c in 0..d {
            on_contact_node[free(n * d + c)] = true;
        }
    }
    let vertical = (0..dofs.n_free())
        .filter(|&r| dofs.free[r] % d == d - 1)
        .collect();
    let tangential = (0..dofs.n_free())
        .filter(|&r| dofs.free[r].is_multiple_of(d))
        .collect();
    let layers = mesh_layers(&*mesh, &group.nodes);
    // Heights above the lowest Γ_C node, as the nodes' (the run adds its gap, [`factor`]).
    let points = gmsh_contact_faces(&mesh, group).map(|faces| {
        reduce_points(
            face_contact_points(&*mesh, &faces, s.lame_lambda, s.lame_mu, 1.0, lowest),
            &dofs,
        )
    });
    Ok(Geometry {
        mesh: FeMesh::Gmsh { mesh, layers },
        dofs,
        pattern,
        cholesky: opts,
        symbolic: OnceLock::new(),
        k,
        gram,
        grad,
        contact,
        contact_height,
        gap_in_geometry: false,
        contact_node,
        points,
        contact_weight,
        contact_measure,
        on_contact_node,
        vertical,
        tangential,
    })
}

/// The stiffness, Gram and grad-grad matrices of a mesh on its free dofs.
fn operators(
    s: &FeSetup,
    mesh: &dyn Mesh,
    dofs: &DofMap,
    pattern: &Arc<Pattern>,
) -> (SymMatrix, SymMatrix, SymMatrix) {
    let one = |_: usize| 1.0;
    let k = assemble(
        mesh,
        dofs,
        pattern,
        ElementOp::Stiffness {
            lambda: s.lame_lambda,
            mu: s.lame_mu,
        },
        &one,
    );
    let gram = assemble(mesh, dofs, pattern, ElementOp::Mass { rho: 1.0 }, &one);
    let grad = assemble(mesh, dofs, pattern, ElementOp::GradGrad, &one);
    (k, gram, grad)
}

/// The disc/ball: nothing clamped; contact on the vertical dofs of the Γ_C nodes, with gaps
/// their heights above the plane (SPEC §1.3: g(x) = x_d, u_n = −u_d).
fn build_ball(s: &FeSetup, mesh: BallMesh) -> Result<Geometry, String> {
    let d = mesh.dim;
    let dofs = DofMap::all(mesh.coords.len() * d);
    let pattern = fe_pattern(&mesh, &dofs);
    // AMD: the mapped mesh has no lattice to dissect; simplicial in 2D, supernodal in 3D (the
    // bars' measurements, `cholesky_options`).
    let opts = CholeskyOptions {
        ordering: Ordering::Amd,
        kind: if d == 2 {
            FACTOR_KIND_2D
        } else {
            FactorKind::Supernodal
        },
    };
    let (k, gram, grad) = operators(s, &mesh, &dofs, &pattern);
    let contact: Vec<usize> = mesh.contact_nodes.iter().map(|&n| n * d + d - 1).collect();
    let contact_height = mesh
        .contact_nodes
        .iter()
        .map(|&n| mesh.coords[n][d - 1])
        .collect();
    let contact_weight = mesh.contact_node_weights();
    // |Γ_C| by the faces' quadrature of `contact_node_weights` (the weights' normalisation).
    let contact_measure = mesh
        .contact_faces
        .iter()
        .map(|&f| {
            mesh.face_points(&mesh.boundary_faces[f], 3)
                .iter()
                .map(|q| q.weight)
                .sum::<f64>()
        })
        .sum();
    // The ball keeps its own face quadrature (its run ids and figures predate the general one);
    // all its dofs are free, so global and reduced dofs coincide.
    let points = Ok(contact_points(&mesh, s.lame_lambda, s.lame_mu, 1.0));
    let mut contact_node = vec![false; mesh.coords.len()];
    for &n in &mesh.contact_nodes {
        contact_node[n] = true;
    }
    let on_contact_node = (0..dofs.n_free()).map(|r| contact_node[r / d]).collect();
    let vertical = (0..dofs.n_free()).filter(|&r| r % d == d - 1).collect();
    let tangential = (0..dofs.n_free()).filter(|&r| r % d == 0).collect();
    Ok(Geometry {
        mesh: FeMesh::Ball(mesh),
        dofs,
        pattern,
        cholesky: opts,
        symbolic: OnceLock::new(),
        k,
        gram,
        grad,
        contact,
        contact_height,
        gap_in_geometry: true,
        contact_node,
        points,
        contact_weight,
        contact_measure,
        on_contact_node,
        vertical,
        tangential,
    })
}

fn build_box(s: &FeSetup, extent: &[f64], cells: &[usize]) -> Result<Geometry, String> {
    let mesh = BoxMesh::try_new(extent, cells).map_err(|e| e.to_string())?;
    let d = mesh.dim;
    let top = cells[d - 1];
    let clamped = |node: usize| mesh.node_index(node)[d - 1] == top;
    let dofs = DofMap::new(mesh.num_nodes() * d, |g| clamped(g / d));
    let pattern = fe_pattern(&mesh, &dofs);
    let opts = cholesky_options(&mesh, &dofs);
    let (k, gram, grad) = operators(s, &mesh, &dofs, &pattern);
    let bottom = mesh.nodes_on_plane(d - 1, 0);
    let free = |g: usize| dofs.free_index(g).expect("Γ_C is not clamped");
    let contact: Vec<usize> = bottom.iter().map(|&n| free(n * d + d - 1)).collect();
    // Trapezoidal weight of a node of the bottom face: ½ per end of each horizontal axis.
    let mut contact_weight: Vec<f64> = bottom
        .iter()
        .map(|&n| {
            let idx = mesh.node_index(n);
            (0..d - 1)
                .map(|a| {
                    if idx[a] == 0 || idx[a] == cells[a] {
                        0.5
                    } else {
                        1.0
                    }
                })
                .product()
        })
        .collect();
    let total: f64 = contact_weight.iter().sum();
    contact_weight.iter_mut().for_each(|w| *w /= total);
    // The bottom face's measure: the product of the horizontal extents.
    let contact_measure = extent[..d - 1].iter().product();
    let mut on_contact_node = vec![false; dofs.n_free()];
    for &n in &bottom {
        for c in 0..d {
            on_contact_node[free(n * d + c)] = true;
        }
    }
    let vertical = (0..dofs.n_free())
        .filter(|&r| dofs.free[r] % d == d - 1)
        .collect();
    let tangential = (0..dofs.n_free())
        .filter(|&r| dofs.free[r].is_multiple_of(d))
        .collect();
    let contact_height = vec![0.0; contact.len()];
    // Heights above the bottom face x_d = 0; the run adds its gap ([`factor`]).
    let points = Ok(reduce_points(
        face_contact_points(
            &mesh,
            &box_contact_faces(&mesh),
            s.lame_lambda,
            s.lame_mu,
            1.0,
            0.0,
        ),
        &dofs,
    ));
    let mut contact_node = vec![false; mesh.num_nodes()];
    for &n in &bottom {
        contact_node[n] = true;
    }
    Ok(Geometry {
        mesh: FeMesh::Box(mesh),
        dofs,
        pattern,
        cholesky: opts,
        symbolic: OnceLock::new(),
        k,
        gram,
        grad,
        contact,
        contact_height,
        gap_in_geometry: false,
        contact_node,
        points,
        contact_weight,
        contact_measure,
        on_contact_node,
        vertical,
        tangential,
    })
}

/// The points with their dofs as reduced indices (the run's unknowns). A clamped dof's value is
/// 0, so its coefficients are dropped: it keeps its slot (every point has the element's k
/// dofs, [`NitscheOps`]) with coefficient 0 on a free dof of the same element, which keeps
/// every rank-one update of [`factor_nitsche`] inside the FE pattern. A point whose element is
/// clamped entirely has u_n = σ_n = 0 for every u and is left out.
fn reduce_points(points: Vec<ContactPoint>, dofs: &DofMap) -> Vec<ContactPoint> {
    points
        .into_iter()
        .filter_map(|mut p| {
            let any = p.dofs.iter().find_map(|&g| dofs.free_index(g))?;
            for k in 0..p.dofs.len() {
                match dofs.free_index(p.dofs[k]) {
                    Some(r) => p.dofs[k] = r,
                    None => {
                        p.dofs[k] = any;
                        p.un[k] = 0.0;
                        p.sn[k] = 0.0;
                        // The tangential rows (friction), d − 1 of each, k apart.
                        let kk = p.un.len();
                        for i in (k..p.ut.len()).step_by(kk) {
                            p.ut[i] = 0.0;
                            p.st[i] = 0.0;
                        }
                    }
                }
            }
            Some(p)
        })
        .collect()
}

/// How `mod2` and `mod3` put the mass of layer 0 back (SPEC §2.2): the weight of every other
/// layer (mod2) and the weight of layer 1 (mod3).
#[derive(Debug, Clone, Copy)]
struct Redistribution {
    mod2: f64,
    mod3: f64,
}

impl Redistribution {
    /// Layers of equal mass m/L (the bars' box: uniform elements, as many per layer):
    /// mod2 = L/(L−1), mod3 = 2 — the 1D weights of 000 §3.
    fn equal_layers(layers: usize) -> Redistribution {
        Redistribution {
            mod2: layers as f64 / (layers as f64 - 1.0),
            mod3: 2.0,
        }
    }

    /// From the measured masses: total m, layer 0 m₀, layer 1 m₁ (the disc/ball, whose layers
    /// differ): mod2 = m/(m − m₀), mod3 = 1 + m₀/m₁, so the total mass is conserved.
    fn measured(total: f64, m0: f64, m1: f64) -> Redistribution {
        Redistribution {
            mod2: total / (total - m0),
            mod3: 1.0 + m0 / m1,
        }
    }
}

/// The element weight of layer `layer` (layer 0 touches Γ_C) for a mass variant (SPEC §2.2).
fn layer_weight(mass: &MassVariant, layer: usize, r: Redistribution) -> f64 {
    match (mass, layer) {
        (
            MassVariant::Mod1 | MassVariant::Mod2 | MassVariant::Mod3 | MassVariant::Weights(_),
            0,
        ) => 0.0,
        (MassVariant::Mod2, _) => r.mod2,
        (MassVariant::Mod3, 1) => r.mod3,
        (MassVariant::Weights(w), k) => w[(k - 1).min(w.len() - 1)],
        _ => 1.0,
    }
}

/// 1ᵀM1 over one component of the mass assembled with the element weights `weight` on the full
/// dof set (clamped nodes included), leaving out the entries `zeroed(i, j)` (dofs).
fn component_total(
    mesh: &dyn Mesh,
    rho: f64,
    weight: &dyn Fn(usize) -> f64,
    zeroed: &dyn Fn(usize, usize) -> bool,
) -> f64 {
    let d = mesh.dim();
    let all = DofMap::all(mesh.num_nodes() * d);
    let full_pattern = fe_pattern(mesh, &all);
    let full = assemble(mesh, &all, &full_pattern, ElementOp::Mass { rho }, weight);
    let mut total = 0.0;
    for j in (0..full_pattern.n).filter(|j| j % d == 0) {
        for k in full_pattern.col_ptr[j]..full_pattern.col_ptr[j + 1] {
            if !zeroed(full_pattern.row_idx[k], j) {
                total += full.values[k];
            }
        }
    }
    total
}

/// The volume load of a run with gravity (SPEC §1.3, §1.8) and what its time loop needs of it.
#[derive(Debug)]
struct GravityLoad {
    /// F on the free dofs: ∫ρ f·φ (`load = "body"`) or M_run f (`"inertial"`), with
    /// f = gravity·(sin α e_1 − cos α e_d) (α the `incline`, 0 but on the mesh scenes).
    force: Vec<f64>,
    /// a⁰ with M a⁰ = F − K u⁰ = F on the dofs with inertia (u⁰ = 0, no contact at t = 0; 003
    /// Remark 2.1), 0 on the massless ones (their rows are quasi-static: they never use it).
    a0: Vec<f64>,
    /// M e_d (the run's M), for the centre of mass e_dᵀ M u / e_dᵀ M e_d.
    m_ed: Vec<f64>,
    /// e_dᵀ M e_d.
    vertical_mass: f64,
    /// The unit relative energies are measured in, the same for every mass variant (m = ∫ρ the
    /// body's mass, |f| = gravity whatever the incline): m·|f|·gap, the work of the weight
    /// over the gap (SPEC §1.3), plus ½·m·V_t², the kinetic energy of the initial tangential
    /// velocity (SPEC §1.8; 0 unless `velocity_tangential` is given, so every earlier run keeps
    /// its scale). A body that starts on the plane at rest (both 0) would have no unit at all:
    /// it is measured in m·|f|·H, H its height along e_d, the work of its weight over its own
    /// size.
    energy_scale: f64,
}

/// The load of `cfg`'s gravity on `g` with the run's mass matrix `m` (None without gravity).
///
/// The load per unit mass is f = gravity·(sin α e_1 − cos α e_d) (SPEC §1.8: a plane tilted by
/// the `incline` α, seen in the plane's frame; α = 0 is f = −gravity e_d bit for bit, sin 0 = 0
/// and cos 0 = 1). With `load = "body"` (the papers' model) and a mass variant that keeps
/// 1ᵀM = ∫ρφ (consistent, lumped), F = M f in exact arithmetic (per component) and a⁰ = f
/// exactly: the body moves rigidly. A redistributed or removed mass keeps F but not M, so
/// a⁰ = M⁻¹F is no longer uniform (the body strains in free fall, SPEC §1.3): it is solved on
/// the dofs with inertia by conjugate gradients on M (κ = O(1), a few dozen iterations to
/// round-off).
fn gravity_load(
    g: &Geometry,
    cfg: &FeConfig,
    m: &SymMatrix,
) -> Result<Option<GravityLoad>, String> {
    let s = &cfg.setup;
    let fall = -s.gravity;
    if fall == 0.0 {
        return Ok(None);
    }
    if g.mesh.as_box().is_some() {
        return Err(format!(
            "scene {}: a volume load on the clamped bar is not supported",
            s.scene
        ));
    }
    let n = g.dofs.n_free();
    let mesh = g.mesh.mesh();
    let d = mesh.dim();
    // The load's components per unit mass: along the slope (e_1) and into the plane (e_d).
    let (sin, cos) = s.incline.to_radians().sin_cos();
    // A flat plane keeps f = −gravity e_d bit for bit (no −0.0 slope component either).
    let f_t = if s.incline == 0.0 {
        0.0
    } else {
        s.gravity * sin
    };
    let f_d = fall * cos;
    let mut ed = vec![0.0; n];
    for &r in &g.vertical {
        ed[r] = 1.0;
    }
    let mut m_ed = vec![0.0; n];
    m.matvec_into(&ed, &mut m_ed);
    let vertical_mass: f64 = g.vertical.iter().map(|&r| m_ed[r]).sum();
    // The body force on every dof, clamped ones included: its vertical sum is f_d·∫ρ (Σφ = 1).
    let mut f = [0.0; 3];
    f[0] = f_t;
    f[d - 1] = f_d;
    let all = DofMap::all(mesh.num_nodes() * d);
    let body = assemble_load(mesh, &all, s.density, f, &|_| 1.0);
    // |f_d| ≥ gravity·cos 89.99…° > 0: the planner keeps |α| < 90°.
    let body_mass = body.iter().skip(d - 1).step_by(d).sum::<f64>() / f_d;
    // M e_1 for the inertial load's slope component (only on an incline).
    let m_e1 = (f_t != 0.0).then(|| {
        let mut e1 = vec![0.0; n];
        for &r in &g.tangential {
            e1[r] = 1.0;
        }
        let mut out = vec![0.0; n];
        m.matvec_into(&e1, &mut out);
        out
    });
    let force: Vec<f64> = match s.load {
        LoadModel::Body => g.dofs.free.iter().map(|&gd| body[gd]).collect(),
        LoadModel::Inertial => match &m_e1 {
            None => m_ed.iter().map(|x| f_d * x).collect(),
            Some(m_e1) => m_ed
                .iter()
                .zip(m_e1)
                .map(|(x, y)| f_d * x + f_t * y)
                .collect(),
        },
    };
    // The rigid acceleration f on every free dof.
    let mut rigid: Vec<f64> = ed.iter().map(|e| f_d * e).collect();
    if f_t != 0.0 {
        for &r in &g.tangential {
            rigid[r] = f_t;
        }
    }
    let keeps_row_sums = matches!(cfg.mass, MassVariant::Consistent | MassVariant::Lumped);
    let a0 = if s.load == LoadModel::Inertial || keeps_row_sums {
        rigid
    } else {
        // (M + I_massless) a = F with F = 0 on the massless rows: M's massless rows and
        // columns are zero (module header of the mass variants), so a_f = M_ff⁻¹ F_f, a_c = 0.
        let mut shifted = m.clone();
        let diag = m.diagonal();
        let mut rhs = force.clone();
        for (j, &dj) in diag.iter().enumerate() {
            if dj == 0.0 {
                let k = shifted
                    .pattern
                    .position(j, j)
                    .expect("the pattern holds the diagonal");
                shifted.values[k] = 1.0;
                rhs[j] = 0.0;
            }
        }
        let inv = jacobi(&shifted).map_err(|e| format!("initial acceleration: {e}"))?;
        let mut a = rigid;
        let mut work = CgWork::new(n);
        pcg_into(
            &shifted,
            &inv,
            &rhs,
            &mut a,
            CgOptions::new(1e-14),
            &mut work,
        )
        .map_err(|e| format!("initial acceleration M a⁰ = F: {e}"))?;
        a
    };
    let v_t = s.v0_tangential;
    let mut energy_scale = body_mass * fall.abs() * s.gap;
    if v_t != 0.0 {
        energy_scale += 0.5 * body_mass * v_t * v_t;
    }
    if energy_scale == 0.0 {
        let heights = (0..mesh.num_nodes()).map(|a| mesh.coord(a)[d - 1]);
        let (lo, hi) = heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
            (lo.min(z), hi.max(z))
        });
        energy_scale = body_mass * fall.abs() * (hi - lo);
    }
    Ok(Some(GravityLoad {
        force,
        a0,
        m_ed,
        vertical_mass,
        energy_scale,
    }))
}

/// The Γ_C node nearest the plane, whose vertical dof gives `u_lowest` (the disc's and ball's
/// lowest point; a mesh body's lowest Γ_C node). The bars' bottom face is flat: none.
fn lowest_contact(g: &Geometry) -> Option<usize> {
    if g.mesh.as_box().is_some() {
        return None;
    }
    g.contact
        .iter()
        .zip(&g.contact_height)
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(&c, _)| c)
}

/// The run's mass matrix and 1ᵀM1 (per component: the total mass it represents).
fn mass_matrix(g: &Geometry, s: &FeSetup, mass: &MassVariant) -> Result<(SymMatrix, f64), String> {
    let layers = g.mesh.num_layers();
    if layers < 2 && mass.massless_contact() {
        return Err(format!(
            "mass = {} needs at least two element layers",
            mass.name()
        ));
    }
    let fm = &g.mesh;
    let mesh = fm.mesh();
    let never = |_: usize, _: usize| false;
    let redistribution = match fm {
        FeMesh::Ball(_) | FeMesh::Gmsh { .. }
            if matches!(mass, MassVariant::Mod2 | MassVariant::Mod3) =>
        {
            let layer_mass = |l: usize| {
                let w = |e: usize| f64::from(u8::from(fm.element_layer(e) == l));
                component_total(mesh, s.density, &w, &never)
            };
            let total = component_total(mesh, s.density, &|_| 1.0, &never);
            Redistribution::measured(total, layer_mass(0), layer_mass(1))
        }
        _ => Redistribution::equal_layers(layers),
    };
    let weight = |e: usize| layer_weight(mass, fm.element_layer(e), redistribution);
    let rho = ElementOp::Mass { rho: s.density };
    let mut m = assemble(mesh, &g.dofs, &g.pattern, rho, &weight);
    match mass {
        MassVariant::Lumped => {
            let sums = m.row_sums();
            // Row-sum lumping of P2 simplices gives the vertices no mass (triangles: their rows
            // of the P2 mass matrix sum to 0) or a negative one (tetrahedra): the step then
            // has massless or anti-inertial dofs and blows up at the contact (the Hertz
            // half-disc, docs/methods.md). Refused rather than run.
            if let Some((i, x)) = sums.iter().enumerate().find(|(_, x)| **x <= 0.0) {
                return Err(format!(
                    "mass = lumped: row-sum lumping gives free dof {i} the mass {x:.3e} ≤ 0 (the vertices of P2 triangles and tetrahedra); use consistent or a modified mass, or degree-1 elements"
                ));
            }
            m = SymMatrix::diagonal_from(&g.pattern, &sums);
        }
        MassVariant::ZeroContact => {
            let p = &g.pattern;
            for j in 0..p.n {
                for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                    if g.on_contact_node[j] || g.on_contact_node[p.row_idx[k]] {
                        m.values[k] = 0.0;
                    }
                }
            }
        }
        _ => {}
    }
    // 1ᵀM1 over one component, clamped nodes included: assembled on the full dof set.
    let d = mesh.dim();
    let bottom_node = |dof: usize| g.contact_node[dof / d];
    let zeroed = |i: usize, j: usize| {
        matches!(mass, MassVariant::ZeroContact) && (bottom_node(i) || bottom_node(j))
    };
    let total = component_total(mesh, s.density, &weight, &zeroed);
    Ok((m, total))
}

/// The part of a factor's cache key beyond geometry, mass, method and step: the run's gap when
/// the Nitsche/penalty rows carry it (box and Gmsh meshes, [`factor`]); empty otherwise, so the
/// mixed runs and the ball share their entries as before.
/// The identity of a run's step matrix and condensation (the [`FACTORS`] cache's key): the
/// geometry, mass, contact method, cτ² and solver — and the gap where it enters the operators.
/// The solver is part of it: a `cg` entry holds A itself, not its factor.
fn factor_key(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> String {
    format!(
        "{}|{:?}|{:?}|{:e}|{:?}",
        geometry_key(&cfg.setup),
        cfg.mass,
        cfg.method,
        c_tau2,
        cfg.solver
    ) + &factor_key_gap(g, cfg)
        + if frictional(cfg) && cfg.method == ContactMethod::Mixed {
            // The tangential columns are added: not the frictionless entry.
            "|friction"
        } else {
            ""
        }
        + &factor_key_friction(cfg)
}

/// A frictional Nitsche/penalty run's factor has the tangential rows (their k_q = 1/(γτ) holds
/// τ itself, not only cτ²): its own entry; empty for every other run.
fn factor_key_friction(cfg: &FeConfig) -> String {
    if frictional(cfg) && cfg.method != ContactMethod::Mixed {
        format!("|friction τ {:e}", cfg.dt)
    } else {
        String::new()
    }
}

fn factor_key_gap(g: &Geometry, cfg: &FeConfig) -> String {
    if cfg.method == ContactMethod::Mixed || g.gap_in_geometry {
        String::new()
    } else {
        format!("|gap {:e}", cfg.setup.gap)
    }
}

fn factor(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> Result<Factored, String> {
    let points = || -> Result<&[ContactPoint], String> {
        match &g.points {
            Ok(p) if !p.is_empty() => Ok(p),
            Ok(_) => Err(format!(
                "space = {} is not available for scene {}: Γ_C has no quadrature points",
                cfg.method.name(),
                cfg.setup.scene
            )),
            Err(e) => Err(format!(
                "space = {} is not available for scene {}: {e}",
                cfg.method.name(),
                cfg.setup.scene
            )),
        }
    };
    let mut ops = match cfg.method {
        ContactMethod::Nitsche { theta, gamma0 } => NitscheOps::new(points()?, theta, gamma0),
        ContactMethod::Penalty { gamma0 } => {
            // Young's modulus E = μ(3λ + 2μ)/(λ + μ) of κ = E·γ0/h_K (SPEC §2.4).
            let (l, m) = (cfg.setup.lame_lambda, cfg.setup.lame_mu);
            let young = m * (3.0 * l + 2.0 * m) / (l + m);
            NitscheOps::penalty(points()?, young, gamma0)
        }
        ContactMethod::Mixed => return factor_mixed(g, cfg, c_tau2),
    };
    // The box's and Gmsh meshes' points hold their heights above Γ_C's lowest level; the
    // plane is the run's gap below it (the ball's gap is in its geometry: nothing added).
    if !g.gap_in_geometry {
        ops.gap.iter_mut().for_each(|x| *x += cfg.setup.gap);
    }
    if frictional(cfg) {
        ops = ops.with_friction(points()?, cfg.dt);
    }
    factor_nitsche(g, cfg, c_tau2, ops)
}

/// The mixed method's factor: A = M + cτ²K, Z = A⁻¹Bᵀ, H = cτ² B Z. With friction Z also holds
/// A⁻¹ of the tangential unit vectors of the Γ_C nodes and W = cτ² C Z spans the normal and
/// tangential rows ([`FrictionFactor`]); H and the normal columns are made as without.
fn factor_mixed(g: &Geometry, cfg: &FeConfig, c_tau2: f64) -> Result<Factored, String> {
    let (m, mass_total) = mass_matrix(g, &cfg.setup, &cfg.mass)?;
    let a = SymMatrix::lin_comb(1.0, &m, c_tau2, &g.k);
    let chol = StepSolver::new(cfg.solver, || g.symbolic(), a).map_err(|e| e.to_string())?;
    let n = g.dofs.n_free();
    let nc = g.contact.len();
    let tangential = if frictional(cfg) {
        tangential_dofs(g)?
    } else {
        Vec::new()
    };
    let nz = nc + tangential.len();
    let mut z = vec![0.0; n * nz];
    for (j, &c) in g.contact.iter().chain(&tangential).enumerate() {
        z[j * n + c] = 1.0;
    }
    let mut work = chol.work_for(nz);
    chol.try_solve_many_in_place(&mut z, nz, &mut work)
        .map_err(|e| format!("the condensation columns A⁻¹Bᵀ: {e}"))?;
    let mut h = vec![0.0; nc * nc];
    for (i, &ci) in g.contact.iter().enumerate() {
        for j in 0..nc {
            h[i * nc + j] = c_tau2 * z[j * n + ci];
        }
    }
    // W is symmetric in exact arithmetic; symmetrise the round-off.
    symmetrise(&mut h, nc);
    let friction = (!tangential.is_empty()).then(|| {
        let d = g.mesh.dim();
        let dm = nc * d;
        // Row/column (i, a) of W: node i's normal (a = 0) or tangential a − 1; its dof and
        // its column of Z.
        let dof = |k: usize| {
            let (i, a) = (k / d, k % d);
            if a == 0 {
                g.contact[i]
            } else {
                tangential[i * (d - 1) + a - 1]
            }
        };
        let col = |k: usize| {
            let (i, a) = (k / d, k % d);
            if a == 0 { i } else { nc + i * (d - 1) + a - 1 }
        };
        let mut w = vec![0.0; dm * dm];
        for r in 0..dm {
            let dr = dof(r);
            for c in 0..dm {
                w[r * dm + c] = c_tau2 * z[col(c) * n + dr];
            }
        }
        symmetrise(&mut w, dm);
        FrictionFactor { tangential, w }
    });
    Ok(Factored {
        m_products: m.without_zeros(),
        m,
        mass_total,
        chol,
        z,
        h,
        nitsche: None,
        friction,
    })
}

/// The average of a square matrix (row-major, k × k) and its transpose, in place.
fn symmetrise(h: &mut [f64], k: usize) {
    for i in 0..k {
        for j in 0..i {
            let s = 0.5 * (h[i * k + j] + h[j * k + i]);
            h[i * k + j] = s;
            h[j * k + i] = s;
        }
    }
}

/// The body's mean velocities per axis (SPEC §5; [`MeanVelocity`]) with the run's mass matrix:
/// a reduced dof's axis is its global dof's component.
fn mean_velocity(g: &Geometry, m: &SymMatrix) -> MeanVelocity {
    let d = g.mesh.dim();
    MeanVelocity::new(d, m, |r| g.dofs.free[r] % d)
}

/// The reduced indices of the Γ_C nodes' tangential dofs, node-major (e_1, then e_2 in 3D).
/// Every Γ_C node's dofs are free (only the clamped face is removed, and it is not Γ_C), so
/// node i's component c sits d − 1 − c below its vertical one; checked against the DofMap.
fn tangential_dofs(g: &Geometry) -> Result<Vec<usize>, String> {
    let d = g.mesh.dim();
    let mut out = Vec::with_capacity(g.contact.len() * (d - 1));
    for &cv in &g.contact {
        let global = g.dofs.free[cv];
        for c in 0..d - 1 {
            let want = global - (d - 1 - c);
            match (cv.checked_sub(d - 1 - c), g.dofs.free_index(want)) {
                (Some(r), Some(f)) if r == f => out.push(r),
                _ => {
                    return Err(format!(
                        "friction: the tangential dof {c} of the Γ_C node with global vertical dof {global} is not free"
                    ));
                }
            }
        }
    }
    Ok(out)
}

/// A = M + cτ²(K − Θ Σ_q w_q γ_q s_q s_qᵀ) factored once, Z = A⁻¹C and W = P Z
/// ([`super::fe_nitsche`]; the penalty is the case Θ = 0 with its own rows). Each s_q lives on
/// one element's dofs, so the rank-one updates stay in the FE pattern.
fn factor_nitsche(
    g: &Geometry,
    cfg: &FeConfig,
    c_tau2: f64,
    ops: NitscheOps,
) -> Result<Factored, String> {
    let (m, mass_total) = mass_matrix(g, &cfg.setup, &cfg.mass)?;
    let mut a = SymMatrix::lin_comb(1.0, &m, c_tau2, &g.k);
    let (theta, gamma0) = match cfg.method {
        ContactMethod::Nitsche { theta, gamma0 } => (theta, gamma0),
        _ => (0.0, 0.0),
    };
    let (k, nq, n) = (ops.k, ops.len(), g.dofs.n_free());
    // The points' dofs are reduced indices already ([`reduce_points`]).
    let red = |gd: usize| gd;
    if theta != 0.0 {
        // σ_n's rows, and with friction the σ_t rows too (the full-vector form's
        // −Θ∫γ σ_t(u)·σ_t(v), fe_nitsche header).
        let td = ops.friction.as_ref().map_or(0, |f| f.td);
        for q in 0..nq {
            let f = c_tau2 * theta * ops.w[q] * ops.gamma[q];
            let d = &ops.dofs[q * k..(q + 1) * k];
            for r in 0..=td {
                let sq = match (r, ops.friction.as_ref()) {
                    (0, _) => &ops.s[q * k..(q + 1) * k],
                    (r, Some(fr)) => &fr.st[(q * td + r - 1) * k..(q * td + r) * k],
                    (_, None) => unreachable!("no tangential rows without friction"),
                };
                for (i, &gi) in d.iter().enumerate() {
                    for (j, &gj) in d.iter().enumerate() {
                        let pos = a
                            .pattern
                            .position(red(gi), red(gj))
                            .expect("element dofs are in the pattern");
                        a.values[pos] -= f * sq[i] * sq[j];
                    }
                }
            }
        }
    }
    // The condensed unknowns: the points' P_γ (and P_t with friction).
    let nq = ops.unknowns();
    let chol = StepSolver::new(cfg.solver, || g.symbolic(), a).map_err(|e| {
        format!("the Nitsche step matrix M + cτ²(K − Θ·γ-term) is not positive definite (Θ = {theta}, γ0 = {gamma0}): {e}")
    })?;
    let mut z = vec![0.0; n * nq];
    for q in 0..nq {
        let (c_row, dofs) = ops.c_row(q);
        for (&gd, &c) in dofs.iter().zip(c_row) {
            z[q * n + red(gd)] += c;
        }
    }
    let mut work = chol.work_for(nq);
    chol.try_solve_many_in_place(&mut z, nq, &mut work).map_err(|e| {
        format!("the Nitsche step matrix M + cτ²(K − Θ·γ-term) (Θ = {theta}, γ0 = {gamma0}), its condensation columns: {e}")
    })?;
    let mut h = vec![0.0; nq * nq];
    for q in 0..nq {
        let (p_row, dofs) = ops.p_row(q);
        for r in 0..nq {
            let zr = &z[r * n..(r + 1) * n];
            h[q * nq + r] = p_row.iter().zip(dofs).map(|(a, &g)| a * zr[g]).sum();
        }
    }
    Ok(Factored {
        m_products: m.without_zeros(),
        m,
        mass_total,
        chol,
        z,
        h,
        nitsche: Some(ops),
        friction: None,
    })
}

/// How the run reads its reference: for every free dof, its offset in a stored time slice (or,
/// on a mesh not nested in the reference's, the offsets and weights that interpolate the
/// reference there); and the stored index of coarse step n is n·`time_ratio`.
struct RefMap {
    data: Arc<ReferenceData>,
    dof_offset: Vec<usize>,
    interp: Option<Arc<Interpolation>>,
    time_ratio: usize,
}

/// I u_ref at the run's free dofs: dof i is Σ_k w_k u_ref[offset_k] over
/// `start[i]..start[i + 1]` ([`crate::space::fe::locate`]).
#[derive(Debug)]
struct Interpolation {
    start: Vec<usize>,
    offset: Vec<usize>,
    weight: Vec<f64>,
}

impl RefMap {
    /// The run at step n against the reference at the same time: e = u − I u_ref into `err`,
    /// its squared L2 and H1-seminorm (the Gram and grad-grad matrices, `tmp` as scratch), and
    /// the reference's scalar observables. One definition for every time loop of the engine.
    pub(super) fn compare(
        &self,
        g: &Geometry,
        step: usize,
        u: &[f64],
        err: &mut [f64],
        tmp: &mut [f64],
    ) -> ExactValues {
        let k = step * self.time_ratio;
        let base = k * self.data.lattice.iter().product::<usize>() * self.data.dim;
        for (i, e) in err.iter_mut().enumerate() {
            *e = u[i] - self.value(base, i);
        }
        let l2_sq = quad(&g.gram, err, tmp);
        let h1_semi_sq = quad(&g.grad, err, tmp);
        ExactValues {
            u_contact: self.data.u_contact[k],
            sigma_contact: -self.data.force[k],
            sigma_contact_mid: None,
            energy: self.data.energy[k],
            l2_sq,
            h1_semi_sq,
        }
    }

    /// The reference's value at free dof i in the stored slice starting at `base`.
    #[inline]
    fn value(&self, base: usize, i: usize) -> f64 {
        match &self.interp {
            None => self.data.u[base + self.dof_offset[i]],
            Some(ip) => (ip.start[i]..ip.start[i + 1])
                .map(|k| ip.weight[k] * self.data.u[base + ip.offset[k]])
                .sum(),
        }
    }
}

/// Interpolations shared by the runs of one mesh against one reference.
static INTERPOLATIONS: Cache<Interpolation> = Cache::new();

fn ref_map(g: &Geometry, cfg: &FeConfig, data: &Arc<ReferenceData>) -> Result<RefMap, String> {
    let Some(mesh) = g.mesh.as_box() else {
        return ball_ref_map(g, cfg, data);
    };
    let d = mesh.dim;
    let ratio = |coarse: f64, fine: f64, stride: usize, what: &str| {
        let q = coarse / fine;
        let r = q.round() as usize;
        if r == 0 || (q - r as f64).abs() > 1e-9 * q || !r.is_multiple_of(stride) {
            Err(format!(
                "the reference's {what} ({fine}) is not nested in the run's ({coarse}) on its stored lattice (stride {stride})"
            ))
        } else {
            Ok(r / stride)
        }
    };
    let rs = ratio(cfg.setup.h, data.h, data.space_stride, "mesh size")?;
    let rt = ratio(cfg.dt, data.dt, data.time_stride, "time step")?;
    if data.dim != d || (0..d).any(|a| mesh.cells[a] * rs + 1 != data.lattice[a]) {
        return Err("the reference's lattice does not cover the run's mesh".into());
    }
    if cfg.steps * rt >= data.times {
        return Err(format!(
            "the reference holds {} stored times, the run needs {}",
            data.times,
            cfg.steps * rt + 1
        ));
    }
    let slice = data.lattice.iter().product::<usize>() * d;
    let _ = slice;
    let dof_offset = g
        .dofs
        .free
        .iter()
        .map(|&gd| {
            let idx = mesh.node_index(gd / d);
            let l = [idx[0] * rs, idx[1] * rs, idx[2] * rs];
            let node = l[0] + data.lattice[0] * (l[1] + data.lattice[1] * l[2]);
            node * d + gd % d
        })
        .collect();
    Ok(RefMap {
        data: Arc::clone(data),
        dof_offset,
        interp: None,
        time_ratio: rt,
    })
}

/// The disc/ball or a mesh file's run against its reference. On the run's own mesh (a finer
/// step only) the stored dofs are the run's, read one to one. On another mesh — the mapped
/// meshes of two sizes are not nested: n_t = 2·round(πR/(4h)) and n_r = round((R − a)/h) give
/// (8, 3), (16, 5), (32, 10) at h = 4, 2, 1; another mesh file; the bars' box meshed by a mesh
/// file (SPEC §1.6) — each run node is located in the reference's stored mesh and the
/// reference's finite-element function is evaluated there ([`Interpolation`]).
fn ball_ref_map(g: &Geometry, cfg: &FeConfig, data: &Arc<ReferenceData>) -> Result<RefMap, String> {
    // The reference stores every node of its mesh, node-major (`record_lattice`; a mesh
    // file's clamped nodes as zeros, a box's at stride 1 in its lattice order = node order).
    let d = g.mesh.dim();
    let mesh = g.mesh.mesh();
    let nodes = mesh.num_nodes();
    let same_mesh = data.h == cfg.setup.h
        && data.lattice == [nodes, 1, 1]
        && data.mesh.as_ref().is_none_or(|m| {
            m.dim == d
                && m.nodes_per_element == mesh.nodes_per_element()
                && m.coords.len() == nodes
                && (0..nodes).all(|n| m.coords[n] == mesh.coord(n))
                && (0..mesh.num_elements()).all(|e| m.element_nodes(e) == mesh.element_nodes(e))
        });
    // Interpolating reads the reference's dofs by node (rn·d + component): every node of its
    // stored mesh must be stored.
    let interpolable = data
        .mesh
        .as_ref()
        .is_some_and(|m| data.lattice.iter().product::<usize>() == m.coords.len());
    if data.space_stride != 1 || (!same_mesh && !interpolable) {
        return Err(format!(
            "scene {}: the reference (h = {}, {} stored nodes) is on another mesh than the run's (h = {}, {nodes} nodes) and cannot be interpolated: it does not store its whole mesh (written by an older version: remove DIR/references/ to record it again)",
            cfg.setup.scene,
            data.h,
            data.lattice.iter().product::<usize>(),
            cfg.setup.h
        ));
    }
    let q = cfg.dt / data.dt;
    let r = q.round() as usize;
    if r == 0 || (q - r as f64).abs() > 1e-9 * q || !r.is_multiple_of(data.time_stride) {
        return Err(format!(
            "the reference's time step ({}) is not nested in the run's ({}) on its stored times (stride {})",
            data.dt, cfg.dt, data.time_stride
        ));
    }
    let rt = r / data.time_stride;
    if data.dim != d || cfg.steps * rt >= data.times {
        return Err(format!(
            "the reference holds {} stored times, the run needs {}",
            data.times,
            cfg.steps * rt + 1
        ));
    }
    let interp = match (&data.mesh, same_mesh) {
        (Some(ref_mesh), false) => {
            let key = format!(
                "{}|{:p}|{:e}|{}|{}",
                geometry_key(&cfg.setup),
                Arc::as_ptr(data),
                data.h,
                data.times,
                ref_mesh.coords.len()
            );
            let (ip, _) = INTERPOLATIONS.get(key, || interpolation(g, ref_mesh));
            Some(ip.map_err(|e| format!("scene {}: {e}", cfg.setup.scene))?)
        }
        _ => None,
    };
    Ok(RefMap {
        data: Arc::clone(data),
        // On the same mesh: free dof i is global dof free[i] = node·d + component.
        dof_offset: g.dofs.free.clone(),
        interp,
        time_ratio: rt,
    })
}

/// Locate every node of the run's mesh in the reference mesh; the weights of a node serve each
/// of its components (the reference stores every dof of its mesh, node-major).
fn interpolation(g: &Geometry, reference: &PlainMesh) -> Result<Interpolation, String> {
    let d = g.mesh.dim();
    let locator = PointLocator::new(reference).map_err(|e| e.to_string())?;
    let mesh = g.mesh.mesh();
    let mut per_node: Vec<Option<Vec<(usize, f64)>>> = vec![None; mesh.num_nodes()];
    let n = g.dofs.n_free();
    let mut ip = Interpolation {
        start: Vec::with_capacity(n + 1),
        offset: Vec::new(),
        weight: Vec::new(),
    };
    ip.start.push(0);
    for &gd in &g.dofs.free {
        let node = gd / d;
        if per_node[node].is_none() {
            per_node[node] = Some(
                locator
                    .weights(mesh.coord(node))
                    .map_err(|e| format!("run node {node}: {e}"))?,
            );
        }
        for &(rn, w) in per_node[node].as_ref().expect("just set") {
            ip.offset.push(rn * d + gd % d);
            ip.weight.push(w);
        }
        ip.start.push(ip.offset.len());
    }
    Ok(ip)
}

/// The stored slots (a reduced dof or none, per lattice node and component) and the lattice of
/// a reference run: every `space_stride`-th node of the bars' box, or every node of the
/// disc/ball or mesh file, clamped ones included (stride 1 only: its meshes are not nested,
/// [`ball_ref_map`]).
fn record_lattice(
    g: &Geometry,
    cfg: &FeConfig,
    space_stride: usize,
) -> Result<(Vec<Option<usize>>, [usize; 3]), String> {
    let d = g.mesh.dim();
    let Some(bx) = g.mesh.as_box() else {
        if space_stride != 1 {
            return Err(format!(
                "scene {}: a reference run must be on the runs' mesh (their h / its h = {space_stride}): the mapped meshes of different sizes are not nested",
                cfg.setup.scene
            ));
        }
        // Node-major over every node: a run on another mesh reads the reference by node
        // ([`interpolation`]); a clamped dof (mesh files) has no slot and is stored as 0.
        let n = g.mesh.mesh().num_nodes() * d;
        return Ok((
            (0..n).map(|gd| g.dofs.free_index(gd)).collect(),
            [n / d, 1, 1],
        ));
    };
    let lattice = [0, 1, 2].map(|ax| {
        if ax < d {
            bx.cells[ax] / space_stride + 1
        } else {
            1
        }
    });
    let mut slots = Vec::with_capacity(lattice.iter().product::<usize>() * d);
    for k in 0..lattice[2] {
        for j in 0..lattice[1] {
            for i in 0..lattice[0] {
                let node = bx.node_id([i * space_stride, j * space_stride, k * space_stride]);
                for comp in 0..d {
                    slots.push(g.dofs.free_index(node * d + comp));
                }
            }
        }
    }
    Ok((slots, lattice))
}

/// The reference this run records, if it is one: the slots of its stored lattice and the empty
/// data. Meshes that are not nested store themselves: a coarser run locates its nodes in this
/// one ([`ball_ref_map`]). So does the bars' box stored whole (stride 1: its lattice is its
/// node numbering), for the runs on a mesh file of the same bar (SPEC §1.6); a nested bar run
/// still reads it node for node.
#[allow(clippy::type_complexity)]
fn reference_record(
    g: &Geometry,
    cfg: &FeConfig,
    ctx: &RunContext,
) -> Result<Option<(Vec<Option<usize>>, ReferenceData)>, String> {
    let Some((space_stride, time_stride)) = ctx.record_reference else {
        return Ok(None);
    };
    let (slots, lattice) = record_lattice(g, cfg, space_stride)?;
    let times = cfg.steps / time_stride + 1;
    let mesh = (g.mesh.as_box().is_none() || space_stride == 1)
        .then(|| PlainMesh::from_mesh(g.mesh.mesh()));
    let data = ReferenceData::new(
        g.mesh.dim(),
        cfg.setup.h,
        cfg.dt,
        space_stride,
        time_stride,
        lattice,
        times,
        mesh,
    );
    Ok(Some((slots, data)))
}

/// Run one finite-element simulation.
pub fn simulate(cfg: &FeConfig, opts: &RunOptions, ctx: &RunContext) -> Outcome {
    // The methods of SPEC §3.2 solve friction with the nodal multiplier in their own loops.
    if frictional(cfg) && methods::handles(cfg) && cfg.method == ContactMethod::Mixed {
        return methods::simulate(cfg, opts, ctx);
    }
    // Friction is solved by Nitsche and the penalty with the Newmark family and θ-schemes
    // (fe_nitsche header) and with generalized-α/HHT (fe_methods header, the same frictional
    // Newton), by the mixed method in [`Stepper`] and in the §3.2 methods' loops.
    let nitsche_solved = cfg.method != ContactMethod::Mixed
        && (matches!(cfg.scheme, Scheme::Newmark(_) | Scheme::Theta(_)) && !methods::handles(cfg)
            || matches!(cfg.scheme, Scheme::GeneralizedAlpha(_)));
    if frictional(cfg) && !mixed_stepper(cfg) && !nitsche_solved {
        return Outcome {
            status: Status::Invalid,
            message: Some(format!(
                "friction = {} with space = {} and scheme = {} has no frictional version (SPEC §2.5)",
                cfg.friction.kind().name(),
                cfg.method.name(),
                cfg.scheme.label()
            )),
            metrics: Metrics::default(),
            series: Series::default(),
            reference: None,
        };
    }
    if methods::handles(cfg) {
        return methods::simulate(cfg, opts, ctx);
    }
    // Alone is a lockstep group of one: the same loop, each solve with the run's own work
    // (CG warm-starts from its previous step).
    match Stepper::new(cfg, opts, ctx) {
        Err(out) => *out,
        Ok(s) => {
            let mut done = lockstep::step_together(vec![(0, s)]);
            done.pop().expect("one member, one outcome").1
        }
    }
}

/// Whether [`Stepper`] runs `cfg` with `mixed` contact: the Newmark family and the θ-scheme
/// (the hybrid scheme is Nitsche's and the penalty's; SPEC §3.2's methods have their own loops).
fn mixed_stepper(cfg: &FeConfig) -> bool {
    cfg.method == ContactMethod::Mixed && !methods::handles(cfg) && cfg.coefficients().is_ok()
}

/// Whether the run takes the frictional engine. A law with μ_f = 0 or s = 0 is the
/// frictionless problem, which the frictionless engine solves: the "μ_f = 0 gives the
/// frictionless numbers bit for bit" rule of SPEC §2.5 holds by construction — except Nitsche
/// with Θ ≠ 0, whose frictional form at μ_f = 0 is the full-vector frictionless Nitsche (σ_t = 0
/// imposed weakly with its Θ term, SPEC §2.5), not `none`'s: any Coulomb/Tresca law takes
/// the frictional engine there.
fn frictional(cfg: &FeConfig) -> bool {
    let full_vector = matches!(cfg.method, ContactMethod::Nitsche { theta, .. } if theta != 0.0);
    match cfg.friction {
        FrictionLaw::None => false,
        FrictionLaw::Coulomb { coefficient } => coefficient != 0.0 || full_vector,
        FrictionLaw::Tresca { threshold } => threshold != 0.0 || full_vector,
    }
}

/// One run of the engine between its setup and its outcome: the shared operators, the run's own
/// workspace, observer and counters. A step is split around its one linear solve —
/// [`Stepper::prepare`] writes the right-hand side into the member's column y of the group's
/// block, the solve replaces it by A⁻¹y, [`Stepper::contact`], [`Stepper::accelerate`] and
/// [`Stepper::end_step`] do the contact and the updates — so runs sharing A can make their
/// solves together ([`lockstep`]), and also their other reads of shared operators: u^{n+1} =
/// y + cτ²Zλ and the products with M and K. A run alone is a group of one.
struct Stepper<'a> {
    cfg: &'a FeConfig,
    opts: &'a RunOptions,
    geo: Arc<Geometry>,
    fac: Arc<Factored>,
    refmap: Option<RefMap>,
    metrics: Metrics,
    start: Instant,
    loop_start: Instant,
    // The scheme: p^n = u + τv + c₁τ²a, γ, cτ²; the θ-midpoint (hybrid) has its own update.
    tau: f64,
    c1: f64,
    gamma: f64,
    c_tau2: f64,
    hybrid: bool,
    /// f = −gravity (downward acceleration), F = M f e_d its load.
    fall: f64,
    force_vec: Vec<f64>,
    vertical_mass: f64,
    energy_scale: Option<f64>,
    /// Gap of each contact dof, and the Γ_C node nearest the plane (disc/ball).
    gaps: Vec<f64>,
    lowest: Option<usize>,
    // State and workspace (module header: M u, M v, M a carried along).
    u: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    mu: Vec<f64>,
    mv: Vec<f64>,
    ma: Vec<f64>,
    pred: Vec<f64>,
    /// K u^n (hybrid and Nitsche/penalty: the midpoint's right-hand side and the energy's
    /// uᵀKu), made by the group with K read once for all members; empty otherwise.
    ku: Vec<f64>,
    /// vᵀMv and uᵀMa of the state just made, summed by the pass that made it (Newmark/θ's
    /// [`Stepper::end_step`]) so the observation does not stream the vectors again; taken by
    /// [`Stepper::observe`].
    sums: Option<(f64, f64)>,
    tmp: Vec<f64>,
    err: Vec<f64>,
    q: Vec<f64>,
    lambda: Vec<f64>,
    lcp: Lcp,
    newton_work: NewtonWork,
    /// Friction with Nitsche/penalty (SPEC §2.5): u_t^n, the previous forces, the tally.
    friction: Option<FrictionState>,
    /// Newton's kinks: the gaps (Newmark/θ), or shifted per step (hybrid).
    kink: Vec<f64>,
    newton_max: usize,
    iterations: i64,
    work: StepWork,
    record: Option<(Vec<Option<usize>>, ReferenceData)>,
    obs: Observer,
    observe_timer: SampledTimer,
    /// Centre of mass against free fall until the first contact (scenes with gravity).
    fall_error: f64,
    touched: bool,
    done: usize,
    /// Mixed with friction: the frictional contact problem in place of the LCP, and the
    /// friction observables. `lambda` then holds the normal forces, then the tangential ones
    /// (Z's column order, [`FrictionFactor`]).
    fric: Option<Box<FrictionStep>>,
}

/// A frictional mixed run's contact workspace and tally (SPEC §2.5, §1.8).
struct FrictionStep {
    solver: FrictionalContact,
    law: FrictionLaw,
    /// Tresca's node weights w_i = ∫_ΓC φ_i.
    weights: Vec<f64>,
    /// The free gaps and slip increments of the step, and the forces (node-major
    /// [f_n, f_t…], the solver's warm start).
    q_n: Vec<f64>,
    q_t: Vec<f64>,
    forces: Vec<f64>,
    /// u_t^n at the Γ_C nodes' tangential dofs, then Δu_t.
    ut_prev: Vec<f64>,
    du_t: Vec<f64>,
    tally: FrictionTally,
    /// The body's mean velocities 1ᵀMv/1ᵀM1 per axis from the carried M v.
    mean: MeanVelocity,
    /// The last mean velocities (e_1, e_2, e_d).
    mean_v: [f64; 3],
}

impl<'a> Stepper<'a> {
    /// The setup: operators and factor from the shared caches, the reference map, the workspace
    /// and the initial state. A run that cannot start is returned as its outcome.
    fn new(
        cfg: &'a FeConfig,
        opts: &'a RunOptions,
        ctx: &RunContext,
    ) -> Result<Stepper<'a>, Box<Outcome>> {
        let start = Instant::now();
        let mut metrics = Metrics {
            dofs: cfg.unknowns() as i64,
            // Known before anything can fail: a failed row still gets its energy tolerance.
            length_scale: Some(cfg.setup.geometry.length_scale()),
            ..Metrics::default()
        };
        let fail = |status, msg: String, metrics: Metrics| {
            Box::new(Outcome {
                status,
                message: Some(msg),
                metrics,
                series: Series::default(),
                reference: None,
            })
        };
        let (c1, c, gamma) = match cfg.coefficients() {
            Ok(x) => x,
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
        };
        let tau = cfg.dt;
        let c_tau2 = c * tau * tau;
        let (geo, _) = GEOMETRIES.get(geometry_key(&cfg.setup), || build_geometry(&cfg.setup));
        let geo = match geo {
            Ok(g) => g,
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
        };
        // Checked outside the shared caches: an entry is never left half built.
        if let Some((status, msg)) = opts.setup_stop(start, "the mesh and operators") {
            return Err(fail(status, msg, metrics));
        }
        let (fac, hit) = FACTORS.get(factor_key(&geo, cfg, c_tau2), || factor(&geo, cfg, c_tau2));
        let fac = match fac {
            Ok(f) => f,
            Err(e) => return Err(fail(factor_failure(&e), e, metrics)),
        };
        // CG factors nothing: no factorisation made, none reused (its matrix and condensation
        // columns are still shared through the cache).
        let factored = fac.chol.is_factored();
        metrics.factorizations = i64::from(!hit && factored);
        metrics.factor_cache_hits = factored.then_some(i64::from(hit));
        metrics.mass_total = Some(fac.mass_total);
        if let Some((status, msg)) = opts.setup_stop(start, "the factorisation") {
            return Err(fail(status, msg, metrics));
        }
        let refmap = match ctx.reference.as_ref().map(|r| ref_map(&geo, cfg, r)) {
            Some(Err(e)) => return Err(fail(Status::Invalid, e, metrics)),
            Some(Ok(m)) => Some(m),
            None => None,
        };

        let g = &*geo;
        let n = g.dofs.n_free();
        let nit = fac.nitsche.as_ref();
        // Contact unknowns: the Γ_C nodes' vertical dofs (mixed) or Nitsche's points.
        let nc = nit.map_or(g.contact.len(), NitscheOps::unknowns);
        metrics.contact_dofs = Some(nc as i64);
        // Gap of each contact dof: its height above the plane (ball) or the run's gap (box).
        let base_gap = if g.gap_in_geometry {
            0.0
        } else {
            cfg.setup.gap
        };
        let gaps: Vec<f64> = g.contact_height.iter().map(|h| h + base_gap).collect();

        // Workspace: every vector of the time loop, allocated once. M u, M v and M a are
        // carried along the recursions of u, v, a, so a step costs one product with M (M a^{n+1})
        // besides the solve: M p^n = Mu + τ Mv + c₁τ² Ma, and the energy needs no product at
        // all, uᵀKu = uᵀ(F + Bᵀλ − M a) by the equation at t^{n+1}.
        let mut v = vec![0.0; n];
        let mut a = vec![0.0; n];
        let mut mv = vec![0.0; n];
        let mut ma = vec![0.0; n];
        let lcp = Lcp::new(
            g.contact.len(),
            if nit.is_some() {
                vec![0.0; g.contact.len().pow(2)]
            } else {
                fac.h.clone()
            },
        );
        let newton_work = match nit {
            Some(o) if o.friction.is_some() => NewtonWork::frictional(nc, o.per_point()),
            _ => NewtonWork::new(nit.map_or(0, NitscheOps::len)),
        };
        let kink: Vec<f64> = nit.map_or(Vec::new(), |o| o.gap.clone());
        let work: StepWork = fac.chol.work();
        for &r in &g.vertical {
            v[r] = cfg.setup.v0;
        }
        for &r in &g.tangential {
            v[r] = cfg.setup.v0_tangential;
        }
        if let Some((delta, seed)) = cfg.perturbation {
            let mut rng = fastrand::Rng::with_seed(seed);
            for x in v.iter_mut() {
                *x *= 1.0 + delta * (2.0 * rng.f64() - 1.0);
            }
        }
        fac.m.matvec_into(&v, &mut mv);
        let friction = match nit {
            Some(o) if o.friction.is_some() => {
                // f̄_t's weight of f_t^{n+1}: Newmark's γ, the θ-scheme's θ.
                let mut f = FrictionState::new(
                    o,
                    cfg.friction,
                    mean_velocity(g, &fac.m),
                    gamma,
                    cfg.setup.h,
                );
                f.start(&mv);
                Some(f)
            }
            _ => None,
        };
        // Gravity (SPEC §1.3, [`gravity_load`]): F and a⁰ with M a⁰ = F on the dofs with
        // inertia (u⁰ = 0); M a⁰ is carried as `ma`. The bars have no load (F = 0).
        // The fall along e_d: on an incline (SPEC §1.8) the load's e_d part is −g cos α (cos 0 = 1:
        // the flat runs' numbers unchanged); free_fall_error compares the centre of mass with it.
        let fall = -cfg.setup.gravity * cfg.setup.incline.to_radians().cos();
        let (force_vec, vertical_mass, energy_scale) = match gravity_load(g, cfg, &fac.m) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(None) => (vec![0.0; n], 0.0, None),
            Ok(Some(load)) => {
                a.copy_from_slice(&load.a0);
                fac.m.matvec_into(&a, &mut ma);
                (load.force, load.vertical_mass, Some(load.energy_scale))
            }
        };
        // The reference lattice this run records, if it is one.
        let record = match reference_record(g, cfg, ctx) {
            Err(e) => return Err(fail(Status::Invalid, e, metrics)),
            Ok(r) => r,
        };
        if let Some((status, msg)) = opts.setup_stop(start, "the workspace") {
            return Err(fail(status, msg, metrics));
        }
        let lowest = lowest_contact(g);
        let fric = fac.friction.as_ref().map(|ff| {
            let d = g.mesh.dim();
            let m = g.contact.len();
            Box::new(FrictionStep {
                solver: FrictionalContact::new(m, d, ff.w.clone()),
                law: cfg.friction,
                weights: g
                    .contact_weight
                    .iter()
                    .map(|w| w * g.contact_measure)
                    .collect(),
                q_n: vec![0.0; m],
                q_t: vec![0.0; ff.tangential.len()],
                forces: vec![0.0; m * d],
                ut_prev: vec![0.0; ff.tangential.len()],
                du_t: vec![0.0; ff.tangential.len()],
                // f̄ = (1 − γ) fⁿ + γ f^{n+1}: Newmark's γ, the θ-scheme's θ.
                tally: FrictionTally::new(m, d, cfg.setup.h, gamma),
                mean: mean_velocity(g, &fac.m),
                mean_v: [0.0; 3],
            })
        });
        let hybrid = matches!(cfg.scheme, Scheme::Hybrid);
        let needs_ku = hybrid || nit.is_some();
        let mut obs = Observer::new(tau, opts.series_every, cfg.steps);
        if let Some(sc) = energy_scale {
            obs = obs.with_energy_scale(sc);
        }
        metrics.setup_time_s = Some(start.elapsed().as_secs_f64());
        Ok(Stepper {
            cfg,
            opts,
            refmap,
            metrics,
            start,
            loop_start: Instant::now(),
            tau,
            c1,
            gamma,
            c_tau2,
            hybrid,
            fall,
            force_vec,
            vertical_mass,
            energy_scale,
            gaps,
            lowest,
            u: vec![0.0; n],
            v,
            a,
            mu: vec![0.0; n],
            mv,
            ma,
            pred: vec![0.0; n],
            ku: vec![0.0; if needs_ku { n } else { 0 }],
            sums: None,
            tmp: vec![0.0; n],
            err: vec![0.0; n],
            q: vec![0.0; nc],
            // Frictional: the tangential forces after the normal ones (Z's columns).
            lambda: vec![0.0; nc * fac.friction.as_ref().map_or(1, |_| g.mesh.dim())],
            lcp,
            newton_work,
            friction,
            kink,
            newton_max: 0,
            iterations: 0,
            work,
            record,
            obs,
            observe_timer: SampledTimer::default(),
            fall_error: 0.0,
            touched: false,
            done: 0,
            fric,
            geo,
            fac,
        })
    }

    /// Observe step n with the current state (u, v) and contact forces λ (SPEC §1.3).
    fn observe(&mut self, step: usize) -> Result<(), Divergence> {
        let Stepper {
            geo,
            fac,
            refmap,
            tau,
            fall,
            force_vec,
            vertical_mass,
            gaps,
            lowest,
            u,
            v,
            mu,
            mv,
            ma,
            ku,
            sums,
            tmp,
            err,
            lambda,
            record,
            obs,
            fall_error,
            touched,
            fric,
            ..
        } = self;
        let (g, nit, tau, fall) = (&**geo, fac.nitsche.as_ref(), *tau, *fall);
        // E = ½vᵀMv + ½uᵀKu − Fᵀu with Mv carried and Ku = F + Bᵀλ − Ma (module header).
        // Nitsche: the equation involves K_Θ and the nonlinear term, so uᵀKu is taken from the
        // product K u the group made for the step ([`Stepper::k_pair`]). Without a load, Fᵀu
        // is 0 and not summed.
        let carried = sums.take();
        let kinetic: f64 = carried.map_or_else(|| dot(v, mv), |c| c.0);
        let fu: f64 = if fall != 0.0 { dot(u, force_vec) } else { 0.0 };
        let uku = if nit.is_some() {
            dot(u, ku)
        } else {
            let contact: f64 = g
                .contact
                .iter()
                .zip(lambda.iter())
                .map(|(&c, l)| l * u[c])
                .sum();
            let uma: f64 = carried.map_or_else(|| dot(u, ma), |c| c.1);
            match (fric.as_ref(), fac.friction.as_ref()) {
                // With friction Cᵀf has tangential rows too: uᵀKu = uᵀ(F + Cᵀf − Ma).
                (Some(_), Some(ff)) => {
                    let nc = g.contact.len();
                    let tangential: f64 = ff
                        .tangential
                        .iter()
                        .zip(&lambda[nc..])
                        .map(|(&c, l)| l * u[c])
                        .sum();
                    fu + (contact + tangential) - uma
                }
                _ => fu + contact - uma,
            }
        };
        let [kinetic, elastic, gravity] = [0.5 * kinetic, 0.5 * uku, -fu];
        let e = kinetic + elastic + gravity;
        // Penetration at the Γ_C nodes, (u_n − g)_+ with u_n = −u_d (SPEC §1.3 decisions): the
        // points where the mixed method enforces the constraint, and where Nitsche/penalty
        // are measured too (their quadrature points carry only a weak constraint).
        let penetration = g
            .contact
            .iter()
            .zip(gaps.iter())
            .fold(0.0f64, |m, (&c, gap)| m.max(-u[c] - gap));
        // Nitsche: E_Θ and the total force from u itself (SPEC §2.3); mixed: Σ λ.
        // Penalty: its potential is part of E^h (SPEC §2.4), and there is no E_Θ.
        let (e, theta_term, force) = match nit {
            Some(ops) => {
                let (pot, t, f) = ops.energy_terms_and_force(u);
                (e + pot, t, f)
            }
            // The normal forces (frictional runs hold the tangential ones after them).
            None => (e, None, lambda[..g.contact.len()].iter().sum()),
        };
        let mean = |x: &[f64]| -> f64 {
            g.contact
                .iter()
                .zip(&g.contact_weight)
                .map(|(&c, w)| w * x[c])
                .sum()
        };
        let uc = mean(u);
        if let (Some(fr), Some(ff)) = (fric.as_mut(), fac.friction.as_ref()) {
            // The body's mean velocities 1ᵀMv/1ᵀM1 per axis from the carried M v; the stop
            // time and E + W_f in the tally; the series' Σf_t along e_1, the Γ_C mean of v_1
            // and W_f (SPEC §5).
            fr.mean.means_into(mv, &mut fr.mean_v);
            fr.tally.energy(e);
            fr.tally.velocity(step as f64 * tau, fr.mean_v[0]);
            let t = ff.tangential.len() / g.contact.len();
            let v1: f64 = g
                .contact_weight
                .iter()
                .enumerate()
                .map(|(i, w)| w * v[ff.tangential[i * t]])
                .sum();
            obs.set_friction(fr.tally.total_tangential()[0], v1, fr.tally.work());
        }
        if fall != 0.0 && !*touched {
            if force > 0.0 {
                *touched = true;
            } else {
                let t = step as f64 * tau;
                let com: f64 = g.vertical.iter().map(|&r| mu[r]).sum::<f64>() / *vertical_mass;
                *fall_error = fall_error.max((com - 0.5 * fall * t * t).abs());
            }
        }
        if let Some((slots, data)) = record.as_mut()
            && step.is_multiple_of(data.time_stride)
        {
            data.u.extend(slots.iter().map(|s| s.map_or(0.0, |r| u[r])));
            data.force.push(force);
            data.energy.push(e);
            data.u_contact.push(uc);
        }
        let exact = refmap.as_ref().map(|rm| rm.compare(g, step, u, err, tmp));
        obs.observe(
            StepValues {
                step,
                t: step as f64 * tau,
                u_contact: uc,
                v_contact: mean(v),
                sigma_contact: -force,
                sigma_mid: None,
                energy: e,
                energy_theta: theta_term.map(|t| e + t),
                energy_kinetic: Some(kinetic),
                energy_elastic: Some(elastic),
                energy_gravity: (fall != 0.0).then_some(gravity),
                u_lowest: lowest.map(|c| u[c]),
                penetration: Some(penetration),
            },
            exact,
        )
    }

    /// The right-hand side of step n into `y` (the member's column of the group's block, solved
    /// in place with A).
    fn prepare(&mut self, y: &mut [f64]) {
        let n = y.len();
        let (tau, c_tau2) = (self.tau, self.c_tau2);
        if self.hybrid {
            // Midpoint rule: (M + τ²/4 K_Θ) u^{n+1} = M(u + τv) − τ²/4 K_Θ u + τ²/2 F − τ²/2 N_Φ
            // (fe_nitsche header), K_Θ u = K u − Θ Σ w γ s (s·u); K u is the group's product.
            let kt: &[f64] = match self.fac.nitsche.as_ref() {
                Some(ops) if ops.theta != 0.0 => {
                    let tmp = &mut self.tmp;
                    tmp.copy_from_slice(&self.ku);
                    for k in 0..ops.len() {
                        let f = ops.theta * ops.w[k] * ops.gamma[k] * ops.apply(&ops.s, k, &self.u);
                        for (&gd, &sk) in ops.dofs[k * ops.k..(k + 1) * ops.k]
                            .iter()
                            .zip(&ops.s[k * ops.k..(k + 1) * ops.k])
                        {
                            tmp[gd] -= f * sk;
                        }
                    }
                    tmp
                }
                _ => &self.ku,
            };
            let (mu, mv, f, kt) = (&self.mu[..n], &self.mv[..n], &self.force_vec[..n], &kt[..n]);
            for i in 0..n {
                y[i] = mu[i] + tau * mv[i] - c_tau2 * kt[i] + 2.0 * c_tau2 * f[i];
            }
        } else {
            // p^n and M p^n (the right-hand side) from the carried products. M p^n is
            // M u^{n+1} before the correction by a^{n+1}: kept in `mu`. Then + cτ²F. (Slices cut
            // to n: the loop runs without bounds checks.)
            let ct2 = self.c1 * tau * tau;
            let (u, v, a) = (&self.u[..n], &self.v[..n], &self.a[..n]);
            let (mv, ma) = (&self.mv[..n], &self.ma[..n]);
            let (pred, mu) = (&mut self.pred[..n], &mut self.mu[..n]);
            for i in 0..n {
                pred[i] = u[i] + tau * v[i] + ct2 * a[i];
                let mp = mu[i] + tau * mv[i] + ct2 * ma[i];
                y[i] = mp;
                mu[i] = mp;
            }
            if self.fall != 0.0 {
                for (yi, fi) in y.iter_mut().zip(&self.force_vec) {
                    *yi += c_tau2 * fi;
                }
            }
        }
    }

    /// Step n's contact problem once `y` = A⁻¹(right-hand side): the forces λ (upward) from
    /// the exact LCP (mixed) or Newton (Nitsche/penalty). u^{n+1} = y + cτ² Z λ is then made by
    /// the group ([`lockstep`]), which reads each column of Z once for all its members.
    fn contact(&mut self, step: usize, y: &[f64]) -> Result<(), Stop<String>> {
        let c_tau2 = self.c_tau2;
        let fac = &*self.fac;
        if let (Some(ops), Some(fr)) = (fac.nitsche.as_ref(), self.friction.as_mut()) {
            // x0 = P y (+ k u_t^n), then the frictional Newton (fe_nitsche header); λ holds the
            // previous step's forces, its warm start.
            if self.hybrid {
                return Err(Stop::Solver(
                    step,
                    "friction is not defined for the hybrid scheme".into(),
                ));
            }
            fr.start_step(ops, y, &self.u, &mut self.q);
            let it = newton_friction(
                ops,
                fr.law,
                &fac.h,
                c_tau2,
                &self.q,
                &mut self.lambda,
                &mut fr.slides,
                &mut self.newton_work,
            )
            .map_err(|e| Stop::Solver(step, e))?;
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        } else if let Some(ops) = fac.nitsche.as_ref() {
            // s0 = P y, then Newton for s and φ(s) (the upward forces, into λ).
            for (k, qk) in self.q.iter_mut().enumerate() {
                *qk = ops.apply(&ops.p, k, y);
            }
            if self.hybrid {
                // Kinks g − max(P̃ⁿ, 0) from u^n (fe_nitsche header).
                for (k, kk) in self.kink.iter_mut().enumerate() {
                    let pn = ops.apply(&ops.p, k, &self.u) - ops.gap[k];
                    *kk = ops.gap[k] - pn.max(0.0);
                }
            }
            let it = newton(
                ops,
                &fac.h,
                c_tau2,
                &self.q,
                &self.kink,
                &mut self.lambda,
                &mut self.newton_work,
            )
            .map_err(|e| Stop::Solver(step, e))?;
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        } else if let (Some(fr), Some(ff)) = (self.fric.as_mut(), fac.friction.as_ref()) {
            // q_n = y_d + gap, q_t = y_t − u_t^n (the contact-free step's slip increment);
            // u^{n+1} = y + cτ²Z f over the normal and tangential columns ([`lockstep`]).
            let g = &*self.geo;
            for ((qi, &ci), gi) in fr.q_n.iter_mut().zip(&g.contact).zip(&self.gaps) {
                *qi = y[ci] + gi;
            }
            for ((qt, up), &ct) in fr.q_t.iter_mut().zip(&mut fr.ut_prev).zip(&ff.tangential) {
                *up = self.u[ct];
                *qt = y[ct] - *up;
            }
            let it = fr
                .solver
                .solve(
                    &fr.law,
                    &fr.weights,
                    &fr.q_n,
                    &fr.q_t,
                    None,
                    &mut fr.forces,
                    LCP_MAX_ITER,
                    LCP_TOL,
                )
                .map_err(|e| Stop::Solver(step, e.to_string()))?;
            let (nc, d) = (g.contact.len(), g.mesh.dim());
            for i in 0..nc {
                self.lambda[i] = fr.forces[i * d];
                for c in 1..d {
                    self.lambda[nc + i * (d - 1) + c - 1] = fr.forces[i * d + c];
                }
            }
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        } else {
            let g = &*self.geo;
            for ((qi, &ci), gi) in self.q.iter_mut().zip(&g.contact).zip(&self.gaps) {
                *qi = y[ci] + gi;
            }
            let it = self
                .lcp
                .solve(&self.q, &mut self.lambda, LCP_MAX_ITER, LCP_TOL)
                .map_err(|e| Stop::Solver(step, e.to_string()))?;
            self.newton_max = self.newton_max.max(it);
            self.iterations += it as i64;
        }
        Ok(())
    }

    /// With `y` = u^{n+1}: the acceleration a^{n+1} = (u^{n+1} − p^n)/(cτ²) into `tmp`
    /// (Newmark/θ), or v^{n+1} = 2(u^{n+1} − u^n)/τ − v^n (hybrid); then u ← u^{n+1}, in the
    /// same pass. The products with M (and K) that follow are the group's
    /// ([`Stepper::mass_pairs`], [`Stepper::k_pair`]).
    fn accelerate(&mut self, y: &[f64]) {
        let (tau, c_tau2) = (self.tau, self.c_tau2);
        let n = y.len();
        let u = &mut self.u[..n];
        if self.hybrid {
            let v = &mut self.v[..n];
            for i in 0..n {
                v[i] = 2.0 * (y[i] - u[i]) / tau - v[i];
                u[i] = y[i];
            }
        } else {
            let (t, p) = (&mut self.tmp[..n], &self.pred[..n]);
            for i in 0..n {
                t[i] = (y[i] - p[i]) / c_tau2;
                u[i] = y[i];
            }
        }
    }

    /// The products with M of this step, as (x, M x) pairs: M a^{n+1} into `pred` (Newmark/θ),
    /// or M u and M v (hybrid, whose u and v are not carried through recursions).
    fn mass_pairs(&mut self) -> [Option<(&[f64], &mut [f64])>; 2] {
        if self.hybrid {
            [
                Some((self.u.as_slice(), self.mu.as_mut_slice())),
                Some((self.v.as_slice(), self.mv.as_mut_slice())),
            ]
        } else {
            [Some((self.tmp.as_slice(), self.pred.as_mut_slice())), None]
        }
    }

    /// The product K u with the current u, as an (x, K x) pair, for the runs that need it
    /// (hybrid: the next right-hand side; Nitsche/penalty: the energy's uᵀKu); one product
    /// serves both, where each used to make its own.
    fn k_pair(&mut self) -> Option<(&[f64], &mut [f64])> {
        (!self.ku.is_empty()).then_some((self.u.as_slice(), self.ku.as_mut_slice()))
    }

    /// The end of step n after the products with M: v, M v, M u and a (Newmark/θ), the
    /// observation, the clock. The same pass sums vᵀMv and uᵀMa for the observation (in the
    /// order of [`dot`]: the same numbers).
    fn end_step(&mut self, step: usize) -> Result<(), Stop<String>> {
        if !self.hybrid {
            let (tau, gamma, c_tau2) = (self.tau, self.gamma, self.c_tau2);
            let n = self.u.len();
            let (a, an, ma, man) = (&self.a[..n], &self.tmp[..n], &self.ma[..n], &self.pred[..n]);
            let (v, mv, mu) = (&mut self.v[..n], &mut self.mv[..n], &mut self.mu[..n]);
            let u = &self.u[..n];
            let (mut kinetic, mut uma) = (-0.0, -0.0);
            for i in 0..n {
                v[i] += tau * ((1.0 - gamma) * a[i] + gamma * an[i]);
                mv[i] += tau * ((1.0 - gamma) * ma[i] + gamma * man[i]);
                mu[i] += c_tau2 * man[i];
                kinetic += v[i] * mv[i];
                uma += u[i] * man[i];
            }
            self.sums = Some((kinetic, uma));
            std::mem::swap(&mut self.a, &mut self.tmp);
            std::mem::swap(&mut self.ma, &mut self.pred);
        }
        if let (Some(fr), Some(ff)) = (self.fric.as_mut(), self.fac.friction.as_ref()) {
            for ((du, up), &ct) in fr.du_t.iter_mut().zip(&fr.ut_prev).zip(&ff.tangential) {
                *du = self.u[ct] - up;
            }
            fr.tally.step(&fr.forces, &fr.du_t);
        }
        if let (Some(fr), Some(ops)) = (self.friction.as_mut(), self.fac.nitsche.as_ref()) {
            let t = step as f64 * self.tau;
            let (ft, vt, wf) = fr.after_step(ops, &self.u, &self.v, &self.mv, &self.lambda, t);
            self.obs.set_friction(ft, vt, wf);
        }
        let e_prev = self.obs.last_energy();
        let mut timer = self.observe_timer;
        let r = timer.time(step, || self.observe(step));
        self.observe_timer = timer;
        r.map_err(Stop::Diverged)?;
        if let Some(fr) = self.friction.as_mut() {
            fr.balance(e_prev, self.obs.last_energy());
        }
        self.done = step;
        self.opts.step_stop(step, CLOCK_EVERY, self.start)
    }

    /// The outcome of the run, however its loop ended.
    fn finish(mut self, stop: Result<(), Stop<String>>) -> Outcome {
        let cfg = self.cfg;
        let metrics = &mut self.metrics;
        metrics.steps = self.done as i64;
        metrics.iterations = self.iterations;
        metrics.iterations_max_step = Some(self.newton_max as i64);
        if !self.fac.chol.is_factored() {
            metrics.solver_iterations = Some(self.work.iterations_total() as i64);
            metrics.solver_iterations_max_step = Some(self.work.iterations_max() as i64);
        }
        metrics.stepping_time_s = Some(self.loop_start.elapsed().as_secs_f64());
        metrics.observe_time_s = self.observe_timer.estimate_s();
        let (status, message) = Stop::status(stop, self.tau, cfg.steps, self.start, metrics);
        self.obs.finish(metrics, status == Status::Ok);
        metrics.free_fall_error = (self.fall != 0.0).then_some(self.fall_error);
        // The observer's pressure columns are the total force here; there is no midpoint
        // pressure.
        metrics.err_force_l2 = metrics.err_sigma_l2.take();
        metrics.err_sigma_mid_l2 = None;
        metrics.contact_toggles = Some(metrics.contact_switches);
        metrics.energy_scale = self.energy_scale.or(metrics.energy_initial);
        if let Some(fr) = self.fric.as_ref() {
            // SPEC §5: the e_1 component in 2D, the tangential norm in 3D.
            let vt = fr.mean.tangential(&fr.mean_v);
            let scale = metrics.energy_scale.unwrap_or(1.0);
            fr.tally.finish(metrics, scale, vt, fr.mean_v[2]);
        }
        if let Some(fr) = &self.friction {
            let scale = metrics.energy_scale.filter(|s| *s != 0.0).unwrap_or(1.0);
            fr.finish(metrics, scale);
        }
        let reference = match self.record {
            Some((_, data)) if status == Status::Ok => Some(data),
            _ => None,
        };
        Outcome {
            status,
            message,
            metrics: self.metrics,
            series: std::mem::take(&mut self.obs.series),
            reference,
        }
    }
}

/// xᵀAx with `tmp` as scratch.
fn quad(a: &SymMatrix, x: &[f64], tmp: &mut [f64]) -> f64 {
    a.matvec_into(x, tmp);
    dot(x, tmp)
}

/// xᵀy summed in order from −0.0 (the iterator sum's arithmetic, which the fused passes of
/// the time loop repeat).
fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(p, q)| p * q).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::FeGeometry;

    fn disc(h: f64) -> FeSetup {
        let (n_t, n_r) = BallMesh::counts_for_size(20.0, h);
        FeSetup {
            scene: "disc2d",
            dim: 2,
            geometry: FeGeometry::Ball {
                dim: 2,
                degree: 2,
                radius: 20.0,
                centre_height: 21.0,
                n_t,
                n_r,
            },
            h,
            density: 1.0,
            lame_lambda: 1.0,
            lame_mu: 1.0,
            gap: 1.0,
            gravity: 0.1,
            load: LoadModel::Body,
            v0: 0.0,
            v0_tangential: 0.0,
            incline: 0.0,
        }
    }

    /// Issue 22: for nested meshes the interpolating path equals the node-for-node one to
    /// 1e-12. The disc against a reference on its own mesh: every run dof takes its own
    /// reference dof with weight 1 and every other weight vanishes, to round-off of the
    /// inverse map (Newton to 1e-15 on elements of size ~1, weights O(1)).
    #[test]
    fn interpolating_a_reference_on_the_same_mesh_is_the_identity() {
        let g = build_geometry(&disc(4.0)).unwrap();
        let plain = PlainMesh::from_mesh(g.mesh.mesh());
        let ip = interpolation(&g, &plain).unwrap();
        for i in 0..g.dofs.n_free() {
            for k in ip.start[i]..ip.start[i + 1] {
                let want = if ip.offset[k] == i { 1.0 } else { 0.0 };
                // A node shared by several elements appears once: its weight is 1.
                assert!(
                    (ip.weight[k] - want).abs() < 1e-12,
                    "dof {i}: weight {} at offset {}",
                    ip.weight[k],
                    ip.offset[k]
                );
            }
            let total: f64 = (ip.start[i]..ip.start[i + 1]).map(|k| ip.weight[k]).sum();
            assert!((total - 1.0).abs() < 1e-12, "partition of unity at dof {i}");
        }
    }

    /// A coarser disc in finer ones: each run node gets weights summing to 1 (the shape
    /// functions' partition of unity), and a smooth field given at the reference nodes is
    /// evaluated at the run's nodes with the error of Q2 interpolation, O(h_ref³): halving
    /// h_ref divides it by ~8 (measured 2.84e-4 → 3.06e-5, ×9.3; asserted ≥ 6), and it is
    /// small in absolute terms (f = sin(x/7)·cos(y/5), third derivatives ≤ 1/125).
    #[test]
    fn a_coarse_disc_interpolates_finer_ones_at_the_q2_rate() {
        let f = |x: [f64; 3]| (x[0] / 7.0).sin() * (x[1] / 5.0).cos();
        // h = 4: (n_t, n_r) = (8, 3), not nested in (16, 5) or (32, 10).
        let coarse = build_geometry(&disc(4.0)).unwrap();
        let error = |h_ref: f64| {
            let fine = build_geometry(&disc(h_ref)).unwrap();
            let plain = PlainMesh::from_mesh(fine.mesh.mesh());
            let ip = interpolation(&coarse, &plain).unwrap();
            let mut worst = 0.0f64;
            for (i, &gd) in coarse.dofs.free.iter().enumerate() {
                let total: f64 = (ip.start[i]..ip.start[i + 1]).map(|k| ip.weight[k]).sum();
                assert!((total - 1.0).abs() < 1e-12);
                let v: f64 = (ip.start[i]..ip.start[i + 1])
                    .map(|k| ip.weight[k] * f(plain.coords[ip.offset[k] / 2]))
                    .sum();
                worst = worst.max((v - f(coarse.mesh.mesh().coord(gd / 2))).abs());
            }
            worst
        };
        let (e2, e1) = (error(2.0), error(1.0));
        assert!(
            e1 < e2 / 6.0 && e1 < 1e-4,
            "max errors {e2:e} (h = 2), {e1:e} (h = 1)"
        );
    }
}
