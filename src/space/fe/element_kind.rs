//! The cell types of a Gmsh mesh ([`ElementKind`]): their reference nodes, Gmsh's local node
//! order against the engine's (tensor order for quadrilaterals and hexahedra), their shape
//! gradients, a quadrature exact for their measure, and det J of a cell from its node coordinates.
//!
//! Why a file of its own: the reader of a mesh file (`gmsh.rs`) and its whole-mesh checks
//! (`check.rs`) both stand on these facts of the reference cells, and the reader calls the
//! checks; kept here, below both, the facts are shared without the two files importing each other.

use super::element::{gauss_legendre, shape};

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
    pub(crate) fn mirror_2d(self) -> Vec<usize> {
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
                let (lam, dlam) = barycentric(d, xi);
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

/// Barycentric coordinates λ_0 = 1 − Σ ξ_k, λ_k = ξ_k of the point ξ of the reference
/// d-simplex, and their (constant) gradients; unused trailing entries 0.
pub(crate) fn barycentric(d: usize, xi: [f64; 3]) -> ([f64; 4], [[f64; 3]; 4]) {
    let mut lam = [0.0; 4];
    let mut dlam = [[0.0; 3]; 4];
    lam[0] = 1.0 - xi.iter().take(d).sum::<f64>();
    for k in 0..d {
        lam[k + 1] = xi[k];
        dlam[0][k] = -1.0;
        dlam[k + 1][k] = 1.0;
    }
    (lam, dlam)
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

/// det J at `xi` of the cell with node coordinates `x` (engine order).
pub(crate) fn jacobian_det(kind: ElementKind, x: &[[f64; 3]], xi: [f64; 3]) -> f64 {
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
