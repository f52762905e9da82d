//! Gmsh MSH 4.1 meshes (ASCII or binary) read into the engine's mesh representation: the body of
//! the `mesh2d`/`mesh3d` scenes (SPEC §1.6, issue 22), validated before anything is run.
//!
//! Why here: every scene of the engine reaches assembly through the [`Mesh`] trait ("an element =
//! its node ids + its node coordinates"), so a Gmsh mesh is one more implementation of that trait
//! ([`GmshMesh`]), not a parallel mesh type.
//!
//! What is read (by [`super::msh`], the engine's own MSH 4.1 parser, which cannot panic and
//! checks every count against the bytes left before allocating):
//! - the nodes, numbered by increasing tag whatever order or block header the file has (a
//!   rewrite listing them otherwise is the same mesh, to the bit);
//! - the cells: the elements of the highest dimension present, one type per mesh among 3- and
//!   6-node triangles, 4- and 9-node quadrilaterals, 4- and 10-node tetrahedra, 8- and 27-node
//!   hexahedra ([`ElementKind`]);
//! - the physical groups by name (`contact` = Γ_C, required; `clamped`; any other), each with the
//!   entities it tags, its elements (boundary lines/faces, or cells) as node ids, and its nodes.
//!
//! Node order of a cell (the engine's contract, see [`ElementKind`]): triangles and tetrahedra
//! keep Gmsh's order (vertices, then edge midpoints); quadrilaterals and hexahedra are permuted
//! into the tensor order of [`super::element`] (local node a has index ⌊a/(p+1)^k⌋ mod (p+1)
//! along axis k), so the Q1/Q2 kernels apply unchanged.
//!
//! Validation (each failure a [`GmshError`] naming the file, the element/node/group and the
//! reason, on one line): a file that is not MSH 4.1 or not well formed (the section, the block
//! and why), a node tag given twice, a coordinate that is not finite, mixed cell types, no
//! cells, a missing `contact` group, a 2D mesh whose nodes do not share one z, unreferenced
//! nodes (not in any cell), inverted or degenerate cells — det J is evaluated at every
//! reference node of the cell and at its quadrature points ([`ElementKind::quadrature`]), then
//! certified positive over the whole cell by its Bernstein coefficients — and the whole-mesh
//! checks of [`super::check`]: cells listed twice, faces shared by more than two cells or by
//! two on one side (overlaps), neighbours not sharing their midside nodes, coincident distinct
//! nodes (a crack), and `contact`/`clamped` elements that are not boundary faces of the cells'
//! type. A 2D mesh whose cells are all clockwise in the (x, y) plane (a surface oriented
//! towards −z) is
//! reoriented rather than refused; a cell of the other orientation is then inverted.
//!
//! Also returned: `h` = the largest cell diameter (largest distance between two nodes of a
//! cell: for affine cells the longest edge) and the SHA-256 of the file's bytes (the run id
//! includes it, SPEC §1.6).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::SystemTime;

use sha2::{Digest, Sha256};

use super::element::{gauss_legendre, shape};
use super::mesh::Mesh;
use super::{check, msh};

/// The cell types of a Gmsh mesh the engine supports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ElementKind {
    /// 3-node triangle (P1).
    Tri3,
    /// 6-node triangle (P2): vertices, then the midpoints of edges 01, 12, 20.
    Tri6,
    /// 4-node quadrilateral (Q1), tensor order.
    Quad4,
    /// 9-node quadrilateral (Q2), tensor order.
    Quad9,
    /// 4-node tetrahedron (P1).
    Tet4,
    /// 10-node tetrahedron (P2): vertices, then edges 01, 12, 20, 30, 32, 31 (Gmsh's order).
    Tet10,
    /// 8-node hexahedron (Q1), tensor order.
    Hex8,
    /// 27-node hexahedron (Q2), tensor order.
    Hex27,
}

/// Edges of the P2 simplices in Gmsh's order (midpoint node 3 + k of a triangle, 4 + k of a
/// tetrahedron, lies on edge k).
pub(crate) const TRI_EDGES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];
pub(crate) const TET_EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
/// Gmsh's hexahedron edges (nodes 8–19 of Hex27) and faces (nodes 20–25).
const HEX_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (0, 3),
    (0, 4),
    (1, 2),
    (1, 5),
    (2, 3),
    (2, 6),
    (3, 7),
    (4, 5),
    (4, 7),
    (5, 6),
    (6, 7),
];
const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [0, 1, 5, 4],
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [4, 5, 6, 7],
];

impl ElementKind {
    /// The supported cell kind of a Gmsh element type id, if any.
    pub fn from_gmsh(t: i32) -> Option<ElementKind> {
        Some(match t {
            2 => ElementKind::Tri3,
            9 => ElementKind::Tri6,
            3 => ElementKind::Quad4,
            10 => ElementKind::Quad9,
            4 => ElementKind::Tet4,
            11 => ElementKind::Tet10,
            5 => ElementKind::Hex8,
            12 => ElementKind::Hex27,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Tri3 => "3-node triangle",
            ElementKind::Tri6 => "6-node triangle",
            ElementKind::Quad4 => "4-node quadrilateral",
            ElementKind::Quad9 => "9-node quadrilateral",
            ElementKind::Tet4 => "4-node tetrahedron",
            ElementKind::Tet10 => "10-node tetrahedron",
            ElementKind::Hex8 => "8-node hexahedron",
            ElementKind::Hex27 => "27-node hexahedron",
        }
    }

    pub fn dim(self) -> usize {
        match self {
            ElementKind::Tri3 | ElementKind::Tri6 | ElementKind::Quad4 | ElementKind::Quad9 => 2,
            _ => 3,
        }
    }

    /// Polynomial degree (1 or 2).
    pub fn degree(self) -> usize {
        match self {
            ElementKind::Tri3 | ElementKind::Quad4 | ElementKind::Tet4 | ElementKind::Hex8 => 1,
            _ => 2,
        }
    }

    pub fn is_simplex(self) -> bool {
        matches!(
            self,
            ElementKind::Tri3 | ElementKind::Tri6 | ElementKind::Tet4 | ElementKind::Tet10
        )
    }

    pub fn num_nodes(self) -> usize {
        match self {
            ElementKind::Tri3 => 3,
            ElementKind::Tri6 => 6,
            ElementKind::Quad4 => 4,
            ElementKind::Quad9 => 9,
            ElementKind::Tet4 => 4,
            ElementKind::Tet10 => 10,
            ElementKind::Hex8 => 8,
            ElementKind::Hex27 => 27,
        }
    }

    /// Reference coordinates of the nodes in Gmsh's local order: the unit simplex (vertices at 0
    /// and e_k) or [−1, 1]^d.
    fn gmsh_reference_nodes(self) -> Vec<[f64; 3]> {
        let mid = |a: [f64; 3], b: [f64; 3]| {
            [
                0.5 * (a[0] + b[0]),
                0.5 * (a[1] + b[1]),
                0.5 * (a[2] + b[2]),
            ]
        };
        let d = self.dim();
        if self.is_simplex() {
            let mut v = vec![[0.0; 3]];
            for k in 0..d {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                v.push(e);
            }
            if self.degree() == 2 {
                let edges: &[(usize, usize)] = if d == 2 { &TRI_EDGES } else { &TET_EDGES };
                let corners = v.clone();
                v.extend(edges.iter().map(|&(a, b)| mid(corners[a], corners[b])));
            }
            return v;
        }
        let sq = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
        let mut v: Vec<[f64; 3]> = Vec::new();
        if d == 2 {
            v.extend(sq.iter().map(|p| [p[0], p[1], 0.0]));
            if self.degree() == 2 {
                for k in 0..4 {
                    v.push(mid(v[k], v[(k + 1) % 4]));
                }
                v.push([0.0; 3]);
            }
        } else {
            for z in [-1.0, 1.0] {
                v.extend(sq.iter().map(|p| [p[0], p[1], z]));
            }
            if self.degree() == 2 {
                let c = v.clone();
                v.extend(HEX_EDGES.iter().map(|&(a, b)| mid(c[a], c[b])));
                for f in HEX_FACES {
                    let mut p = [0.0; 3];
                    for a in f {
                        for k in 0..3 {
                            p[k] += 0.25 * c[a][k];
                        }
                    }
                    v.push(p);
                }
                v.push([0.0; 3]);
            }
        }
        v
    }

    /// `perm[a]` = Gmsh's local index of the engine's local node a (identity for simplices,
    /// Gmsh → tensor order for quadrilaterals and hexahedra).
    pub fn gmsh_local_order(self) -> Vec<usize> {
        let g = self.gmsh_reference_nodes();
        if self.is_simplex() {
            return (0..g.len()).collect();
        }
        let p = self.degree();
        let mut perm = vec![usize::MAX; g.len()];
        for (gi, xi) in g.iter().enumerate() {
            let mut a = 0;
            let mut stride = 1;
            for x in xi.iter().take(self.dim()) {
                a += ((x + 1.0) * p as f64 / 2.0).round() as usize * stride;
                stride *= p + 1;
            }
            perm[a] = gi;
        }
        perm
    }

    /// Reference coordinates of the nodes in the engine's local order.
    pub fn reference_nodes(self) -> Vec<[f64; 3]> {
        let g = self.gmsh_reference_nodes();
        self.gmsh_local_order().iter().map(|&i| g[i]).collect()
    }

    /// The local permutation that reverses a 2D cell's orientation (mirror of the reference
    /// element: swap ξ and η), `new[a] = old[perm[a]]`.
    fn mirror_2d(self) -> Vec<usize> {
        match self {
            ElementKind::Tri3 => vec![0, 2, 1],
            ElementKind::Tri6 => vec![0, 2, 1, 5, 4, 3],
            ElementKind::Quad4 => vec![0, 2, 1, 3],
            ElementKind::Quad9 => (0..9).map(|a| (a % 3) * 3 + a / 3).collect(),
            _ => (0..self.num_nodes()).collect(),
        }
    }

    /// Reference gradients ∂N_a/∂ξ_k of the shape functions at `xi`, engine order (unused
    /// trailing components 0).
    pub fn shape_gradients(self, xi: [f64; 3]) -> Vec<[f64; 3]> {
        match self {
            ElementKind::Quad4 => tensor_gradients::<2, 4>(xi),
            ElementKind::Quad9 => tensor_gradients::<2, 9>(xi),
            ElementKind::Hex8 => tensor_gradients::<3, 8>(xi),
            ElementKind::Hex27 => tensor_gradients::<3, 27>(xi),
            _ => {
                let d = self.dim();
                // Barycentric λ_0 = 1 − Σ ξ_k, λ_k = ξ_k, and their (constant) gradients.
                let mut lam = [0.0; 4];
                let mut dlam = [[0.0; 3]; 4];
                lam[0] = 1.0 - xi.iter().take(d).sum::<f64>();
                for k in 0..d {
                    lam[k + 1] = xi[k];
                    dlam[0][k] = -1.0;
                    dlam[k + 1][k] = 1.0;
                }
                let scale = |g: [f64; 3], s: f64| [g[0] * s, g[1] * s, g[2] * s];
                if self.degree() == 1 {
                    return dlam[..=d].to_vec();
                }
                let mut out: Vec<[f64; 3]> = (0..=d)
                    .map(|i| scale(dlam[i], 4.0 * lam[i] - 1.0))
                    .collect();
                let edges: &[(usize, usize)] = if d == 2 { &TRI_EDGES } else { &TET_EDGES };
                for &(i, j) in edges {
                    let mut g = [0.0; 3];
                    for k in 0..3 {
                        g[k] = 4.0 * (lam[j] * dlam[i][k] + lam[i] * dlam[j][k]);
                    }
                    out.push(g);
                }
                out
            }
        }
    }

    /// Quadrature points and weights on the reference cell: degree 2 on simplices (3 points on
    /// the triangle, 4 on the tetrahedron), 3 Gauss–Legendre points per direction on [−1, 1]^d.
    /// Exact for the measure of affine cells of every kind, and of curved Tri6/Quad9/Hex27.
    pub fn quadrature(self) -> Vec<([f64; 3], f64)> {
        match self {
            ElementKind::Tri3 | ElementKind::Tri6 => {
                let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
                vec![
                    ([a, a, 0.0], 1.0 / 6.0),
                    ([b, a, 0.0], 1.0 / 6.0),
                    ([a, b, 0.0], 1.0 / 6.0),
                ]
            }
            ElementKind::Tet4 | ElementKind::Tet10 => {
                let (a, b) = (0.585_410_196_624_968_5, 0.138_196_601_125_010_5);
                vec![
                    ([b, b, b], 1.0 / 24.0),
                    ([a, b, b], 1.0 / 24.0),
                    ([b, a, b], 1.0 / 24.0),
                    ([b, b, a], 1.0 / 24.0),
                ]
            }
            _ => {
                let g = gauss_legendre(3);
                let d = self.dim();
                let mut out = Vec::new();
                for &(z, wz) in if d == 3 { g } else { &g[1..2] } {
                    for &(y, wy) in g {
                        for &(x, wx) in g {
                            let w = wx * wy * if d == 3 { wz } else { 1.0 };
                            out.push(([x, y, if d == 3 { z } else { 0.0 }], w));
                        }
                    }
                }
                out
            }
        }
    }
}

fn tensor_gradients<const D: usize, const NN: usize>(xi: [f64; 3]) -> Vec<[f64; 3]> {
    let mut x = [0.0; D];
    x.copy_from_slice(&xi[..D]);
    let (_, g) = shape::<D, NN>(x);
    g.iter()
        .map(|ga| {
            let mut o = [0.0; 3];
            o[..D].copy_from_slice(ga);
            o
        })
        .collect()
}

/// Node tag → node index of a file (see `from_bytes`).
enum TagIndex {
    Dense { lo: u64, table: Vec<usize> },
    Map(HashMap<u64, usize>),
}

impl TagIndex {
    fn get(&self, t: u64) -> Option<usize> {
        match self {
            TagIndex::Dense { lo, table } => t
                .checked_sub(*lo)
                .and_then(|k| table.get(k as usize))
                .copied()
                .filter(|&i| i != usize::MAX),
            TagIndex::Map(m) => m.get(&t).copied(),
        }
    }
}

/// det J at `xi` of the cell with node coordinates `x` (engine order).
fn jacobian_det(kind: ElementKind, x: &[[f64; 3]], xi: [f64; 3]) -> f64 {
    det_from_gradients(kind.dim(), x, &kind.shape_gradients(xi))
}

/// det J of the cell with node coordinates `x` from the reference shape gradients at one point
/// (computed once per point for every cell of a mesh by the validation).
pub(crate) fn det_from_gradients(d: usize, x: &[[f64; 3]], grads: &[[f64; 3]]) -> f64 {
    let mut j = [[0.0; 3]; 3];
    for (xa, ga) in x.iter().zip(grads) {
        for i in 0..d {
            for k in 0..d {
                j[i][k] += xa[i] * ga[k];
            }
        }
    }
    if d == 2 {
        j[0][0] * j[1][1] - j[0][1] * j[1][0]
    } else {
        j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
            - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
            + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
    }
}

/// Why a mesh file is refused; every variant names the file and what in it is wrong.
#[derive(Debug, thiserror::Error)]
pub enum GmshError {
    #[error("{file}: cannot read the mesh file: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: not a Gmsh MSH 4.1 file ({reason}); save it with Gmsh's -format msh41")]
    NotMsh41 { file: String, reason: String },
    /// The file's structure: the section, the entity or block, and why (one line, no dump).
    #[error("{file}: {error}")]
    Parse { file: String, error: msh::MshError },
    #[error(
        "{file}: no physical group named \"{group}\" (found: {found}); tag the boundary with \
         Physical Curve(\"{group}\") in 2D or Physical Surface(\"{group}\") in 3D"
    )]
    MissingGroup {
        file: String,
        group: String,
        found: String,
    },
    #[error(
        "{file}: physical group \"{group}\" has dimension {found}, expected {expected} (the \
         boundary of a {mesh_dim}D mesh)"
    )]
    GroupDimension {
        file: String,
        group: String,
        found: usize,
        expected: usize,
        mesh_dim: usize,
    },
    #[error(
        "{file}: element {element} is a {found} but the mesh's cells are {first}s; one cell type per mesh"
    )]
    MixedElements {
        file: String,
        element: u64,
        found: &'static str,
        first: &'static str,
    },
    #[error(
        "{file}: no triangles, quadrilaterals, tetrahedra or hexahedra (Gmsh saves only the \
         elements of physical groups once any is defined: add a Physical Surface/Volume for the body)"
    )]
    NoCells { file: String },
    #[error("{file}: 2D mesh not in a plane: node {node} has z = {z}, node {first} has z = {z0}")]
    NotPlanar {
        file: String,
        node: u64,
        z: f64,
        first: u64,
        z0: f64,
    },
    #[error("{file}: element {element} is inverted (det J = {det:e} at reference point {xi:?})")]
    Inverted {
        file: String,
        element: u64,
        det: f64,
        xi: [f64; 3],
    },
    #[error(
        "{file}: element {element} is degenerate (det J = {det:e} at reference point {xi:?}, relative {relative:e})"
    )]
    Degenerate {
        file: String,
        element: u64,
        det: f64,
        relative: f64,
        xi: [f64; 3],
    },
    #[error(
        "{file}: node {node} is not a node of any {cell}; remove it (e.g. Gmsh's Coherence Mesh)"
    )]
    UnreferencedNode {
        file: String,
        node: u64,
        cell: &'static str,
    },
    #[error("{file}: node {node} is defined twice")]
    DuplicateNodeTag { file: String, node: u64 },
    #[error("{file}: node {node} has {axis} = {value}; every coordinate must be finite")]
    NonFinite {
        file: String,
        node: u64,
        axis: &'static str,
        value: f64,
    },
    #[error("{file}: element {element} has the nodes of element {first}: a cell listed twice")]
    DuplicateCell {
        file: String,
        element: u64,
        first: u64,
    },
    #[error(
        "{file}: the face with nodes {nodes:?} is shared by elements {cells:?}; a face belongs to at most two cells (overlapping cells)"
    )]
    FaceOverShared {
        file: String,
        nodes: Vec<u64>,
        cells: Vec<u64>,
    },
    #[error(
        "{file}: elements {a} and {b} lie on the same side of their common face (nodes {nodes:?}): the cells overlap"
    )]
    SameSide {
        file: String,
        a: u64,
        b: u64,
        nodes: Vec<u64>,
    },
    #[error(
        "{file}: elements {a} and {b} share the vertices {vertices:?} but not the nodes between them ({na:?} against {nb:?}): the mesh is not conforming"
    )]
    NotConforming {
        file: String,
        a: u64,
        b: u64,
        vertices: Vec<u64>,
        na: Vec<u64>,
        nb: Vec<u64>,
    },
    #[error(
        "{file}: nodes {a} and {b} coincide (distance {distance:e}): a crack or duplicated nodes; merge them (e.g. Gmsh's Coherence Mesh)"
    )]
    CoincidentNodes {
        file: String,
        a: u64,
        b: u64,
        distance: f64,
    },
    #[error(
        "{file}: element {element}: det J could not be certified positive over the cell (smallest Bernstein coefficient {min:e} after {pieces} subdivisions); straighten or refine it"
    )]
    NotCertified {
        file: String,
        element: u64,
        min: f64,
        pieces: usize,
    },
    #[error("{file}: group \"{group}\", element {element}: {reason}")]
    GroupElement {
        file: String,
        group: String,
        element: u64,
        reason: String,
    },
    #[error("{file}: element {element} refers to node {node}, which the file does not define")]
    UnknownNode {
        file: String,
        element: u64,
        node: u64,
    },
}

/// A named physical group: the entities it tags and their elements.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalGroup {
    pub name: String,
    /// Dimension of the tagged entities (d − 1 for a boundary, d for cells).
    pub dim: usize,
    /// Gmsh's physical tag.
    pub tag: i32,
    /// Tags of the geometric entities (of dimension `dim`) in the group.
    pub entities: Vec<i32>,
    /// The group's elements as node ids, Gmsh's local order (boundary lines/faces, or cells).
    pub elements: Vec<Vec<usize>>,
    /// The distinct nodes of those elements, increasing.
    pub nodes: Vec<usize>,
}

/// A validated Gmsh mesh (see the module header).
#[derive(Debug, Clone, PartialEq)]
pub struct GmshMesh {
    /// The file it was read from, as given.
    pub file: String,
    /// 2 or 3.
    pub dim: usize,
    pub kind: ElementKind,
    /// Node coordinates (z = 0 in 2D, whatever the plane's z in the file).
    pub coords: Vec<[f64; 3]>,
    /// Gmsh tag of each node.
    pub node_tags: Vec<u64>,
    /// Cells' node ids, `kind.num_nodes()` per cell, engine local order.
    pub elements: Vec<usize>,
    /// Gmsh tag of each cell.
    pub element_tags: Vec<u64>,
    pub groups: Vec<PhysicalGroup>,
    /// Largest cell diameter.
    pub h: f64,
    /// SHA-256 of the file's bytes, lowercase hex.
    pub content_hash: String,
    /// Whether the 2D cells were reoriented (all clockwise in the file).
    pub reoriented: bool,
}

impl GmshMesh {
    /// Read and validate a mesh file.
    pub fn read(path: &Path) -> Result<GmshMesh, GmshError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| GmshError::Io {
            file: file.clone(),
            source,
        })?;
        GmshMesh::from_bytes(&file, &bytes)
    }

    /// Validate the bytes of a mesh file (`file` names it in errors).
    pub fn from_bytes(file: &str, bytes: &[u8]) -> Result<GmshMesh, GmshError> {
        let f = || file.to_string();
        check_version(file, bytes)?;
        let msh = msh::parse(bytes).map_err(|error| GmshError::Parse { file: f(), error })?;

        // Nodes: the tags of every block, kept whatever the section's header says about their
        // range (issue 36: a file listing its nodes out of tag order is read as written).
        let total: usize = msh.node_blocks.iter().map(|b| b.tags.len()).sum();
        let mut coords = Vec::with_capacity(total);
        let mut node_tags = Vec::with_capacity(total);
        for block in &msh.node_blocks {
            node_tags.extend_from_slice(&block.tags);
            coords.extend_from_slice(&block.coords);
        }
        // Nodes are numbered in increasing tag order, not in the order the file lists them: a
        // file and its rewrite with the nodes listed otherwise (another writer's block order)
        // are then one mesh, and run to the same numbers to the bit (the assembly and the
        // factor's ordering follow the node numbering). Gmsh lists its nodes in tag order, so
        // its files keep their numbering.
        if node_tags.windows(2).any(|w| w[0] >= w[1]) {
            let mut order: Vec<usize> = (0..node_tags.len()).collect();
            order.sort_by_key(|&i| node_tags[i]);
            node_tags = order.iter().map(|&i| node_tags[i]).collect();
            coords = order.iter().map(|&i| coords[i]).collect();
        }
        for (i, c) in coords.iter().enumerate() {
            if let Some(k) = (0..3).find(|&k| !c[k].is_finite()) {
                return Err(GmshError::NonFinite {
                    file: f(),
                    node: node_tags[i],
                    axis: ["x", "y", "z"][k],
                    value: c[k],
                });
            }
        }
        // Tag → index: a table when the tags are dense (Gmsh numbers nodes 1..n; a 10⁵-node
        // file spent 5 % of its reading in SipHash), a map otherwise. A tag given twice is
        // refused: its elements would be ambiguous.
        let index_of = {
            let (lo, hi) = node_tags
                .iter()
                .fold((u64::MAX, 0), |(lo, hi), &t| (lo.min(t), hi.max(t)));
            let twice = |t: u64| GmshError::DuplicateNodeTag { file: f(), node: t };
            if !node_tags.is_empty() && hi - lo <= 2 * node_tags.len() as u64 + 16 {
                let mut table = vec![usize::MAX; (hi - lo + 1) as usize];
                for (i, &t) in node_tags.iter().enumerate() {
                    let slot = &mut table[(t - lo) as usize];
                    if *slot != usize::MAX {
                        return Err(twice(t));
                    }
                    *slot = i;
                }
                TagIndex::Dense { lo, table }
            } else {
                let mut m = HashMap::with_capacity(node_tags.len());
                for (i, &t) in node_tags.iter().enumerate() {
                    if m.insert(t, i).is_some() {
                        return Err(twice(t));
                    }
                }
                TagIndex::Map(m)
            }
        };

        // The cells are the elements of the highest dimension (the parser checked that each
        // block's type has its entity's dimension).
        let blocks = &msh.element_blocks;
        let dim = blocks
            .iter()
            .map(|b| b.entity_dim.max(0) as usize)
            .max()
            .unwrap_or(0);
        if dim < 2 {
            return Err(GmshError::NoCells { file: f() });
        }
        let node_index = |element: u64, t: u64| {
            index_of.get(t).ok_or_else(|| GmshError::UnknownNode {
                file: f(),
                element,
                node: t,
            })
        };

        // Every element's nodes are defined, those of blocks no group names included.
        for b in blocks {
            for (i, &t) in b.tags.iter().enumerate() {
                for &n in b.element(i) {
                    node_index(t, n)?;
                }
            }
        }

        // Cells.
        let mut kind: Option<ElementKind> = None;
        let mut elements = Vec::new();
        let mut element_tags = Vec::new();
        for b in blocks.iter().filter(|b| b.entity_dim as usize == dim) {
            let element = b.tags.first().copied().unwrap_or(0);
            let Some(k) = ElementKind::from_gmsh(b.element_type).filter(|k| k.dim() == dim) else {
                return Err(GmshError::MixedElements {
                    file: f(),
                    element,
                    found: "lower-dimensional element",
                    first: if dim == 2 {
                        "surface cell"
                    } else {
                        "volume cell"
                    },
                });
            };
            let first = *kind.get_or_insert(k);
            if k != first {
                return Err(GmshError::MixedElements {
                    file: f(),
                    element,
                    found: k.name(),
                    first: first.name(),
                });
            }
            let perm = k.gmsh_local_order();
            elements.reserve(b.tags.len() * perm.len());
            for (i, &t) in b.tags.iter().enumerate() {
                let nodes = b.element(i);
                for &g in &perm {
                    elements.push(node_index(t, nodes[g])?);
                }
                element_tags.push(t);
            }
        }
        let kind = kind.ok_or_else(|| GmshError::NoCells { file: f() })?;
        let nn = kind.num_nodes();

        // Unreferenced nodes.
        let mut used = vec![false; coords.len()];
        for &n in &elements {
            used[n] = true;
        }
        if let Some(i) = used.iter().position(|u| !u) {
            return Err(GmshError::UnreferencedNode {
                file: f(),
                node: node_tags[i],
                cell: kind.name(),
            });
        }

        // 2D: one plane z = const, then z := 0.
        let (lo, hi) = bounding_box(&coords);
        let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max).max(1.0);
        if dim == 2 {
            let z0 = coords[0][2];
            if let Some(i) = coords.iter().position(|c| (c[2] - z0).abs() > 1e-12 * size) {
                return Err(GmshError::NotPlanar {
                    file: f(),
                    node: node_tags[i],
                    z: coords[i][2],
                    first: node_tags[0],
                    z0,
                });
            }
            for c in &mut coords {
                c[2] = 0.0;
            }
        }

        // Orientation: in 2D the majority sign of det J at the cells' centres defines it (all
        // clockwise → mirrored); in 3D it must be positive.
        let centre = {
            let r = kind.reference_nodes();
            let mut c = [0.0; 3];
            let nv = if kind.is_simplex() { dim + 1 } else { r.len() };
            for p in r.iter().take(nv) {
                for k in 0..3 {
                    c[k] += p[k] / nv as f64;
                }
            }
            c
        };
        // One buffer for the cells' coordinates, the shape gradients once per point: the
        // checks below run at every cell of the mesh.
        let mut x = vec![[0.0; 3]; nn];
        let cell_x = |x: &mut [[f64; 3]], els: &[usize], e: usize| {
            for (xa, &n) in x.iter_mut().zip(&els[e * nn..(e + 1) * nn]) {
                *xa = coords[n];
            }
        };
        let ne = element_tags.len();
        let mut reoriented = false;
        if dim == 2 {
            let at_centre = kind.shape_gradients(centre);
            let negative = (0..ne)
                .filter(|&e| {
                    cell_x(&mut x, &elements, e);
                    det_from_gradients(dim, &x, &at_centre) < 0.0
                })
                .count();
            if 2 * negative > ne {
                reoriented = true;
                let m = kind.mirror_2d();
                for cell in elements.chunks_exact_mut(nn) {
                    let old = cell.to_vec();
                    for (a, slot) in cell.iter_mut().enumerate() {
                        *slot = old[m[a]];
                    }
                }
            }
        }
        let mut checks = kind.reference_nodes();
        checks.extend(kind.quadrature().into_iter().map(|(xi, _)| xi));
        let check_grads: Vec<Vec<[f64; 3]>> =
            checks.iter().map(|&xi| kind.shape_gradients(xi)).collect();
        // Reference measure: det J of an undistorted cell of diameter h_K is ~ h_K^d times this.
        let ref_measure = if kind.is_simplex() {
            0.5
        } else {
            2f64.powi(-(dim as i32))
        };
        let mut h: f64 = 0.0;
        for e in 0..ne {
            cell_x(&mut x, &elements, e);
            let mut diam: f64 = 0.0;
            for a in 0..nn {
                for b in a + 1..nn {
                    diam = diam.max(dist(x[a], x[b]));
                }
            }
            h = h.max(diam);
            let scale = diam.powi(dim as i32) * ref_measure;
            for (&xi, grads) in checks.iter().zip(&check_grads) {
                let det = det_from_gradients(dim, &x, grads);
                let relative = det / scale;
                if relative.is_nan() || relative.abs() <= 1e-10 {
                    return Err(GmshError::Degenerate {
                        file: f(),
                        element: element_tags[e],
                        det,
                        relative,
                        xi,
                    });
                }
                if det < 0.0 {
                    return Err(GmshError::Inverted {
                        file: f(),
                        element: element_tags[e],
                        det,
                        xi,
                    });
                }
            }
        }

        // Topology (issue 36): no cell twice, every face shared by at most two cells lying on
        // either side of it with the same midside nodes, no distinct nodes at one point, and
        // det J certified positive on the whole of every curved cell.
        let topo = check::Topology::new(kind, &elements, &node_tags, &element_tags);
        topo.check(file)?;
        check::coincident_nodes(dim, &coords).map_err(|(a, b, distance)| {
            GmshError::CoincidentNodes {
                file: f(),
                a: node_tags[a],
                b: node_tags[b],
                distance,
            }
        })?;
        check::certify_jacobians(kind, &coords, &elements)
            .map_err(|e| e.into_gmsh(f(), &element_tags))?;

        // Physical groups: entities by (dim, physical tag), then their elements.
        let mut groups = Vec::new();
        let entities = msh.entities.as_ref();
        for (gdim, tag, name) in msh.names {
            let mut ents: Vec<i32> = Vec::new();
            if let Some(en) = entities {
                ents.extend(
                    en[gdim.min(3)]
                        .iter()
                        .filter(|x| x.physical_tags.iter().any(|&t| t.abs() == tag))
                        .map(|x| x.tag),
                );
            }
            let boundary = name == "contact" || name == "clamped";
            if boundary && gdim + 1 != dim {
                return Err(GmshError::GroupDimension {
                    file: f(),
                    group: name,
                    found: gdim,
                    expected: dim - 1,
                    mesh_dim: dim,
                });
            }
            let mut els = Vec::new();
            let mut nodes = Vec::new();
            for b in blocks
                .iter()
                .filter(|b| b.entity_dim as usize == gdim && ents.contains(&b.entity_tag))
            {
                for (i, &t) in b.tags.iter().enumerate() {
                    let ids = b
                        .element(i)
                        .iter()
                        .map(|&n| node_index(t, n))
                        .collect::<Result<Vec<_>, _>>()?;
                    // `contact` and `clamped` are boundary faces of the cells' degree: Γ_C's
                    // quadrature and the clamped nodes act on them (a point or an interior face
                    // would fail or silently cut the body inside the runs).
                    if boundary {
                        topo.boundary_face(b.element_type, &ids).map_err(|reason| {
                            GmshError::GroupElement {
                                file: f(),
                                group: name.clone(),
                                element: t,
                                reason,
                            }
                        })?;
                    }
                    nodes.extend_from_slice(&ids);
                    els.push(ids);
                }
            }
            nodes.sort_unstable();
            nodes.dedup();
            groups.push(PhysicalGroup {
                name,
                dim: gdim,
                tag,
                entities: ents,
                elements: els,
                nodes,
            });
        }
        if !groups.iter().any(|g| g.name == "contact") {
            return Err(GmshError::MissingGroup {
                file: f(),
                group: "contact".into(),
                found: if groups.is_empty() {
                    "none".into()
                } else {
                    groups
                        .iter()
                        .map(|g| format!("\"{}\"", g.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                },
            });
        }
        let content_hash = Sha256::digest(bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        Ok(GmshMesh {
            file: f(),
            dim,
            kind,
            coords,
            node_tags,
            elements,
            element_tags,
            groups,
            h,
            content_hash,
            reoriented,
        })
    }

    /// [`GmshMesh::read`] through a process-wide cache: the planner validates a sweep's mesh
    /// files once per file (a `[grid]` crosses each with many methods) and the runs of the
    /// same process reuse the read mesh. Keyed by the path and the file's size and modification
    /// time, so a file rewritten between two sweeps of one process is read again.
    pub fn read_shared(path: &Path) -> Result<Arc<GmshMesh>, GmshError> {
        type Key = (PathBuf, u64, Option<SystemTime>);
        static CACHE: Mutex<Vec<(Key, Arc<GmshMesh>)>> = Mutex::new(Vec::new());
        /// Distinct files kept: a refinement family of a few meshes, and its reference.
        const CAP: usize = 8;
        let meta = std::fs::metadata(path).map_err(|source| GmshError::Io {
            file: path.display().to_string(),
            source,
        })?;
        let key: Key = (path.to_path_buf(), meta.len(), meta.modified().ok());
        {
            let cache = CACHE.lock().unwrap_or_else(|p| p.into_inner());
            if let Some((_, m)) = cache.iter().find(|(k, _)| *k == key) {
                return Ok(Arc::clone(m));
            }
        }
        let mesh = Arc::new(GmshMesh::read(path)?);
        let mut cache = CACHE.lock().unwrap_or_else(|p| p.into_inner());
        cache.retain(|(k, _)| k.0 != key.0);
        cache.push((key, Arc::clone(&mesh)));
        if cache.len() > CAP {
            cache.remove(0);
        }
        Ok(mesh)
    }

    /// The physical group of this name, if any.
    pub fn group(&self, name: &str) -> Option<&PhysicalGroup> {
        self.groups.iter().find(|g| g.name == name)
    }

    /// The nodes that carry contact (SPEC §1.6): those of the `contact` group not in `clamped`
    /// (a clamped node never moves towards the obstacle), increasing.
    pub fn contact_nodes(&self) -> Vec<usize> {
        let clamped = self.group("clamped").map_or(&[][..], |g| &g.nodes[..]);
        self.group("contact").map_or_else(Vec::new, |g| {
            // Both lists are increasing: a merge, not a search per node.
            let mut c = clamped.iter().peekable();
            g.nodes
                .iter()
                .copied()
                .filter(|&n| {
                    while c.next_if(|&&m| m < n).is_some() {}
                    c.peek() != Some(&&n)
                })
                .collect()
        })
    }

    /// The lowest x_d of the contact nodes ([`GmshMesh::contact_nodes`]), None without any: the
    /// rigid plane x_d = this − gap (SPEC §1.6), so a run's `gap` and `obstacle` are two names
    /// of one plane.
    pub fn contact_floor(&self) -> Option<f64> {
        self.contact_nodes()
            .iter()
            .map(|&n| self.coords[n][self.dim - 1])
            .reduce(f64::min)
    }

    /// |Ω_h| = Σ_K ∫_K̂ det J by [`ElementKind::quadrature`] (exact for affine cells).
    pub fn measure(&self) -> f64 {
        let q = self.kind.quadrature();
        let nn = self.kind.num_nodes();
        self.elements
            .chunks_exact(nn)
            .map(|cell| {
                let x: Vec<[f64; 3]> = cell.iter().map(|&n| self.coords[n]).collect();
                q.iter()
                    .map(|&(xi, w)| w * jacobian_det(self.kind, &x, xi))
                    .sum::<f64>()
            })
            .sum()
    }
}

impl Mesh for GmshMesh {
    fn dim(&self) -> usize {
        self.dim
    }
    fn num_nodes(&self) -> usize {
        self.coords.len()
    }
    fn num_elements(&self) -> usize {
        self.element_tags.len()
    }
    fn nodes_per_element(&self) -> usize {
        self.kind.num_nodes()
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        let nn = self.kind.num_nodes();
        &self.elements[e * nn..(e + 1) * nn]
    }
    fn coord(&self, node: usize) -> [f64; 3] {
        self.coords[node]
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn bounding_box(c: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in c {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// The `$MeshFormat` header must be the first section and say version 4.1.
fn check_version(file: &str, bytes: &[u8]) -> Result<(), GmshError> {
    let bad = |reason: String| GmshError::NotMsh41 {
        file: file.to_string(),
        reason,
    };
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(256)]);
    let mut lines = head.lines().map(str::trim);
    if lines.next() != Some("$MeshFormat") {
        return Err(bad("it does not start with $MeshFormat".into()));
    }
    let version = lines
        .next()
        .and_then(|l| l.split_whitespace().next())
        .unwrap_or("");
    if version != "4.1" {
        return Err(bad(format!("format version \"{version}\"")));
    }
    Ok(())
}
