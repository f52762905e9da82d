//! The Gmsh test meshes of `sweeps/meshes/` read back (issue 22): node, cell and group counts
//! against their `.geo` sources, |Ω_h| exact for affine cells, `h` by hand, the binary and ASCII
//! encodings of one mesh equal, the engine's node order (tensor order for quadrilaterals) and
//! the content hash. The `.msh` files are committed (regenerate with sweeps/meshes/generate.sh),
//! so these tests need no Gmsh.

use std::path::PathBuf;

use contact_sweep::space::fe::{ElementKind, GmshMesh, Mesh};
use sha2::{Digest, Sha256};

fn mesh(name: &str) -> GmshMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("sweeps/meshes")
        .join(name);
    GmshMesh::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

// Tolerances.
// |Ω_h|: a sum of 8–48 cell measures of size ~1/N^d, each exact up to a few ulps; the boundary
// nodes lie exactly on x_k ∈ {0, 1}, so the sum telescopes to 1 up to ~1e-15.
const MEASURE_TOL: f64 = 1e-13;
// h: Gmsh places transfinite nodes at parametric coordinates with ~1e-12 error (e.g. x =
// 0.2499999999994109 for 1/4 in square_tri_p1.msh), so the diameters differ from the exact
// ones by up to ~1e-12.
const H_TOL: f64 = 1e-11;

/// (cells, nodes) of a group, and every node of it on the plane x_axis = value.
fn check_group(m: &GmshMesh, name: &str, elements: usize, nodes: usize, axis: usize, value: f64) {
    let g = m.group(name).unwrap_or_else(|| panic!("no group {name}"));
    assert_eq!(g.dim, m.dim - 1, "{name}");
    assert_eq!(
        (g.elements.len(), g.nodes.len()),
        (elements, nodes),
        "{name}"
    );
    for &n in &g.nodes {
        // The boundary nodes of a transfinite mesh are on the plane to the bit (Gmsh copies
        // the corner coordinate along a straight line of constant x_axis).
        assert_eq!(m.coord(n)[axis], value, "{name}: node {n}");
    }
}

#[test]
fn square_p1_triangles() {
    // square_tri.geo, N = 4: 2 N^2 = 32 triangles, (N+1)^2 = 25 nodes, contact/clamped N lines.
    let m = mesh("square_tri_p1.msh");
    assert_eq!((m.dim, m.kind), (2, ElementKind::Tri3));
    assert_eq!((m.num_nodes(), m.num_elements()), (25, 32));
    check_group(&m, "contact", 4, 5, 1, 0.0);
    check_group(&m, "clamped", 4, 5, 1, 1.0);
    assert_eq!(m.group("body").unwrap().elements.len(), 32);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    // The longest edge is a cell diagonal √2/N.
    assert!((m.h - 2f64.sqrt() / 4.0).abs() < H_TOL, "h = {}", m.h);
    assert!(!m.reoriented);
}

#[test]
fn square_p1_binary_equals_ascii() {
    let a = mesh("square_tri_p1.msh");
    let b = mesh("square_tri_p1_bin.msh");
    assert_eq!(a.elements, b.elements);
    assert_eq!(a.node_tags, b.node_tags);
    assert_eq!(a.groups, b.groups);
    for (p, q) in a.coords.iter().zip(&b.coords) {
        for k in 0..3 {
            // The ASCII file prints 16 significant digits; the binary one stores the double.
            assert!((p[k] - q[k]).abs() < 1e-15, "{p:?} vs {q:?}");
        }
    }
    assert_ne!(a.content_hash, b.content_hash);
}

#[test]
fn square_p2_triangles() {
    // Degree 2: (2N+1)^2 = 81 nodes, the same 32 cells; a boundary line has 3 nodes, so the
    // contact group has 2N+1 = 9 nodes.
    let m = mesh("square_tri_p2.msh");
    assert_eq!((m.dim, m.kind), (2, ElementKind::Tri6));
    assert_eq!((m.num_nodes(), m.num_elements()), (81, 32));
    check_group(&m, "contact", 4, 9, 1, 0.0);
    check_group(&m, "clamped", 4, 9, 1, 1.0);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    assert!((m.h - 2f64.sqrt() / 4.0).abs() < H_TOL, "h = {}", m.h);
    // Edge nodes at the midpoints of their vertices (straight edges), to Gmsh's placement.
    for cell in m.elements.chunks_exact(6) {
        for (k, (i, j)) in [(0, 1), (1, 2), (2, 0)].into_iter().enumerate() {
            let (a, b, c) = (m.coords[cell[i]], m.coords[cell[j]], m.coords[cell[3 + k]]);
            for d in 0..2 {
                assert!((0.5 * (a[d] + b[d]) - c[d]).abs() < H_TOL);
            }
        }
    }
}

#[test]
fn square_q1_quadrilaterals_in_tensor_order() {
    // square_quad.geo, N = 4, M = 2: 8 quads, 5 × 3 = 15 nodes, h = √(1/16 + 1/4).
    let m = mesh("square_quad_q1.msh");
    assert_eq!((m.dim, m.kind), (2, ElementKind::Quad4));
    assert_eq!((m.num_nodes(), m.num_elements()), (15, 8));
    check_group(&m, "contact", 4, 5, 1, 0.0);
    check_group(&m, "clamped", 4, 5, 1, 1.0);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    assert!(
        (m.h - (1.0f64 / 16.0 + 0.25).sqrt()).abs() < H_TOL,
        "h = {}",
        m.h
    );
    // Tensor order (as BoxMesh): node 1 = node 0 + (1/4, 0), node 2 = node 0 + (0, 1/2),
    // node 3 = node 0 + (1/4, 1/2), up to Gmsh's node placement.
    for e in 0..m.num_elements() {
        let x: Vec<[f64; 3]> = m.element_nodes(e).iter().map(|&n| m.coord(n)).collect();
        for (a, off) in [(1, [0.25, 0.0]), (2, [0.0, 0.5]), (3, [0.25, 0.5])] {
            for d in 0..2 {
                assert!((x[a][d] - x[0][d] - off[d]).abs() < H_TOL, "cell {e} {x:?}");
            }
        }
    }
}

#[test]
fn square_q2_quadrilaterals() {
    // Degree 2 (9-node): (2N+1)(2M+1) = 45 nodes; tensor node a = (i, j) at x_0 + (i/8, j/4).
    let m = mesh("square_quad_q2.msh");
    assert_eq!((m.dim, m.kind), (2, ElementKind::Quad9));
    assert_eq!((m.num_nodes(), m.num_elements()), (45, 8));
    check_group(&m, "contact", 4, 9, 1, 0.0);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    assert!(
        (m.h - (1.0f64 / 16.0 + 0.25).sqrt()).abs() < H_TOL,
        "h = {}",
        m.h
    );
    for e in 0..m.num_elements() {
        let x: Vec<[f64; 3]> = m.element_nodes(e).iter().map(|&n| m.coord(n)).collect();
        for (a, xa) in x.iter().enumerate() {
            let off = [(a % 3) as f64 / 8.0, (a / 3) as f64 / 4.0];
            for d in 0..2 {
                assert!(
                    (xa[d] - x[0][d] - off[d]).abs() < H_TOL,
                    "cell {e} node {a}"
                );
            }
        }
    }
}

#[test]
fn cube_tetrahedra_binary() {
    // cube_tet.geo, N = 2, binary file: 6 N^3 = 48 tets, (N+1)^3 = 27 nodes; contact = bottom
    // face, 2 N^2 = 8 triangles on (N+1)^2 = 9 nodes. Each cube is cut into 6 tets around its
    // space diagonal, so h = √3/N.
    let m = mesh("cube_tet.msh");
    assert_eq!((m.dim, m.kind), (3, ElementKind::Tet4));
    assert_eq!((m.num_nodes(), m.num_elements()), (27, 48));
    check_group(&m, "contact", 8, 9, 2, 0.0);
    check_group(&m, "clamped", 8, 9, 2, 1.0);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    assert!((m.h - 3f64.sqrt() / 2.0).abs() < H_TOL, "h = {}", m.h);
}

#[test]
fn content_hash_is_the_files_sha256() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("sweeps/meshes/cube_tet.msh");
    let bytes = std::fs::read(&path).unwrap();
    let want: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(mesh("cube_tet.msh").content_hash, want);
    assert_eq!(want.len(), 64);
}

/// Cells of a structured box mesh in tensor order: local node a = (i, j, k) (x fastest, p + 1
/// per axis) sits at node 0 + (i, j, k)·spacing/p.
fn check_tensor_order(m: &GmshMesh, p: usize, spacing: [f64; 3]) {
    let n1 = p + 1;
    for e in 0..m.num_elements() {
        let x: Vec<[f64; 3]> = m.element_nodes(e).iter().map(|&n| m.coord(n)).collect();
        for (a, xa) in x.iter().enumerate() {
            let idx = [a % n1, (a / n1) % n1, a / (n1 * n1)];
            for d in 0..m.dim {
                let want = x[0][d] + idx[d] as f64 * spacing[d] / p as f64;
                assert!((xa[d] - want).abs() < H_TOL, "cell {e} node {a}");
            }
        }
    }
}

#[test]
fn cube_q1_hexahedra_in_tensor_order() {
    // cube_hex.geo, N = 2: 8 hexahedra, 27 nodes; contact = 4 quadrilaterals on 9 nodes at z = 0;
    // h = the space diagonal √3/2.
    let m = mesh("cube_hex_q1.msh");
    assert_eq!((m.dim, m.kind), (3, ElementKind::Hex8));
    assert_eq!((m.num_nodes(), m.num_elements()), (27, 8));
    check_group(&m, "contact", 4, 9, 2, 0.0);
    check_group(&m, "clamped", 4, 9, 2, 1.0);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    assert!((m.h - 3f64.sqrt() / 2.0).abs() < H_TOL, "h = {}", m.h);
    check_tensor_order(&m, 1, [0.5; 3]);
}

#[test]
fn cube_q2_hexahedra_in_tensor_order() {
    // Degree 2 (27-node): (2N+1)^3 = 125 nodes; contact = 4 nine-node quadrilaterals, 25 nodes.
    let m = mesh("cube_hex_q2.msh");
    assert_eq!((m.dim, m.kind), (3, ElementKind::Hex27));
    assert_eq!((m.num_nodes(), m.num_elements()), (125, 8));
    check_group(&m, "contact", 4, 25, 2, 0.0);
    assert!((m.measure() - 1.0).abs() < MEASURE_TOL, "{}", m.measure());
    assert!((m.h - 3f64.sqrt() / 2.0).abs() < H_TOL, "h = {}", m.h);
    check_tensor_order(&m, 2, [0.5; 3]);
}
