//! Nitsche's points between two bodies on a general interface (contract §2.6; issue 45): the
//! quadrature points of Γ^a and Γ^b placed by the interface geometry of
//! [`crate::space::fe::interface`] (the projection Π through its bin grid, the segmentation),
//! each carrying both bodies' traces in the form the one-body engine's operators take
//! ([`super::nitsche::NitscheOps::new`]) — the same rows as [`super::nitsche_pair`]'s matching
//! points, wherever the faces are.
//!
//! Placement. Side i's faces become a [`Surface`] (its cells' face vertices, so a Q1/P1 face is
//! the surface's bilinear/affine face exactly), the other side j's a [`Projector`] (set-up and
//! queries linear in the interface). A point of side i is x on face f_i at the face parameter
//! s_i, its weight, and Π(x) on face f_j at s_j:
//! - `segment`: the pieces of Γ^i's segmentation by Γ^j's projected faces ([`segment`]), each
//!   piece with a rule exact for the polynomial integrands on affine faces (the segmentation's
//!   own: 2 Gauss points on a sub-segment, 2 × 2 on a parallelogram — two boxes' faces overlap
//!   in rectangles —, the collapsed 3 × 3 rule on each triangle of another polygon): the patch
//!   test's integrands have degree ≤ 2 per direction on a piece (δ, σ_n^i and the test
//!   functions bilinear there). Why not the one-body faces' 3 points per direction on every
//!   piece: the condensed Newton is dense over the points (Q × Q), and the pieces already
//!   split each face in about (1 + ratio)^{d−1}. A piece that is its whole face (the matching
//!   case) takes the face's own rule (3 Gauss points per direction), so a matching interface is
//!   integrated exactly as the blocks' matching path does ([`super::nitsche_pair`]);
//! - `element`: Γ^i's own face rule, the other body at Π(x) — what GetFEM integrates; not exact
//!   where Γ^j's shape functions kink inside a face of Γ^i (the patch test shows it, §6).
//!
//! Traces. A face's parameter maps affinely (bilinearly on a square) to its cell's reference
//! coordinates through the face's reference vertices ([`ContactFace`]): ξ(s) = Σ_k N_k(s) ξ_k.
//! On a Q1/P1 cell the cell's trace is the surface's face map, so ξ(s_j) is the reference point
//! of Π(x) itself (no inverse map needed: Π is found on the face, in its parameter); on a
//! degree-2 cell whose face is straight the same holds, on a curved one Π is taken on the
//! face's straight (vertex) surface — an approximation of the curved Π, not used by the
//! blocks. Each point's rows are then made in one place ([`pair_point`]): its own element's
//! shape values and gradients (σ_n^i), the other element's shape values at ξ(s_j) (δ).
//!
//! Normals and gaps. n^i is side i's outward unit normal at x (the surface's, oriented away
//! from the own cell's centroid); δ^i(u) = (u^i(x) − u^j(Πx))·n^i, the same sign as the blocks'
//! δ = u^b_d − u^a_d; the point's gap is (Π(x) − x)·n^i minus the caller's `lowest` (the run's
//! gap is added where the operators are made, as for the blocks and the files' node rows).

use crate::scene::InterfaceQuadrature;
use crate::space::fe::element::{det_inv, physical_gradients, shape};
use crate::space::fe::interface::surface::{add, cross, dot, norm, scale, sub};
use crate::space::fe::interface::{FaceKind, Projector, Surface, closest_on_face, segment};
use crate::space::fe::nitsche::{ContactFace, ContactPoint};
use crate::space::fe::quadrature::{collapsed_simplex_rule, gauss_legendre_any};
use crate::space::fe::simplex::simplex_shape;
use crate::space::fe::sparse::element_coords;
use crate::space::fe::{Mesh, element::jacobian};

/// The two sides' faces of a general interface, kept with a two-body geometry until a Nitsche
/// run asks for its points ([`PairFaces::points`]).
#[derive(Debug, Clone)]
pub(super) struct PairFaces {
    /// Γ^a's and Γ^b's faces, cells of the joined mesh.
    pub(super) faces: [Vec<ContactFace>; 2],
    /// The largest distance at which the faces face each other (the projection's reach).
    pub(super) reach: f64,
    /// Subtracted from every point's gap: the closest pair's distance (module header).
    pub(super) lowest: f64,
}

impl PairFaces {
    /// Both sides' points on `mesh` (A's then B's nodes and cells), dofs global: module header.
    pub(super) fn points(
        &self,
        mesh: &dyn Mesh,
        lame: [(f64, f64); 2],
        rule: InterfaceQuadrature,
    ) -> Result<[Vec<ContactPoint>; 2], String> {
        let faces = [&self.faces[0][..], &self.faces[1][..]];
        interface_points(mesh, faces, lame, rule, self.reach, self.lowest)
    }
}

/// A face of one side on the joined mesh: its cell, the face's reference vertices in the
/// cell, and the surface's outward orientation (+1 or −1 times the surface normal).
struct SideGeometry<'f> {
    faces: &'f [ContactFace],
    surface: Surface,
    orient: Vec<f64>,
}

/// Side `faces` of `mesh` as a surface (module header): the vertices' nodes found as the
/// cell's nodes whose shape function is 1 at the vertex (a nodal basis), shared between faces.
fn side_geometry<'f>(
    mesh: &dyn Mesh,
    faces: &'f [ContactFace],
    side: char,
) -> Result<SideGeometry<'f>, String> {
    let d = mesh.dim();
    let mut local = vec![usize::MAX; mesh.num_nodes()];
    let mut coords = Vec::new();
    let mut conn = Vec::new();
    let mut orient = Vec::with_capacity(faces.len());
    let mut kind = FaceKind::Seg2;
    for face in faces {
        let nodes = mesh.element_nodes(face.element);
        kind = match (d, face.vertices.len()) {
            (2, _) => FaceKind::Seg2,
            (_, 3) => FaceKind::Tri3,
            _ => FaceKind::Quad4,
        };
        for v in &face.vertices {
            let t = trace(mesh, face.element, *v);
            let a = (0..t.n.len())
                .max_by(|&p, &q| t.n[p].total_cmp(&t.n[q]))
                .expect("a cell has nodes");
            let g = nodes[a];
            if local[g] == usize::MAX {
                local[g] = coords.len();
                coords.push(mesh.coord(g));
            }
            conn.push(local[g]);
        }
    }
    let surface = Surface::new(side, kind, coords, conn).map_err(|e| e.to_string())?;
    for (f, face) in faces.iter().enumerate() {
        let nodes = mesh.element_nodes(face.element);
        let mut c = [0.0; 3];
        for &n in nodes {
            let x = mesh.coord(n);
            (0..3).for_each(|k| c[k] += x[k] / nodes.len() as f64);
        }
        let centre = surface.point(f, kind.centre());
        let s = dot(surface.normal(f), sub(centre, c));
        orient.push(if s < 0.0 { -1.0 } else { 1.0 });
    }
    Ok(SideGeometry {
        faces,
        surface,
        orient,
    })
}

impl SideGeometry<'_> {
    /// The cell's reference coordinates of face `f`'s parameter `s` (module header).
    fn reference(&self, f: usize, s: [f64; 2]) -> [f64; 3] {
        let n = self.surface.kind.shape(s);
        let mut xi = [0.0; 3];
        for (k, v) in self.faces[f].vertices.iter().enumerate() {
            for c in 0..3 {
                xi[c] += n[k] * v[c];
            }
        }
        xi
    }

    /// The outward unit normal of face `f` at `s`.
    fn normal(&self, f: usize, s: [f64; 2]) -> [f64; 3] {
        let [t, u] = self.surface.tangents(f, s);
        let n = match self.surface.kind {
            FaceKind::Seg2 => [t[1], -t[0], 0.0],
            _ => cross(t, u),
        };
        scale(n, self.orient[f] / norm(n))
    }
}

/// Shape values, physical gradients (padded to 3 components) and the diameter of a cell at ξ.
pub(super) struct Trace {
    pub(super) n: Vec<f64>,
    pub(super) g: Vec<[f64; 3]>,
    pub(super) diameter: f64,
    pub(super) dofs: Vec<usize>,
}

/// The trace of element `e` of `mesh` at reference point ξ (any cell the meshes hold).
pub(super) fn trace(mesh: &dyn Mesh, e: usize, xi: [f64; 3]) -> Trace {
    match (mesh.dim(), mesh.nodes_per_element()) {
        (2, 4) => trace_generic::<2, 4>(mesh, e, xi, shape::<2, 4>),
        (2, 9) => trace_generic::<2, 9>(mesh, e, xi, shape::<2, 9>),
        (3, 8) => trace_generic::<3, 8>(mesh, e, xi, shape::<3, 8>),
        (3, 27) => trace_generic::<3, 27>(mesh, e, xi, shape::<3, 27>),
        (2, 3) => trace_generic::<2, 3>(mesh, e, xi, simplex_shape::<2, 3>),
        (2, 6) => trace_generic::<2, 6>(mesh, e, xi, simplex_shape::<2, 6>),
        (3, 4) => trace_generic::<3, 4>(mesh, e, xi, simplex_shape::<3, 4>),
        (3, 10) => trace_generic::<3, 10>(mesh, e, xi, simplex_shape::<3, 10>),
        (d, k) => unreachable!("no element of dimension {d} with {k} nodes"),
    }
}

type ShapeFn<const D: usize, const NN: usize> = fn([f64; D]) -> ([f64; NN], [[f64; D]; NN]);

fn trace_generic<const D: usize, const NN: usize>(
    mesh: &dyn Mesh,
    e: usize,
    xi: [f64; 3],
    shape_at: ShapeFn<D, NN>,
) -> Trace {
    let x: [[f64; D]; NN] = element_coords(mesh, e);
    let mut r = [0.0; D];
    r.copy_from_slice(&xi[..D]);
    let (n, dn) = shape_at(r);
    let (_, jinv) = det_inv(&jacobian(&x, &dn));
    let g = physical_gradients(&jinv, &dn);
    let mut diameter: f64 = 0.0;
    for a in 0..NN {
        for b in a + 1..NN {
            let s: f64 = (0..D).map(|i| (x[a][i] - x[b][i]).powi(2)).sum();
            diameter = diameter.max(s.sqrt());
        }
    }
    let dofs = mesh
        .element_nodes(e)
        .iter()
        .flat_map(|&node| (0..D).map(move |i| node * D + i))
        .collect();
    Trace {
        n: n.to_vec(),
        g: g.iter()
            .map(|ga| {
                let mut p = [0.0; 3];
                p[..D].copy_from_slice(ga);
                p
            })
            .collect(),
        diameter,
        dofs,
    }
}

/// One point of side `own_side` (0 = A, 1 = B): the engine's rows over the dofs of both
/// elements, A's then B's — δ^i = (u^i(x) − u^j(Πx))·n^i (own shape values times n, the other
/// element's negated) and σ_n^i = λ div u + 2μ n·∇u n over the own element (zero on the
/// other's). Friction's tangential rows (ut, st) belong here too, made from the same traces.
pub(super) fn pair_point(
    own: &Trace,
    other: &Trace,
    own_side: usize,
    normal: [f64; 3],
    (lambda, mu): (f64, f64),
    weight: f64,
    gap: f64,
) -> ContactPoint {
    let d = own.dofs.len() / own.n.len();
    let row = |t: &Trace, sign: f64| -> Vec<f64> {
        let mut r = vec![0.0; t.dofs.len()];
        for (a, &na) in t.n.iter().enumerate() {
            for c in 0..d {
                r[a * d + c] = sign * na * normal[c];
            }
        }
        r
    };
    let mut sn_own = vec![0.0; own.dofs.len()];
    for (a, ga) in own.g.iter().enumerate() {
        let gn: f64 = (0..d).map(|c| ga[c] * normal[c]).sum();
        for c in 0..d {
            sn_own[a * d + c] = lambda * ga[c] + 2.0 * mu * normal[c] * gn;
        }
    }
    let zeros = vec![0.0; other.dofs.len()];
    let (un_own, un_other) = (row(own, 1.0), row(other, -1.0));
    let ((dofs_a, dofs_b), (un_a, un_b), (sn_a, sn_b)) = if own_side == 0 {
        (
            (&own.dofs, &other.dofs),
            (un_own, un_other),
            (sn_own, zeros),
        )
    } else {
        (
            (&other.dofs, &own.dofs),
            (un_other, un_own),
            (zeros, sn_own),
        )
    };
    ContactPoint {
        weight,
        gamma: own.diameter,
        gap,
        dofs: dofs_a.iter().chain(dofs_b).copied().collect(),
        un: un_a.into_iter().chain(un_b).collect(),
        sn: sn_a.into_iter().chain(sn_b).collect(),
        ut: Vec::new(),
        st: Vec::new(),
    }
}

/// Where one point sits: face and parameter on side i, weight, face and parameter of Π(x) on
/// side j.
#[derive(Debug, Clone, Copy)]
struct Placement {
    face: usize,
    s: [f64; 2],
    weight: f64,
    other_face: usize,
    other_s: [f64; 2],
}

/// A rule in the surface's parameter with `n` Gauss points per direction (the collapsed n × n
/// rule on a triangle); n = 3 is the one-body faces' rule (contract §2.3).
fn face_rule(kind: FaceKind, n: usize) -> Vec<([f64; 2], f64)> {
    let g: Vec<(f64, f64)> = gauss_legendre_any(n)
        .into_iter()
        .map(|(t, w)| (0.5 * (t + 1.0), 0.5 * w))
        .collect();
    match kind {
        FaceKind::Seg2 => g.iter().map(|&(s, w)| ([s, 0.0], w)).collect(),
        FaceKind::Tri3 => collapsed_simplex_rule(2, n)
            .into_iter()
            .map(|(p, w)| ([p[0], p[1]], w))
            .collect(),
        FaceKind::Quad4 => g
            .iter()
            .flat_map(|&(t, wt)| g.iter().map(move |&(s, ws)| ([s, t], ws * wt)))
            .collect(),
    }
}

/// `element`: side i's face rule, Π(x) by the projector; points with no projection within the
/// reach (Γ^i beyond Γ^j) carry no contact.
fn element_placements(side: &Surface, other: &Projector) -> Vec<Placement> {
    let rule = face_rule(side.kind, 3);
    let mut out = Vec::with_capacity(side.num_faces() * rule.len());
    for f in 0..side.num_faces() {
        for &(s, w) in &rule {
            if let Ok(p) = other.project(side.point(f, s)) {
                out.push(Placement {
                    face: f,
                    s,
                    weight: w * side.jacobian(f, s),
                    other_face: p.face,
                    other_s: p.xi,
                });
            }
        }
    }
    out
}

/// `segment`: the pieces of side i's segmentation (module header's rules).
fn segment_placements(side: &Surface, other: &Projector) -> Result<Vec<Placement>, String> {
    let seg = segment(side, other).map_err(|e| e.to_string())?;
    let b = other.surface();
    let mut count = vec![0usize; side.num_faces()];
    seg.pieces.iter().for_each(|p| count[p.face_a] += 1);
    let face = face_rule(side.kind, 3);
    let square = face_rule(FaceKind::Quad4, 2);
    let on_segment = face_rule(FaceKind::Seg2, 2);
    let on_triangle = face_rule(FaceKind::Tri3, 3);
    let mut out = Vec::new();
    let mut push = |f: usize, fb: usize, x: [f64; 3], s: [f64; 2], w: f64| -> Result<(), String> {
        let (other_s, _) = closest_on_face(b, fb, x).map_err(|e| e.to_string())?;
        out.push(Placement {
            face: f,
            s,
            weight: w,
            other_face: fb,
            other_s,
        });
        Ok(())
    };
    for piece in &seg.pieces {
        let f = piece.face_a;
        let whole = count[f] == 1 && seg.covered[f] >= (1.0 - 1e-12) * seg.measure[f];
        let v = &piece.vertices;
        if whole {
            for &(s, w) in &face {
                let x = side.point(f, s);
                push(f, piece.face_b, x, s, w * side.jacobian(f, s))?;
            }
        } else if v.len() == 2 {
            let len = norm(sub(v[1], v[0]));
            for &(t, w) in &on_segment {
                let x = add(v[0], scale(sub(v[1], v[0]), t[0]));
                let s = closest_on_face(side, f, x).map_err(|e| e.to_string())?.0;
                push(f, piece.face_b, x, s, w * len)?;
            }
        } else if let Some((e1, e2)) = parallelogram(v) {
            // A parallelogram piece (two boxes' faces overlap in a rectangle): the face rule
            // on its own bilinear map, half the points of its two triangles.
            let area = norm(cross(e1, e2));
            for &(t, w) in &square {
                let x = add(v[0], add(scale(e1, t[0]), scale(e2, t[1])));
                let s = closest_on_face(side, f, x).map_err(|e| e.to_string())?.0;
                push(f, piece.face_b, x, s, w * area)?;
            }
        } else {
            for k in 1..v.len() - 1 {
                let (e1, e2) = (sub(v[k], v[0]), sub(v[k + 1], v[0]));
                let twice = norm(cross(e1, e2));
                for &(t, w) in &on_triangle {
                    let x = add(v[0], add(scale(e1, t[0]), scale(e2, t[1])));
                    let s = closest_on_face(side, f, x).map_err(|e| e.to_string())?.0;
                    // A warped face of side i: the piece lies on its centre plane; the ratio of
                    // the surface's Jacobian to the plane's is left out (flat faces: 1).
                    push(f, piece.face_b, x, s, w * twice)?;
                }
            }
        }
    }
    Ok(out)
}

/// The edges v1 − v0, v3 − v0 of a 4-vertex piece that is a parallelogram (v0 + v2 = v1 + v3
/// to round-off of its size).
fn parallelogram(v: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    if v.len() != 4 {
        return None;
    }
    let (e1, e2) = (sub(v[1], v[0]), sub(v[3], v[0]));
    let off = norm(sub(add(v[0], v[2]), add(v[1], v[3])));
    (off <= 1e-12 * (norm(e1) + norm(e2))).then_some((e1, e2))
}

/// Both sides' points [Γ^a, Γ^b] on the joined `mesh` (A's nodes and cells, then B's) with
/// γ0 = 1 (their `gamma` is h_K), unit side weights, gaps (Π(x) − x)·n^i − `lowest` and global
/// dofs: module header. `faces` are Γ^a's and Γ^b's faces (cells of the joined mesh), `lame`
/// each body's (λ, μ), `reach` the largest distance at which the faces face each other.
pub(super) fn interface_points(
    mesh: &dyn Mesh,
    faces: [&[ContactFace]; 2],
    lame: [(f64, f64); 2],
    rule: InterfaceQuadrature,
    reach: f64,
    lowest: f64,
) -> Result<[Vec<ContactPoint>; 2], String> {
    let sides = [
        side_geometry(mesh, faces[0], 'a')?,
        side_geometry(mesh, faces[1], 'b')?,
    ];
    let mut out = [Vec::new(), Vec::new()];
    for i in 0..2 {
        let (own, other) = (&sides[i], &sides[1 - i]);
        let projector = Projector::new(&other.surface, reach);
        let placed = match rule {
            InterfaceQuadrature::Element => element_placements(&own.surface, &projector),
            InterfaceQuadrature::Segment => segment_placements(&own.surface, &projector)?,
        };
        if placed.is_empty() {
            return Err(format!(
                "nitsche between two bodies: no point of Γ^{} faces Γ^{} within {reach:e}",
                ['a', 'b'][i],
                ['a', 'b'][1 - i]
            ));
        }
        out[i] = placed
            .iter()
            .map(|p| {
                let x = own.surface.point(p.face, p.s);
                let y = other.surface.point(p.other_face, p.other_s);
                let n = own.normal(p.face, p.s);
                let t_own = trace(mesh, own.faces[p.face].element, own.reference(p.face, p.s));
                let t_other = trace(
                    mesh,
                    other.faces[p.other_face].element,
                    other.reference(p.other_face, p.other_s),
                );
                let gap = dot(sub(y, x), n) - lowest;
                pair_point(&t_own, &t_other, i, n, lame[i], p.weight, gap)
            })
            .collect();
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::nitsche_pair::{blocks_interface, pair_points};
    use super::*;
    use crate::space::fe::{BodiesMesh, BoxMesh};

    /// A (W × 1, `na` across, 2 up) on B (W × ½, `nb` across, 1 up), touching at x_d = ½, and
    /// their joined mesh.
    fn blocks(d: usize, na: usize, nb: usize) -> (BoxMesh, BoxMesh, BodiesMesh) {
        let w = 1.5;
        let (mut ext, mut cells) = (vec![w; d], vec![na; d]);
        ext[d - 1] = 1.0;
        cells[d - 1] = 2;
        let mut a = BoxMesh::new(&ext, &cells);
        a.coords.iter_mut().for_each(|c| c[d - 1] += 0.5);
        let mut cells_b = vec![nb; d];
        ext[d - 1] = 0.5;
        cells_b[d - 1] = 1;
        let b = BoxMesh::new(&ext, &cells_b);
        let m = BodiesMesh::new(&[&a, &b]);
        (a, b, m)
    }

    const LAME: [(f64, f64); 2] = [(0.5, 1.0), (2.0, 3.0)];

    /// On matching blocks both rules place the blocks' matching points (the same faces, rule,
    /// order and dofs): weights, h_K, gaps and rows equal to round-off (the other element's
    /// reference point comes from the face parameter, ±1 exact there: measured 0 or 1 ulp).
    #[test]
    fn matching_blocks_give_the_matching_points() {
        for d in [2usize, 3] {
            let (a, b, m) = blocks(d, 3, 3);
            let old = pair_points(&a, &b, a.coords.len(), LAME);
            for rule in [InterfaceQuadrature::Segment, InterfaceQuadrature::Element] {
                let new = blocks_interface(&a, &b).points(&m, LAME, rule).unwrap();
                for (o, n) in old.iter().zip(&new) {
                    assert_eq!(o.len(), n.len(), "{d}D {rule:?}");
                    for (p, q) in o.iter().zip(n) {
                        assert_eq!(p.dofs, q.dofs);
                        assert!((p.weight - q.weight).abs() <= 1e-15 * p.weight);
                        assert!((p.gamma - q.gamma).abs() <= 1e-15 * p.gamma);
                        assert!(q.gap.abs() <= 1e-15, "{}", q.gap);
                        for (r, s) in [(&p.un, &q.un), (&p.sn, &q.sn)] {
                            let scale = r.iter().fold(0.0f64, |x, v| x.max(v.abs()));
                            for (x, y) in r.iter().zip(s) {
                                assert!((x - y).abs() <= 1e-14 * scale, "{x} {y}");
                            }
                        }
                    }
                }
            }
        }
    }

    /// Σ_q w_q row_q(e_g) over a side's points, per global dof g (the row's integral).
    fn integrals(points: &[ContactPoint], n: usize, row: fn(&ContactPoint) -> &[f64]) -> Vec<f64> {
        let mut s = vec![0.0; n];
        for p in points {
            for (&g, c) in p.dofs.iter().zip(row(p)) {
                s[g] += p.weight * c;
            }
        }
        s
    }

    /// ∫_Γ N_j of every node of a face set of the boxes (a Q1 face gives each of its 2^{d−1}
    /// nodes its measure over 2^{d−1}), on the e_d dofs, signed: + for B, − for A (δ's rows).
    fn face_integrals(m: &BodiesMesh, d: usize, level: f64) -> Vec<f64> {
        let mut s = vec![0.0; m.num_nodes() * d];
        for e in 0..m.num_elements() {
            let nodes: Vec<usize> = m
                .element_nodes(e)
                .iter()
                .copied()
                .filter(|&n| (m.coord(n)[d - 1] - level).abs() < 1e-12)
                .collect();
            if nodes.len() < 1 << (d - 1) {
                continue;
            }
            let x = |k: usize| m.coord(nodes[k]);
            let mut measure = (x(1)[0] - x(0)[0]).abs();
            if d == 3 {
                measure *= (x(2)[1] - x(0)[1]).abs();
            }
            let sign = if m.element_body(e) == 0 { -1.0 } else { 1.0 };
            for &n in &nodes {
                s[n * d + d - 1] += sign * measure / nodes.len() as f64;
            }
        }
        s
    }

    /// Non-matching blocks (3 against 4 cells across, 3 × 3 against 4 × 4): on each side's
    /// points the integral of δ's row is ±∫_Γ N_j for every node of both bodies — exact on the
    /// segmentation (each piece's integrand one polynomial: round-off, 1e-14 of the face
    /// measures; measured 4.4e-16 (2D), 6.7e-16 (3D)), not with the element rule (B's shape
    /// functions kink inside A's faces: measured 6.5e-2 (2D), 0.10 (3D); asserted ≥ 1e-4). Both rules: for u linear on each body
    /// δ and σ_n are exact at every point (Q1 holds linear fields, Π is exact on flat faces),
    /// and a rigid translation has δ = σ_n = 0 (action = reaction).
    #[test]
    fn nonmatching_segment_integrates_exactly() {
        for d in [2usize, 3] {
            let (a, b, m) = blocks(d, 3, 4);
            let n = m.num_nodes() * d;
            let exact = face_integrals(&m, d, 0.5);
            let scale = exact.iter().fold(0.0f64, |x, v| x.max(v.abs()));
            for rule in [InterfaceQuadrature::Segment, InterfaceQuadrature::Element] {
                let sides = blocks_interface(&a, &b).points(&m, LAME, rule).unwrap();
                let mut worst: f64 = 0.0;
                for pts in &sides {
                    let got = integrals(pts, n, |p| &p.un);
                    for (g, e) in got.iter().zip(&exact) {
                        worst = worst.max((g - e).abs() / scale);
                    }
                    check_fields(pts, &m, d);
                }
                eprintln!("{d}D {rule:?}: ∫δ rows off by {worst:e} of the face measures");
                match rule {
                    InterfaceQuadrature::Segment => assert!(worst <= 1e-14, "{worst:e}"),
                    InterfaceQuadrature::Element => assert!(worst >= 1e-4, "{worst:e}"),
                }
            }
        }
    }

    /// u = x_1 e_d on A, (2x_1 + 0.3x_d) e_d on B: δ = u^b_d − u^a_d = x_1 + 0.15 (x_d = ½ on
    /// Γ), σ_n = 0 on A's side and 0.3(λ_b + 2μ_b) on B's; translations give 0. Round-off on
    /// O(1) values.
    fn check_fields(pts: &[ContactPoint], m: &BodiesMesh, d: usize) {
        let mut u = vec![0.0; m.num_nodes() * d];
        for node in 0..m.num_nodes() {
            let x = m.coord(node);
            u[node * d + d - 1] = if m.node_body(node) == 0 {
                x[0]
            } else {
                2.0 * x[0] + 0.3 * x[d - 1]
            };
        }
        let apply = |p: &ContactPoint, row: &[f64], v: &[f64]| -> f64 {
            row.iter().zip(&p.dofs).map(|(c, &g)| c * v[g]).sum()
        };
        let (lb, mb) = LAME[1];
        for p in pts {
            // The point's x_1: A's part of δ's row applied to x_1 e_d, negated (n = ∓e_d).
            let own_b = p.sn[..p.sn.len() / 2].iter().all(|&c| c == 0.0);
            let mut xa = vec![0.0; u.len()];
            for node in 0..m.num_nodes() {
                if m.node_body(node) == 0 {
                    xa[node * d + d - 1] = -m.coord(node)[0];
                }
            }
            let place = apply(p, &p.un, &xa);
            assert!((apply(p, &p.un, &u) - (place + 0.15)).abs() < 1e-13);
            let sigma = if own_b { 0.3 * (lb + 2.0 * mb) } else { 0.0 };
            assert!((apply(p, &p.sn, &u) - sigma).abs() < 1e-12);
            for r in 0..d {
                let mut t = vec![0.0; u.len()];
                t.iter_mut().skip(r).step_by(d).for_each(|x| *x = 1.0);
                assert!(apply(p, &p.un, &t).abs() < 1e-14);
                assert!(apply(p, &p.sn, &t).abs() < 1e-12);
            }
        }
    }
}
