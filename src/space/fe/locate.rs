//! Point location in a finite-element mesh and evaluation of a nodal field there: how a run is
//! compared with a reference computed on a finer mesh that is not nested in its own (contract §1.6:
//! the disc and ball's mapped meshes of two sizes, any two Gmsh meshes).
//!
//! For a point x* the element K containing it and the reference coordinates ξ* with
//! F_K(ξ*) = x* are found; then I u_ref(x*) = Σ_a N_a(ξ*) u_a over K's nodes — the reference's
//! own finite-element function, evaluated exactly (no projection), so a coarse node that is a
//! reference node gets that node's value (N_a(ξ*) = δ_ab to round-off).
//!
//! - Candidates: a uniform grid of bins over the mesh's bounding box, about one element per bin,
//!   each element entered in every bin its bounding box meets. The box of a curved degree-2
//!   element is that of its nodes grown by a quarter of its size on each side (the edges of the
//!   meshes here bulge by far less than that), so no element is missed. On a quasi-uniform mesh
//!   a query meets O(1) candidates, cheaper than the O(log n) of a tree; a graded mesh puts more
//!   elements in a bin, never fewer.
//! - The inverse map: Newton on F_K(ξ) − x* = 0, J = Σ_a x_a ⊗ ∇_ξ N_a, from the reference
//!   element's centre. Affine elements converge in one step, mapped Q2 ones in 3–5. A simplex
//!   whose map is affine — P1, or P2 with every mid-edge node at its edge's midpoint to
//!   round-off (all but the boundary cells of a Gmsh mesh of a curved body) — needs no Newton:
//!   F_K = F1, so ξ solves the d × d system x* − x_0 = Σ_k ξ_k (x_k − x_0) of its vertices, at a
//!   third of the two Newton iterations' cost with six shape functions (measured on the Gmsh
//!   half-disc, docs/performance.md).
//! - Inside: ξ in the reference element up to 1e-10 (cube [−1, 1]^d, simplex ξ_k ≥ 0,
//!   Σ ξ_k ≤ 1). A point on a shared face is inside both neighbours; either gives the same value,
//!   the field being continuous.
//! - Outside every element by a little: the boundary of a coarse mesh of a curved body is not the
//!   reference's (a Q2 disc's boundary nodes lie on the circle, its edges between them are
//!   parabolas), so a boundary node may lie outside the reference mesh by O(h_ref³). The
//!   candidate whose ξ is nearest its reference element is then used (the field extended by its
//!   polynomial), provided ξ is within [`OUTSIDE_TOL`] of it; further away the point is
//!   reported as not in the mesh.

use super::element::shape;
use super::element_kind::{ElementKind, TET_EDGES, TRI_EDGES, barycentric};
use super::mesh::Mesh;

/// Tolerance of "inside the reference element" in reference coordinates.
const INSIDE_TOL: f64 = 1e-10;
/// How far outside its reference element (in reference coordinates, the element's size being
/// ~1) a point may lie and still take that element's polynomial: a boundary node of a coarser
/// mesh of a curved body lies O(h³) outside the reference's curved edges, O(h²) outside straight
/// ones; 0.05 of an element is far more than either and far less than a wrong neighbour.
pub const OUTSIDE_TOL: f64 = 0.05;
/// Most nodes per element (Hex27).
const MAX_NODES: usize = 27;
const NEWTON_ITERS: usize = 30;

/// The element kind of a mesh from its dimension and nodes per element (unambiguous for the
/// supported kinds).
pub fn element_kind(dim: usize, nodes: usize) -> Option<ElementKind> {
    Some(match (dim, nodes) {
        (2, 3) => ElementKind::Tri3,
        (2, 6) => ElementKind::Tri6,
        (2, 4) => ElementKind::Quad4,
        (2, 9) => ElementKind::Quad9,
        (3, 4) => ElementKind::Tet4,
        (3, 10) => ElementKind::Tet10,
        (3, 8) => ElementKind::Hex8,
        (3, 27) => ElementKind::Hex27,
        _ => return None,
    })
}

/// Shape function values and reference gradients of `kind` at ξ, engine node order, into the
/// first `kind.num_nodes()` entries.
pub fn shape_into(
    kind: ElementKind,
    xi: [f64; 3],
    n: &mut [f64; MAX_NODES],
    dn: &mut [[f64; 3]; MAX_NODES],
) {
    fn tensor<const D: usize, const NN: usize>(
        xi: [f64; 3],
        n: &mut [f64; MAX_NODES],
        dn: &mut [[f64; 3]; MAX_NODES],
    ) {
        let mut x = [0.0; D];
        x.copy_from_slice(&xi[..D]);
        let (v, g) = shape::<D, NN>(x);
        for a in 0..NN {
            n[a] = v[a];
            dn[a] = [0.0; 3];
            dn[a][..D].copy_from_slice(&g[a]);
        }
    }
    match kind {
        ElementKind::Quad4 => tensor::<2, 4>(xi, n, dn),
        ElementKind::Quad9 => tensor::<2, 9>(xi, n, dn),
        ElementKind::Hex8 => tensor::<3, 8>(xi, n, dn),
        ElementKind::Hex27 => tensor::<3, 27>(xi, n, dn),
        _ => {
            // Barycentric λ_0 = 1 − Σ ξ_k, λ_k = ξ_k; P2: λ_i(2λ_i − 1) at the vertices and
            // 4 λ_i λ_j at the midpoint of edge (i, j), Gmsh's edge order.
            let d = kind.dim();
            let (lam, dlam) = barycentric(d, xi);
            if kind.degree() == 1 {
                n[..=d].copy_from_slice(&lam[..=d]);
                dn[..=d].copy_from_slice(&dlam[..=d]);
                return;
            }
            for a in 0..=d {
                n[a] = lam[a] * (2.0 * lam[a] - 1.0);
                dn[a] = dlam[a].map(|g| g * (4.0 * lam[a] - 1.0));
            }
            let edges: &[(usize, usize)] = if d == 2 { &TRI_EDGES } else { &TET_EDGES };
            for (e, &(i, j)) in edges.iter().enumerate() {
                n[d + 1 + e] = 4.0 * lam[i] * lam[j];
                for k in 0..3 {
                    dn[d + 1 + e][k] = 4.0 * (lam[j] * dlam[i][k] + lam[i] * dlam[j][k]);
                }
            }
        }
    }
}

/// How far ξ lies outside the reference element of `kind` (0 inside), in reference units.
fn outside(kind: ElementKind, xi: [f64; 3]) -> f64 {
    let d = kind.dim();
    if kind.is_simplex() {
        let neg = xi.iter().take(d).fold(0.0f64, |m, &x| m.max(-x));
        neg.max(xi.iter().take(d).sum::<f64>() - 1.0)
    } else {
        xi.iter().take(d).fold(0.0f64, |m, &x| m.max(x.abs() - 1.0))
    }
}

/// The reference element's centre, Newton's start.
fn centre(kind: ElementKind) -> [f64; 3] {
    match kind.dim() {
        _ if !kind.is_simplex() => [0.0; 3],
        2 => [1.0 / 3.0, 1.0 / 3.0, 0.0],
        _ => [0.25; 3],
    }
}

/// A mesh as plain arrays (node coordinates, flat element connectivity): what a reference
/// solution stores of its mesh so that a run on another mesh can locate its nodes in it
/// ([`crate::run::reference::ReferenceData`]), whatever built the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct PlainMesh {
    pub dim: usize,
    pub nodes_per_element: usize,
    pub coords: Vec<[f64; 3]>,
    /// Element e's nodes: `elements[e·nodes_per_element..(e + 1)·nodes_per_element]`.
    pub elements: Vec<usize>,
}

impl PlainMesh {
    pub fn from_mesh(mesh: &dyn Mesh) -> PlainMesh {
        PlainMesh {
            dim: mesh.dim(),
            nodes_per_element: mesh.nodes_per_element(),
            coords: (0..mesh.num_nodes()).map(|n| mesh.coord(n)).collect(),
            elements: (0..mesh.num_elements())
                .flat_map(|e| mesh.element_nodes(e).iter().copied())
                .collect(),
        }
    }
}

impl Mesh for PlainMesh {
    fn dim(&self) -> usize {
        self.dim
    }
    fn num_nodes(&self) -> usize {
        self.coords.len()
    }
    fn num_elements(&self) -> usize {
        self.elements.len() / self.nodes_per_element.max(1)
    }
    fn nodes_per_element(&self) -> usize {
        self.nodes_per_element
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        let k = self.nodes_per_element;
        &self.elements[e * k..(e + 1) * k]
    }
    fn coord(&self, node: usize) -> [f64; 3] {
        self.coords[node]
    }
}

/// Where a point lies: the element and the reference coordinates, and how far outside the
/// element it is (0 for a point of the mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Location {
    pub element: usize,
    pub xi: [f64; 3],
    pub outside: f64,
}

/// The interpolation of a nodal field at a point: `(node, weight)` pairs, I u(x) = Σ w u_node.
pub type Weights = Vec<(usize, f64)>;

/// A mesh made searchable: element kind, bounding boxes and the bins.
pub struct PointLocator<'m> {
    mesh: &'m dyn Mesh,
    kind: ElementKind,
    lo: [f64; 3],
    cell: [f64; 3],
    bins: [usize; 3],
    /// Elements of bin b: `items[start[b]..start[b + 1]]`.
    start: Vec<usize>,
    items: Vec<u32>,
    boxes: Vec<[[f64; 3]; 2]>,
    /// Whether each element's map is affine (simplices only: module header).
    affine: Vec<bool>,
}

/// Why a point cannot be located.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LocateError {
    #[error("{dim}D mesh with {nodes} nodes per element: not a supported element kind")]
    Kind { dim: usize, nodes: usize },
    #[error(
        "point ({x:.6e}, {y:.6e}, {z:.6e}) is not in the reference mesh (nearest element {element}, {outside:.3e} outside it in reference units)"
    )]
    Outside {
        x: f64,
        y: f64,
        z: f64,
        element: usize,
        outside: f64,
    },
    #[error("point ({x:.6e}, {y:.6e}, {z:.6e}) is not in the reference mesh (no element near it)")]
    Far { x: f64, y: f64, z: f64 },
}

impl<'m> PointLocator<'m> {
    /// Index the elements of `mesh` (O(number of elements)).
    pub fn new(mesh: &'m dyn Mesh) -> Result<PointLocator<'m>, LocateError> {
        let (d, nn, ne) = (mesh.dim(), mesh.nodes_per_element(), mesh.num_elements());
        let kind = element_kind(d, nn).ok_or(LocateError::Kind { dim: d, nodes: nn })?;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut boxes = Vec::with_capacity(ne);
        for e in 0..ne {
            let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
            for &node in mesh.element_nodes(e) {
                let x = mesh.coord(node);
                for k in 0..d {
                    b[0][k] = b[0][k].min(x[k]);
                    b[1][k] = b[1][k].max(x[k]);
                }
            }
            // Grown by a quarter of the element's size: curved edges bulge past their nodes.
            let size = (0..d).map(|k| b[1][k] - b[0][k]).fold(0.0f64, f64::max);
            for k in 0..d {
                b[0][k] -= 0.25 * size;
                b[1][k] += 0.25 * size;
                lo[k] = lo[k].min(b[0][k]);
                hi[k] = hi[k].max(b[1][k]);
            }
            boxes.push(b);
        }
        for k in d..3 {
            (lo[k], hi[k]) = (0.0, 0.0);
        }
        // Affine simplices: P1, or P2 with each mid-edge node at its edge's midpoint to the
        // rounding of (x_i + x_j)/2 (4 ulps of the largest coordinate).
        let edges: &[(usize, usize)] = if d == 2 { &TRI_EDGES } else { &TET_EDGES };
        let affine: Vec<bool> = (0..ne)
            .map(|e| {
                if !kind.is_simplex() {
                    return false;
                }
                let nodes = mesh.element_nodes(e);
                edges.iter().enumerate().all(|(k, &(i, j))| {
                    let Some(&m) = nodes.get(d + 1 + k) else {
                        return true;
                    };
                    let (a, b, c) = (mesh.coord(nodes[i]), mesh.coord(nodes[j]), mesh.coord(m));
                    (0..d).all(|q| {
                        let scale = a[q].abs().max(b[q].abs()).max(c[q].abs());
                        (c[q] - 0.5 * (a[q] + b[q])).abs() <= 4.0 * f64::EPSILON * scale
                    })
                })
            })
            .collect();
        // About one element per bin, bins as cubic as the box allows.
        let ext: Vec<f64> = (0..d)
            .map(|k| (hi[k] - lo[k]).max(f64::MIN_POSITIVE))
            .collect();
        let vol: f64 = ext.iter().product();
        let side = (vol / ne.max(1) as f64).powf(1.0 / d as f64);
        let mut bins = [1usize; 3];
        let mut cell = [1.0; 3];
        for k in 0..d {
            bins[k] = ((ext[k] / side).ceil() as usize).clamp(1, 1 << 20);
            cell[k] = ext[k] / bins[k] as f64;
        }
        let nb = bins.iter().product::<usize>();
        let range = |b: &[[f64; 3]; 2], k: usize| -> (usize, usize) {
            if k >= d {
                return (0, 0);
            }
            let i0 = ((b[0][k] - lo[k]) / cell[k]).floor().max(0.0) as usize;
            let i1 = ((b[1][k] - lo[k]) / cell[k]).floor().max(0.0) as usize;
            (i0.min(bins[k] - 1), i1.min(bins[k] - 1))
        };
        // Two passes (count, fill): one flat array instead of a Vec per bin.
        let mut count = vec![0usize; nb + 1];
        let visit = |b: &[[f64; 3]; 2], f: &mut dyn FnMut(usize)| {
            let (r0, r1, r2) = (range(b, 0), range(b, 1), range(b, 2));
            for k in r2.0..=r2.1 {
                for j in r1.0..=r1.1 {
                    for i in r0.0..=r0.1 {
                        f(i + bins[0] * (j + bins[1] * k));
                    }
                }
            }
        };
        for b in &boxes {
            visit(b, &mut |bin| count[bin + 1] += 1);
        }
        for i in 0..nb {
            count[i + 1] += count[i];
        }
        let start = count.clone();
        let mut items = vec![0u32; count[nb]];
        for (e, b) in boxes.iter().enumerate() {
            visit(b, &mut |bin| {
                items[count[bin]] = e as u32;
                count[bin] += 1;
            });
        }
        Ok(PointLocator {
            mesh,
            kind,
            lo,
            cell,
            bins,
            start,
            items,
            boxes,
            affine,
        })
    }

    pub fn kind(&self) -> ElementKind {
        self.kind
    }

    /// ξ with F_K(ξ) = x by Newton from the centre (None if J is singular along the way).
    fn inverse_map(&self, e: usize, x: [f64; 3]) -> Option<[f64; 3]> {
        let d = self.mesh.dim();
        let nodes = self.mesh.element_nodes(e);
        let mut n = [0.0; MAX_NODES];
        let mut dn = [[0.0; 3]; MAX_NODES];
        let mut xi = centre(self.kind);
        for _ in 0..NEWTON_ITERS {
            shape_into(self.kind, xi, &mut n, &mut dn);
            let mut r = [0.0; 3];
            let mut j = [[0.0; 3]; 3];
            for (a, &node) in nodes.iter().enumerate() {
                let xa = self.mesh.coord(node);
                for i in 0..d {
                    r[i] += n[a] * xa[i];
                    for k in 0..d {
                        j[i][k] += xa[i] * dn[a][k];
                    }
                }
            }
            for i in 0..d {
                r[i] -= x[i];
            }
            let step = solve_small(d, &j, &r)?;
            let mut size = 0.0f64;
            for k in 0..d {
                xi[k] -= step[k];
                size = size.max(step[k].abs());
            }
            // Far outside: not this element (and Newton may wander); give up early.
            if outside(self.kind, xi) > 2.0 {
                return Some(xi);
            }
            if size <= 1e-15 * (1.0 + xi.iter().fold(0.0f64, |m, v| m.max(v.abs()))) {
                break;
            }
        }
        Some(xi)
    }

    /// ξ of an affine simplex (module header): x − x_0 = Σ_k ξ_k (x_{k+1} − x_0), the reference
    /// simplex's vertex k + 1 at ξ = e_k (None if the simplex is degenerate).
    fn affine_inverse(&self, e: usize, x: [f64; 3]) -> Option<[f64; 3]> {
        let d = self.mesh.dim();
        let nodes = self.mesh.element_nodes(e);
        let x0 = self.mesh.coord(nodes[0]);
        let mut j = [[0.0; 3]; 3];
        let mut r = [0.0; 3];
        for i in 0..d {
            for (k, &node) in nodes[1..=d].iter().enumerate() {
                j[i][k] = self.mesh.coord(node)[i] - x0[i];
            }
            r[i] = x[i] - x0[i];
        }
        solve_small(d, &j, &r)
    }

    /// The element containing `x`, or the nearest one within [`OUTSIDE_TOL`].
    pub fn locate(&self, x: [f64; 3]) -> Result<Location, LocateError> {
        let d = self.mesh.dim();
        let mut best: Option<Location> = None;
        let mut idx = [0usize; 3];
        for k in 0..d {
            let i = ((x[k] - self.lo[k]) / self.cell[k]).floor();
            if i < 0.0 || i >= self.bins[k] as f64 {
                return Err(LocateError::Far {
                    x: x[0],
                    y: x[1],
                    z: x[2],
                });
            }
            idx[k] = i as usize;
        }
        let bin = idx[0] + self.bins[0] * (idx[1] + self.bins[1] * idx[2]);
        for &e in &self.items[self.start[bin]..self.start[bin + 1]] {
            let e = e as usize;
            let b = &self.boxes[e];
            if (0..d).any(|k| x[k] < b[0][k] || x[k] > b[1][k]) {
                continue;
            }
            let xi = if self.affine[e] {
                self.affine_inverse(e, x)
            } else {
                self.inverse_map(e, x)
            };
            let Some(xi) = xi else {
                continue;
            };
            let out = outside(self.kind, xi);
            if out <= INSIDE_TOL {
                return Ok(Location {
                    element: e,
                    xi,
                    outside: 0.0,
                });
            }
            if best.is_none_or(|l| out < l.outside) {
                best = Some(Location {
                    element: e,
                    xi,
                    outside: out,
                });
            }
        }
        match best {
            Some(l) if l.outside <= OUTSIDE_TOL => Ok(l),
            Some(l) => Err(LocateError::Outside {
                x: x[0],
                y: x[1],
                z: x[2],
                element: l.element,
                outside: l.outside,
            }),
            None => Err(LocateError::Far {
                x: x[0],
                y: x[1],
                z: x[2],
            }),
        }
    }

    /// The nodes and weights that interpolate a nodal field of the mesh at `x`.
    pub fn weights(&self, x: [f64; 3]) -> Result<Weights, LocateError> {
        let l = self.locate(x)?;
        let mut n = [0.0; MAX_NODES];
        let mut dn = [[0.0; 3]; MAX_NODES];
        shape_into(self.kind, l.xi, &mut n, &mut dn);
        Ok(self
            .mesh
            .element_nodes(l.element)
            .iter()
            .zip(n)
            .map(|(&node, w)| (node, w))
            .collect())
    }
}

/// J s = r for a 2×2 or 3×3 J (Cramer); None when J is singular.
fn solve_small(d: usize, j: &[[f64; 3]; 3], r: &[f64; 3]) -> Option<[f64; 3]> {
    if d == 2 {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        return Some([
            (r[0] * j[1][1] - j[0][1] * r[1]) / det,
            (j[0][0] * r[1] - r[0] * j[1][0]) / det,
            0.0,
        ]);
    }
    let det3 = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let det = det3(j);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let mut s = [0.0; 3];
    for (c, sc) in s.iter_mut().enumerate() {
        let mut m = *j;
        for i in 0..3 {
            m[i][c] = r[i];
        }
        *sc = det3(&m) / det;
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::fe::{BallMesh, BoxMesh};

    /// A field that every element of degree ≥ 1 reproduces exactly: affine in x.
    fn affine(x: [f64; 3]) -> f64 {
        0.3 + 1.7 * x[0] - 0.9 * x[1] + 0.4 * x[2]
    }

    fn interpolate(loc: &PointLocator, mesh: &dyn Mesh, x: [f64; 3]) -> f64 {
        loc.weights(x)
            .unwrap()
            .iter()
            .map(|&(node, w)| w * affine(mesh.coord(node)))
            .sum()
    }

    #[test]
    fn affine_fields_are_reproduced_on_boxes_and_mapped_balls() {
        // The interpolant of an affine field is the field (every kind here contains P1), so the
        // value at any point is exact to round-off: |f| ≤ 40, 1e-12 relative.
        let boxm = BoxMesh::new(&[1.0, 3.0], &[4, 12]);
        let loc = PointLocator::new(&boxm).unwrap();
        for x in [
            [0.13, 2.71, 0.0],
            [1.0, 3.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.5, 0.25, 0.0],
        ] {
            assert!((interpolate(&loc, &boxm, x) - affine(x)).abs() < 1e-12);
        }
        for (dim, degree) in [(2, 1), (2, 2), (3, 2)] {
            let ball = BallMesh::new(dim, degree, 20.0, [0.0, 0.0, 0.0], 4, 2).unwrap();
            let loc = PointLocator::new(&ball).unwrap();
            for x in [[3.0, -7.5, 1.0], [-12.0, 4.0, -2.0], [0.0, 0.0, 0.0]] {
                let x = if dim == 2 { [x[0], x[1], 0.0] } else { x };
                let v = interpolate(&loc, &ball, x);
                assert!(
                    (v - affine(x)).abs() < 1e-11,
                    "{dim}D Q{degree} at {x:?}: {v}"
                );
            }
        }
    }

    /// The affine simplices' vertex solve is the inverse map: on the Gmsh Hertz half-disc (P2)
    /// the cells off the arc are marked affine and those with a mid-edge node on the arc
    /// (bulging by the sagitta, ~1e-3 of a cell) are not; for every affine cell and points
    /// inside it, ξ from the vertices equals Newton's and the ξ that made the point to 1e-12:
    /// both are exact up to the rounding of coordinates of size 1 over cells of about the
    /// grading's finest size hc = 0.03, ~2.2e-16/0.03 ≈ 1e-14 (measured ≤ 1.2e-14).
    #[test]
    fn affine_simplices_skip_newton_with_the_same_xi() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("sweeps/meshes/hertz_halfdisc.msh");
        let mesh = crate::space::fe::GmshMesh::read(&path).unwrap();
        let loc = PointLocator::new(&mesh).unwrap();
        let curved = loc.affine.iter().filter(|a| !**a).count();
        // The arc (34 + the top-free part's edges) bounds a few dozen cells; most are straight.
        assert!(curved > 0 && curved < mesh.num_elements() / 4, "{curved}");
        for (e, _) in loc.affine.iter().enumerate().filter(|(_, a)| **a) {
            for xi in [
                [0.2, 0.3, 0.0],
                [0.6, 0.1, 0.0],
                [1.0 / 3.0, 1.0 / 3.0, 0.0],
            ] {
                let mut n = [0.0; MAX_NODES];
                let mut dn = [[0.0; 3]; MAX_NODES];
                shape_into(loc.kind, xi, &mut n, &mut dn);
                let mut x = [0.0; 3];
                for (a, &node) in mesh.element_nodes(e).iter().enumerate() {
                    for k in 0..2 {
                        x[k] += n[a] * mesh.coord(node)[k];
                    }
                }
                let fast = loc.affine_inverse(e, x).unwrap();
                let newton = loc.inverse_map(e, x).unwrap();
                for k in 0..2 {
                    assert!(
                        (fast[k] - newton[k]).abs() < 1e-12,
                        "cell {e}: {fast:?} {newton:?}"
                    );
                    assert!((fast[k] - xi[k]).abs() < 1e-12, "cell {e}: {fast:?} {xi:?}");
                }
            }
        }
    }

    #[test]
    fn a_node_of_a_nested_mesh_takes_the_node_value() {
        // Nested boxes: every coarse node is a fine node, whose weight is 1 and the others'
        // round-off (the inverse map is exact on affine elements up to ~1e-16).
        let fine = BoxMesh::new(&[1.0, 2.0, 1.0], &[4, 8, 4]);
        let coarse = BoxMesh::new(&[1.0, 2.0, 1.0], &[2, 4, 2]);
        let loc = PointLocator::new(&fine).unwrap();
        let field = |n: usize| (n as f64 * 0.37).sin();
        for c in 0..coarse.num_nodes() {
            let x = coarse.coord(c);
            let v: f64 = loc
                .weights(x)
                .unwrap()
                .iter()
                .map(|&(n, w)| w * field(n))
                .sum();
            let same = (0..fine.num_nodes())
                .find(|&n| {
                    let y = fine.coord(n);
                    (0..3).all(|k| (x[k] - y[k]).abs() < 1e-14)
                })
                .unwrap();
            assert!((v - field(same)).abs() < 1e-12, "node {c}");
        }
    }

    #[test]
    fn a_boundary_node_of_a_coarser_disc_is_found_and_far_points_are_refused() {
        // The coarse disc's boundary nodes lie on the circle; the fine Q2 disc's curved edges
        // pass through its own boundary nodes, so a coarse boundary node lies O(h³) outside
        // it or inside it — found either way.
        let coarse = BallMesh::new(2, 2, 20.0, [0.0, 0.0, 0.0], 4, 2).unwrap();
        let fine = BallMesh::new(2, 2, 20.0, [0.0, 0.0, 0.0], 10, 5).unwrap();
        let loc = PointLocator::new(&fine).unwrap();
        for n in 0..coarse.num_nodes() {
            let x = coarse.coord(n);
            let l = loc.locate(x).unwrap();
            assert!(l.outside <= OUTSIDE_TOL, "{x:?}: {l:?}");
        }
        assert!(matches!(
            loc.locate([25.0, 0.0, 0.0]),
            Err(LocateError::Far { .. } | LocateError::Outside { .. })
        ));
        assert!(loc.locate([21.0, 0.0, 0.0]).is_err());
    }
}
