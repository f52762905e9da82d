//! The operators of one geometry and material shared by every run on it: the mesh (box, mapped
//! disc/ball, Gmsh), its dofs and pattern, K, the Gram matrices of the error norms, Γ_C's
//! contact dofs, heights, weights and Nitsche points (contract §1.2, §1.6).

use std::sync::{Arc, OnceLock};

use super::bodies::{BlocksParts, TwoBodies, blocks_parts};
use super::cache::Cache;
use super::mesh_bodies::{face_node_weights, mesh_bodies_parts};
use super::rows::Rows;
use crate::run::friction_tally::MeanVelocity;
use crate::scene::{FeGeometry, FeSetup};
use crate::space::fe::mesh::mesh_layers;
use crate::space::fe::nitsche::{
    ContactPoint, box_contact_faces, contact_points, face_contact_points, gmsh_contact_faces,
};
use crate::space::fe::{
    BallMesh, BodiesMesh, BoxMesh, DofMap, ElementOp, GmshMesh, Mesh, Pattern, SymMatrix, assemble,
    fe_pattern,
};
use crate::space::linalg::{CholeskyOptions, FactorKind, LinalgError, Ordering, SymbolicCholesky};

/// The mesh of a geometry: the bars' box, the mapped disc/ball, or a Gmsh mesh with its mass
/// layers (contract §1.6).
#[derive(Debug)]
pub(super) enum FeMesh {
    Box(BoxMesh),
    Ball(BallMesh),
    Gmsh {
        mesh: Arc<GmshMesh>,
        layers: Vec<usize>,
    },
    /// Several bodies in one numbering (contract §1.10), each element's layer within its body.
    Bodies {
        mesh: BodiesMesh,
        layers: Vec<usize>,
    },
}

impl FeMesh {
    pub(super) fn mesh(&self) -> &dyn Mesh {
        match self {
            FeMesh::Box(m) => m,
            FeMesh::Ball(m) => m,
            FeMesh::Gmsh { mesh, .. } => &**mesh,
            FeMesh::Bodies { mesh, .. } => mesh,
        }
    }
    pub(super) fn dim(&self) -> usize {
        self.mesh().dim()
    }
    /// Mass layer of element e (contract §2.2; layer 0 touches Γ_C).
    pub(super) fn element_layer(&self, e: usize) -> usize {
        match self {
            FeMesh::Box(m) => m.element_layer(e),
            FeMesh::Ball(m) => m.layers[e],
            FeMesh::Gmsh { layers, .. } | FeMesh::Bodies { layers, .. } => layers[e],
        }
    }
    pub(super) fn num_layers(&self) -> usize {
        match self {
            FeMesh::Box(m) => m.num_layers(),
            FeMesh::Ball(m) => m.layers.iter().max().map_or(0, |l| l + 1),
            FeMesh::Gmsh { layers, .. } | FeMesh::Bodies { layers, .. } => {
                layers.iter().max().map_or(0, |l| l + 1)
            }
        }
    }
    /// The bars' box (reference lattices are defined on it only).
    pub(super) fn as_box(&self) -> Option<&BoxMesh> {
        match self {
            FeMesh::Box(m) => Some(m),
            FeMesh::Ball(_) | FeMesh::Gmsh { .. } | FeMesh::Bodies { .. } => None,
        }
    }
}

/// The operators of one geometry and material, shared by every run on it.
#[derive(Debug)]
pub(super) struct Geometry {
    pub(super) mesh: FeMesh,
    pub(super) dofs: DofMap,
    pub(super) pattern: Arc<Pattern>,
    /// The symbolic Cholesky analysis with these choices, made on first use: a `cg` run never
    /// asks for it (at 3·10⁵ dofs in 3D its supernodal structure alone is hundreds of MB).
    pub(super) cholesky: CholeskyOptions,
    pub(super) symbolic: OnceLock<Result<Arc<SymbolicCholesky>, LinalgError>>,
    pub(super) k: SymMatrix,
    /// Unweighted Gram matrix (ρ = 1) and ∫∇u:∇v, for the error norms.
    pub(super) gram: SymMatrix,
    pub(super) grad: SymMatrix,
    /// Reduced index of the vertical dof of each Γ_C node (two bodies: of A's Γ^a node of each
    /// row), the dof the observables read (u_contact is their mean).
    pub(super) contact: Vec<usize>,
    /// The contact rows B_i (one per Γ_C node, [`Rows`]): what the condensed solve, the
    /// energies and the methods take. One body: e_c for c in `contact`.
    pub(super) rows: Rows,
    /// Height x_d of each Γ_C node in the reference configuration, measured from the bottom
    /// face (box: 0, the run's `gap` is added) or from the rigid plane (ball: the gap is in it).
    pub(super) contact_height: Vec<f64>,
    /// Whether the gap is already in `contact_height` (ball) or is the run's `gap` (box).
    pub(super) gap_in_geometry: bool,
    /// Whether each node is on Γ_C (all nodes, clamped ones included).
    pub(super) contact_node: Vec<bool>,
    /// Nitsche's quadrature points of Γ_C with γ0 = 1 (their `gamma` is h_K), dofs reduced; or
    /// why the mesh has none (a Gmsh `contact` group without boundary faces: `mixed` still runs).
    pub(super) points: Result<Vec<ContactPoint>, String>,
    /// Trapezoidal weights of the Γ_C nodes (sum 1): the mean of a nodal field over Γ_C.
    pub(super) contact_weight: Vec<f64>,
    /// |Γ_C|, the measure the weights were normalised by: contact_weight_i·|Γ_C| = ∫_ΓC φ_i,
    /// Tresca's node weight w_i (contract §2.5).
    pub(super) contact_measure: f64,
    /// Reduced dofs that belong to a Γ_C node (all components).
    pub(super) on_contact_node: Vec<bool>,
    /// Reduced indices of the vertical component.
    pub(super) vertical: Vec<usize>,
    /// Reduced indices of the e_1 component (the tangential direction of `velocity_tangential`,
    /// contract §1.8).
    pub(super) tangential: Vec<usize>,
    /// The second body and the pair's data (contract §1.10); None for one body.
    pub(super) bodies: Option<TwoBodies>,
}

impl Geometry {
    /// The symbolic analysis of the pattern (made once, by the first direct run).
    pub(super) fn symbolic(&self) -> Result<Arc<SymbolicCholesky>, LinalgError> {
        self.symbolic
            .get_or_init(|| SymbolicCholesky::with_options(&self.pattern, &self.cholesky))
            .clone()
    }
}

pub(super) static GEOMETRIES: Cache<Geometry> = Cache::new();

/// The factor kind of a 2D step matrix: column by column (simplicial) at every size.
///
/// Why: faer's simplicial solve treats each right-hand side with the same scalar operations
/// whatever the number of columns, so a lockstep member ([`super::lockstep`]) equals its run alone bit
/// for bit through faer's own blocked solve; a supernodal factor needs the engine's
/// column-by-column sweep ([`crate::space::linalg::Cholesky::solve_columns_in_place`]), which in
/// 2D (thousands of supernodes of a few columns each) costs 1.4–1.7× faer's blocked solve. And
/// the supernodal factor buys nothing here. `cargo bench --bench solves` (faer 0.24, AMD, ms for
/// 8 right-hand sides: one at a time / faer's block / the column sweep, medians of 15
/// interleaved): 21 120 dofs simplicial 13.2 / 6.2 / 6.0, supernodal 23.3 / 8.5 / 13.9;
/// 83 200 dofs simplicial 60.5 / 26.6 / 26.8, supernodal 117.7 / 33.6 / 46.1. (An earlier
/// series on a quiet machine had the supernodal factor ahead at 83 200 dofs, 6.4 against
/// 7.6 ms for one solve: docs/performance.md.)
pub(super) const FACTOR_KIND_2D: FactorKind = FactorKind::Simplicial;

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

/// AMD ordering, simplicial in 2D and supernodal in 3D: the meshes without a lattice to
/// dissect (the mapped disc/ball, Gmsh files, the blocks; the bars' measurements,
/// [`cholesky_options`]).
fn amd_options(d: usize) -> CholeskyOptions {
    CholeskyOptions {
        ordering: Ordering::Amd,
        kind: if d == 2 {
            FACTOR_KIND_2D
        } else {
            FactorKind::Supernodal
        },
    }
}

pub(super) fn build_geometry(s: &FeSetup) -> Result<Geometry, String> {
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
            path,
            content_hash,
            bodies,
            ..
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
            match bodies {
                Some(keys) => build_bodies(s, mesh_bodies_parts(s, &mesh, keys)?),
                None => build_gmsh(s, mesh),
            }
        }
        FeGeometry::Blocks(b) => build_bodies(s, blocks_parts(s, b)?),
    }
}

/// Two bodies (contract §1.10, [`super::bodies`]; the blocks or a two-body file): A's Γ^a rows
/// paired node to node with B's Γ^b, the run's gap in the rows; Nitsche's points of both sides
/// (the blocks') in the pair's data, their dofs reduced here.
pub(super) fn build_bodies(s: &FeSetup, mut p: BlocksParts) -> Result<Geometry, String> {
    let sides = std::mem::take(&mut p.two.nitsche_points);
    p.two.nitsche_points = sides.map(|x| reduce_points(x, &p.dofs));
    let d = s.dim;
    let opts = amd_options(d);
    let one = |_: usize| 1.0;
    let gram = assemble(
        &p.mesh,
        &p.dofs,
        &p.pattern,
        ElementOp::Mass { rho: 1.0 },
        &one,
    );
    let grad = assemble(&p.mesh, &p.dofs, &p.pattern, ElementOp::GradGrad, &one);
    let n = p.dofs.n_free();
    let on_contact_node = (0..n).map(|r| p.contact_node[p.dofs.free[r] / d]).collect();
    let vertical = (0..n).filter(|&r| p.dofs.free[r] % d == d - 1).collect();
    let tangential = (0..n)
        .filter(|&r| p.dofs.free[r].is_multiple_of(d))
        .collect();
    Ok(Geometry {
        mesh: FeMesh::Bodies {
            mesh: p.mesh,
            layers: p.layers,
        },
        dofs: p.dofs,
        pattern: p.pattern,
        cholesky: opts,
        symbolic: OnceLock::new(),
        k: p.k,
        gram,
        grad,
        contact_height: p.contact_height,
        contact: p.contact,
        rows: p.rows,
        gap_in_geometry: false,
        contact_node: p.contact_node,
        points: Ok(p.points),
        contact_weight: p.contact_weight,
        contact_measure: p.contact_measure,
        on_contact_node,
        vertical,
        tangential,
        bodies: Some(p.two),
    })
}

/// A Gmsh mesh (contract §1.6): the `clamped` group's nodes fixed (every component), contact on the
/// vertical dofs of the other `contact` nodes, each with its height above the lowest of them
/// (the run's `gap` is added: the plane is x_d = lowest − gap), Γ_C's mean weighting each node
/// by its faces' measures, mass layers by topology ([`mesh_layers`]).
pub(super) fn build_gmsh(s: &FeSetup, mesh: Arc<GmshMesh>) -> Result<Geometry, String> {
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
    let opts = amd_options(d);
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
    let node_weight = face_node_weights(&mesh, &group.elements);
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
        rows: Rows::unit(&contact),
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
        bodies: None,
    })
}

/// The stiffness, Gram and grad-grad matrices of a mesh on its free dofs.
pub(super) fn operators(
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
/// their heights above the plane (contract §1.3: g(x) = x_d, u_n = −u_d).
pub(super) fn build_ball(s: &FeSetup, mesh: BallMesh) -> Result<Geometry, String> {
    let d = mesh.dim;
    let dofs = DofMap::all(mesh.coords.len() * d);
    let pattern = fe_pattern(&mesh, &dofs);
    // AMD: the mapped mesh has no lattice to dissect; simplicial in 2D, supernodal in 3D (the
    // bars' measurements, `cholesky_options`).
    let opts = amd_options(d);
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
        rows: Rows::unit(&contact),
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
        bodies: None,
    })
}

pub(super) fn build_box(s: &FeSetup, extent: &[f64], cells: &[usize]) -> Result<Geometry, String> {
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
        rows: Rows::unit(&contact),
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
        bodies: None,
    })
}

/// The points with their dofs as reduced indices (the run's unknowns). A clamped dof's value is
/// 0, so its coefficients are dropped: it keeps its slot (every point has the element's k
/// dofs, [`NitscheOps`]) with coefficient 0 on a free dof of the same element, which keeps
/// every rank-one update of [`factor_nitsche`] inside the FE pattern. A point whose element is
/// clamped entirely has u_n = σ_n = 0 for every u and is left out.
pub(super) fn reduce_points(points: Vec<ContactPoint>, dofs: &DofMap) -> Vec<ContactPoint> {
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

/// The Γ_C node nearest the plane, whose vertical dof gives `u_lowest` (the disc's and ball's
/// lowest point; a mesh body's lowest Γ_C node). The bars' bottom face is flat: none.
pub(super) fn lowest_contact(g: &Geometry) -> Option<usize> {
    if g.mesh.as_box().is_some() {
        return None;
    }
    g.contact
        .iter()
        .zip(&g.contact_height)
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(&c, _)| c)
}

/// The body's mean velocities per axis (contract §5; [`MeanVelocity`]) with the run's mass matrix:
/// a reduced dof's axis is its global dof's component.
/// Two bodies: A's (the sliding body of contract §1.8's stop time), B's dofs counted on no axis
/// (axis d is none of e_1, e_2, e_d) — with B clamped or at rest, A's mean is the slip's.
pub(super) fn mean_velocity(g: &Geometry, m: &SymMatrix) -> MeanVelocity {
    let d = g.mesh.dim();
    match &g.bodies {
        None => MeanVelocity::new(d, m, |r| g.dofs.free[r] % d),
        Some(two) => MeanVelocity::new(d, m, |r| {
            if two.body[r] == 0 {
                g.dofs.free[r] % d
            } else {
                d
            }
        }),
    }
}

/// The reduced indices of the Γ_C nodes' tangential dofs, node-major (e_1, then e_2 in 3D).
/// Every Γ_C node's dofs are free (only the clamped face is removed, and it is not Γ_C), so
/// node i's component c sits d − 1 − c below its vertical one; checked against the DofMap.
pub(super) fn tangential_dofs(g: &Geometry) -> Result<Vec<usize>, String> {
    let d = g.mesh.dim();
    let mut out = Vec::with_capacity(g.contact.len() * (d - 1));
    for &cv in &g.contact {
        for c in 0..d - 1 {
            out.push(tangential_of(g, cv, c)?);
        }
    }
    Ok(out)
}

/// The reduced index of component c of the node whose vertical dof is `cv` (reduced).
fn tangential_of(g: &Geometry, cv: usize, c: usize) -> Result<usize, String> {
    let d = g.mesh.dim();
    let global = g.dofs.free[cv];
    let want = global - (d - 1 - c);
    match (cv.checked_sub(d - 1 - c), g.dofs.free_index(want)) {
        (Some(r), Some(f)) if r == f => Ok(r),
        _ => Err(format!(
            "friction: the tangential dof {c} of the Γ_C node with global vertical dof {global} is not free"
        )),
    }
}

/// The tangential rows of the contact rows, node-major (contract §2.5, §2.6; [`Rows::tangential`]):
/// one body's unit rows e_{i,c} (the dofs of [`tangential_dofs`], coefficient 1), two bodies'
/// e_{a,i,c} − e_{b,π(i),c} on the relative slip.
pub(super) fn tangential_rows(g: &Geometry) -> Result<Rows, String> {
    g.rows
        .tangential(g.mesh.dim() - 1, |cv, c| tangential_of(g, cv, c))
}
