//! Why a Gmsh mesh file is refused ([`GmshError`]): one variant per reason, each naming the file
//! and what in it is wrong, on one line.
//!
//! Why a file of its own: the reader (`gmsh.rs`) and the whole-mesh checks (`check.rs`) both
//! report these errors, and the reader calls the checks; kept here, below both, the two share the
//! type without importing each other.

use super::msh;

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
        "{file}: elements {a} and {b} overlap (depth {depth:e}, {relative:e} of the smaller cell); cells of one body may meet only along shared faces, edges or vertices"
    )]
    Overlap {
        file: String,
        a: u64,
        b: u64,
        depth: f64,
        relative: f64,
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
    /// A two-body mesh (contract §1.10) whose bodies or interface are not what the engine takes.
    #[error("{file}: two bodies: {reason}")]
    TwoBodies { file: String, reason: String },
    #[error("{file}: element {element} refers to node {node}, which the file does not define")]
    UnknownNode {
        file: String,
        element: u64,
        node: u64,
    },
}
