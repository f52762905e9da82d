//! The segmentation of Γ^a by the projected faces of Γ^b (contract §2.6): pieces each lying in
//! one face of Γ^a and whose projection Π lies in one face of Γ^b, so that every mortar
//! integrand is one polynomial on a piece and a fixed rule integrates it exactly.
//!
//! Π maps x to the closest point of Γ^b (`projection.rs`); where that point is inside a flat
//! face f_b of normal n_b, Π(x) = x − ((x − y₀)·n_b) n_b, an affine map. The points of a flat
//! face f_a of Γ^a that Π sends into f_b are therefore the projection of f_b onto f_a's plane
//! *along n_b* (y ↦ y − ((y − c_a)·n_a)/(n_b·n_a) n_b), intersected with f_a:
//!
//! - 2D: the two nodes of f_b projected on the line of f_a bound an interval of f_a's
//!   parameter; its intersection with [0, 1] is the piece. Over all pairs these are exactly the
//!   sub-segments between the breakpoints of both sides (Γ^b's nodes projected on Γ^a, Γ^a's
//!   own nodes).
//! - 3D: f_a and the projected f_b, both convex polygons in f_a's plane, are clipped by
//!   Sutherland–Hodgman; the convex intersection is kept as a polygon and fanned into triangles
//!   when its points are made.
//!
//! On a piece, φ^a_i is affine (triangles) or bilinear in x (parallelograms), and so is
//! φ^b_j∘Π: the integrands ψ_k φ^a_i, ψ_k φ^b_j∘Π and ψ_k g have degree ≤ 2 on segments and
//! triangles and ≤ 4 with a parallelogram on either side. The rules: 2-point Gauss on a
//! sub-segment (degree 3), the collapsed Gauss rule on each triangle of a polygon with 2 × 2
//! points (degree 3) between triangles and 3 × 3 (degree 5) when a side has quadrilaterals. A
//! warped quadrilateral (non-affine) is integrated on its centre plane with the surface Jacobian
//! ratio |x_ξ × x_η|/J_plane at each point: accurate, not exact.
//!
//! Where a 2D Γ^b turns convexly at a node y (a polyline on a disc), the points of Γ^a whose
//! closest point is y itself — the node's normal cone, between the projections of its two
//! faces — form one more piece, with Π ≡ y (φ^b_j∘Π = δ_jy: exact too). In 3D the ridges and
//! corners of a curved Γ^b are not covered this way yet (their strips are O(gap·angle) wide):
//! the coverage of each face of Γ^a is reported so a
//! caller can refuse an interface that leaves Γ^b, and two faces of Γ^b projecting on the same
//! part of Γ^a (Γ^b folding back, or concave, within the reach: the closest point would switch
//! faces inside a piece) are refused.

use super::super::quadrature::{collapsed_simplex_rule, gauss_legendre_any};
use super::projection::{NEWTON_TOL, Projector, closest_on_face};
use super::surface::{FaceKind, InterfaceError, Surface, add, cross, dot, norm, scale, sub};

/// Smallest |n_a·n_b| of a face pair that can face each other (~84°): steeper pairs project
/// onto a sliver or not at all.
const MIN_COS: f64 = 0.1;
/// A piece of measure below this fraction of its face of Γ^a is round-off of a shared edge or
/// node (matching meshes put Γ^b's edges on Γ^a's): dropped.
const SLIVER: f64 = 1e-14;
/// Relative excess of a face's covered measure over its own that means two faces of Γ^b
/// project on the same part of it (not round-off).
const OVERLAP: f64 = 1e-9;

/// One piece: a sub-segment (2 vertices) or a convex polygon (≥ 3 vertices, counter-clockwise
/// about f_a's normal) in face `face_a` of Γ^a, projected by Π into face `face_b` of Γ^b.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    pub face_a: usize,
    pub face_b: usize,
    pub vertices: Vec<[f64; 3]>,
}

/// An integration point of a piece: x on Γ^a, Π(x) on Γ^b, both faces' reference coordinates,
/// the weight (the measure of Γ^a it stands for) and f_a's unit normal at x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PiecePoint {
    pub x: [f64; 3],
    pub xi_a: [f64; 2],
    pub pi: [f64; 3],
    pub xi_b: [f64; 2],
    pub weight: f64,
    pub normal: [f64; 3],
}

/// The pieces of Γ^a, and how much of each face of Γ^a they cover.
#[derive(Debug, Clone, PartialEq)]
pub struct Segmentation {
    pub pieces: Vec<Piece>,
    /// Measure of each face of Γ^a covered by pieces.
    pub covered: Vec<f64>,
    /// Measure of each face of Γ^a.
    pub measure: Vec<f64>,
    /// The rule on a reference piece (unit interval or unit triangle): points, weights.
    rule: Vec<([f64; 3], f64)>,
}

/// An orthonormal frame of a face of Γ^a: centre, normal, two tangents.
#[derive(Debug, Clone, Copy)]
struct Frame {
    c: [f64; 3],
    n: [f64; 3],
    e1: [f64; 3],
    e2: [f64; 3],
}

impl Frame {
    fn of(a: &Surface, f: usize) -> Frame {
        let c = a.point(f, a.kind.centre());
        let n = a.normal(f);
        let t = a.tangents(f, a.kind.centre())[0];
        let t = sub(t, scale(n, dot(t, n)));
        let e1 = scale(t, 1.0 / norm(t));
        Frame {
            c,
            n,
            e1,
            e2: cross(n, e1),
        }
    }

    fn uv(&self, x: [f64; 3]) -> [f64; 2] {
        let r = sub(x, self.c);
        [dot(r, self.e1), dot(r, self.e2)]
    }

    fn at(&self, uv: [f64; 2]) -> [f64; 3] {
        add(self.c, add(scale(self.e1, uv[0]), scale(self.e2, uv[1])))
    }

    /// y moved along `dir` onto the plane (dir·n ≠ 0).
    fn along(&self, y: [f64; 3], dir: [f64; 3]) -> [f64; 3] {
        sub(
            y,
            scale(dir, dot(sub(y, self.c), self.n) / dot(dir, self.n)),
        )
    }
}

/// The segmentation of Γ^a against Γ^b's projector (module header).
pub fn segment(a: &Surface, proj: &Projector) -> Result<Segmentation, InterfaceError> {
    let b = proj.surface();
    if a.kind.dim() != b.kind.dim() {
        return Err(InterfaceError::MixedDimensions {
            a: a.kind,
            b: b.kind,
        });
    }
    let mut pieces = Vec::new();
    let mut covered = vec![0.0; a.num_faces()];
    let mut measure = vec![0.0; a.num_faces()];
    let mut cands = Vec::new();
    let next = successors(b);
    for fa in 0..a.num_faces() {
        let frame = Frame::of(a, fa);
        let (lo, hi) = a.face_box(fa, 0.0);
        proj.candidates(lo, hi, &mut cands);
        measure[fa] = polygon_measure(&face_polygon(a, fa), &frame);
        for &fb in &cands {
            let n_b = b.normal(fb);
            let poly = if dot(n_b, frame.n).abs() < MIN_COS {
                None
            } else if a.kind == FaceKind::Seg2 {
                clip_segment(a, fa, b, fb)
            } else {
                clip_polygon(a, fa, &frame, b, fb, n_b)
            };
            // 2D: the corner where f_b meets the next face, if Γ^b turns convexly there.
            let corner = next[fb].and_then(|g| clip_corner(a, fa, b, fb, g));
            for vertices in poly.into_iter().chain(corner) {
                let m = polygon_measure(&vertices, &frame);
                // Within the reach: the piece's centre is that far from its projection.
                let c = vertices.iter().fold([0.0; 3], |s, &v| add(s, v));
                let c = scale(c, 1.0 / vertices.len() as f64);
                let gap = norm(sub(closest_on_face(b, fb, c)?.1, c));
                if m > SLIVER * measure[fa] && gap <= proj.reach() {
                    covered[fa] += m;
                    pieces.push(Piece {
                        face_a: fa,
                        face_b: fb,
                        vertices,
                    });
                }
            }
        }
        if covered[fa] > measure[fa] * (1.0 + OVERLAP) {
            return Err(InterfaceError::Overlap {
                face: fa,
                covered: covered[fa],
                measure: measure[fa],
            });
        }
    }
    let quads = a.kind == FaceKind::Quad4 || b.kind == FaceKind::Quad4;
    let rule = match a.kind {
        FaceKind::Seg2 => gauss_legendre_any(2)
            .into_iter()
            .map(|(t, w)| ([0.5 * (t + 1.0), 0.0, 0.0], 0.5 * w))
            .collect(),
        _ => collapsed_simplex_rule(2, if quads { 3 } else { 2 }),
    };
    Ok(Segmentation {
        pieces,
        covered,
        measure,
        rule,
    })
}

/// The nodes of face f of a side in order (a polygon; a segment's two ends).
fn face_polygon(s: &Surface, f: usize) -> Vec<[f64; 3]> {
    s.face(f).iter().map(|&n| s.coords[n]).collect()
}

/// Length of a 2-vertex piece, area (in the frame's plane) of a polygon.
fn polygon_measure(v: &[[f64; 3]], frame: &Frame) -> f64 {
    if v.len() == 2 {
        return norm(sub(v[1], v[0]));
    }
    signed_area(&v.iter().map(|&x| frame.uv(x)).collect::<Vec<_>>()).abs()
}

fn signed_area(p: &[[f64; 2]]) -> f64 {
    let mut s = 0.0;
    for i in 0..p.len() {
        let (u, v) = (p[i], p[(i + 1) % p.len()]);
        s += u[0] * v[1] - u[1] * v[0];
    }
    0.5 * s
}

/// 2D: the sub-segment of f_a that Π sends into f_b (the nodes of f_b projected along n_b on
/// f_a's line bound it).
fn clip_segment(a: &Surface, fa: usize, b: &Surface, fb: usize) -> Option<Vec<[f64; 3]>> {
    let (x0, x1) = (a.coords[a.face(fa)[0]], a.coords[a.face(fa)[1]]);
    let (y0, y1) = (b.coords[b.face(fb)[0]], b.coords[b.face(fb)[1]]);
    let (e, t) = (sub(x1, x0), sub(y1, y0));
    // x0 + s e − y_k ∥ n_b ⇔ (x0 + s e − y_k)·t = 0.
    let s_of = |y: [f64; 3]| dot(sub(y, x0), t) / dot(e, t);
    let (s0, s1) = (s_of(y0), s_of(y1));
    let (lo, hi) = (s0.min(s1).max(0.0), s0.max(s1).min(1.0));
    (hi > lo).then(|| vec![add(x0, scale(e, lo)), add(x0, scale(e, hi))])
}

/// 2D: for each face of Γ^b, the face that starts where it ends (a consistently oriented
/// polyline); none in 3D.
fn successors(b: &Surface) -> Vec<Option<usize>> {
    let mut out = vec![None; b.num_faces()];
    if b.kind != FaceKind::Seg2 {
        return out;
    }
    let mut starting = vec![None; b.num_nodes()];
    for f in 0..b.num_faces() {
        starting[b.face(f)[0]] = Some(f);
    }
    for (f, slot) in out.iter_mut().enumerate() {
        *slot = starting[b.face(f)[1]];
    }
    out
}

/// 2D: the sub-segment of f_a whose closest point on Γ^b is the node y where f_b ends and g
/// begins: (x − y)·t_f ≥ 0 and (x − y)·t_g ≤ 0 (the node's normal cone, empty unless Γ^b turns
/// convexly at y). Π is constant there; the piece's points find it by clamping on f_b.
fn clip_corner(a: &Surface, fa: usize, b: &Surface, fb: usize, g: usize) -> Option<Vec<[f64; 3]>> {
    let (x0, x1) = (a.coords[a.face(fa)[0]], a.coords[a.face(fa)[1]]);
    let e = sub(x1, x0);
    let y = b.coords[b.face(fb)[1]];
    let t_f = sub(y, b.coords[b.face(fb)[0]]);
    let t_g = sub(b.coords[b.face(g)[1]], y);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    // Each condition is α + β s ≥ 0 along x = x0 + s e.
    for (alpha, beta) in [
        (dot(sub(x0, y), t_f), dot(e, t_f)),
        (-dot(sub(x0, y), t_g), -dot(e, t_g)),
    ] {
        if beta == 0.0 {
            if alpha < 0.0 {
                return None;
            }
        } else if beta > 0.0 {
            lo = lo.max(-alpha / beta);
        } else {
            hi = hi.min(-alpha / beta);
        }
    }
    (hi > lo).then(|| vec![add(x0, scale(e, lo)), add(x0, scale(e, hi))])
}

/// 3D: f_a ∩ (f_b projected along n_b on f_a's plane), by Sutherland–Hodgman (both convex).
fn clip_polygon(
    a: &Surface,
    fa: usize,
    frame: &Frame,
    b: &Surface,
    fb: usize,
    n_b: [f64; 3],
) -> Option<Vec<[f64; 3]>> {
    let ccw = |mut p: Vec<[f64; 2]>| {
        if signed_area(&p) < 0.0 {
            p.reverse();
        }
        p
    };
    let clip = ccw(face_polygon(a, fa).iter().map(|&x| frame.uv(x)).collect());
    let mut poly = ccw(face_polygon(b, fb)
        .iter()
        .map(|&y| frame.uv(frame.along(y, n_b)))
        .collect());
    for i in 0..clip.len() {
        let (p, q) = (clip[i], clip[(i + 1) % clip.len()]);
        // Inside = left of p → q (the clip polygon is counter-clockwise).
        let side = |x: [f64; 2]| (q[0] - p[0]) * (x[1] - p[1]) - (q[1] - p[1]) * (x[0] - p[0]);
        let mut out = Vec::with_capacity(poly.len() + 1);
        for k in 0..poly.len() {
            let (u, v) = (poly[k], poly[(k + 1) % poly.len()]);
            let (su, sv) = (side(u), side(v));
            if su >= 0.0 {
                out.push(u);
            }
            if (su >= 0.0) != (sv >= 0.0) {
                let t = su / (su - sv);
                out.push([u[0] + t * (v[0] - u[0]), u[1] + t * (v[1] - u[1])]);
            }
        }
        poly = out;
        if poly.len() < 3 {
            return None;
        }
    }
    Some(poly.into_iter().map(|uv| frame.at(uv)).collect())
}

impl Segmentation {
    /// The integration points of `piece` (module header's rules), appended to `out`.
    pub fn points(
        &self,
        a: &Surface,
        b: &Surface,
        piece: &Piece,
        out: &mut Vec<PiecePoint>,
    ) -> Result<(), InterfaceError> {
        let fa = piece.face_a;
        let frame = Frame::of(a, fa);
        let v = &piece.vertices;
        let mut push = |x: [f64; 3], w: f64| -> Result<(), InterfaceError> {
            let xi_a = inverse_in_plane(a, fa, &frame, x);
            // A warped face of Γ^a is integrated on its centre plane (module header).
            let ratio = match a.kind {
                FaceKind::Seg2 => 1.0,
                _ => a.jacobian(fa, xi_a) / plane_jacobian(a, fa, &frame, xi_a),
            };
            let (xi_b, pi) = closest_on_face(b, piece.face_b, x)?;
            out.push(PiecePoint {
                x,
                xi_a,
                pi,
                xi_b,
                weight: w * ratio,
                normal: frame.n,
            });
            Ok(())
        };
        if v.len() == 2 {
            let len = norm(sub(v[1], v[0]));
            for &(t, w) in &self.rule {
                push(add(v[0], scale(sub(v[1], v[0]), t[0])), w * len)?;
            }
            return Ok(());
        }
        for k in 1..v.len() - 1 {
            let (p0, e1, e2) = (v[0], sub(v[k], v[0]), sub(v[k + 1], v[0]));
            let twice_area = norm(cross(e1, e2));
            for &(t, w) in &self.rule {
                push(
                    add(p0, add(scale(e1, t[0]), scale(e2, t[1]))),
                    w * twice_area,
                )?;
            }
        }
        Ok(())
    }
}

/// ξ of the point x (in f_a's plane) on face f_a: the segment's parameter, or the inverse of
/// the face's map projected on its plane (affine on a triangle; Newton on a quadrilateral, one
/// step on a parallelogram).
fn inverse_in_plane(a: &Surface, fa: usize, frame: &Frame, x: [f64; 3]) -> [f64; 2] {
    let nodes = a.face_coords(fa);
    if a.kind == FaceKind::Seg2 {
        let e = sub(nodes[1], nodes[0]);
        return [dot(sub(x, nodes[0]), e) / dot(e, e), 0.0];
    }
    let uv: Vec<[f64; 2]> = nodes.iter().map(|&p| frame.uv(p)).collect();
    let target = frame.uv(x);
    let mut xi = a.kind.centre();
    let mut last = false;
    for _ in 0..30 {
        let n = a.kind.shape(xi);
        let g = a.kind.shape_grad(xi);
        let mut r = [-target[0], -target[1]];
        let mut j = [[0.0; 2]; 2];
        for k in 0..a.kind.nodes() {
            for c in 0..2 {
                r[c] += n[k] * uv[k][c];
                j[c][0] += g[0][k] * uv[k][c];
                j[c][1] += g[1][k] * uv[k][c];
            }
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let step = [
            (j[1][1] * r[0] - j[0][1] * r[1]) / det,
            (j[0][0] * r[1] - j[1][0] * r[0]) / det,
        ];
        xi = [xi[0] - step[0], xi[1] - step[1]];
        // One more step after a small one (quadratic convergence: round-off after it).
        if last {
            break;
        }
        last = step[0].abs().max(step[1].abs()) < NEWTON_TOL;
    }
    xi
}

/// |det| of the face map projected on f_a's plane at ξ.
fn plane_jacobian(a: &Surface, fa: usize, frame: &Frame, xi: [f64; 2]) -> f64 {
    let [t, s] = a.tangents(fa, xi);
    let (t, s) = (
        [dot(t, frame.e1), dot(t, frame.e2)],
        [dot(s, frame.e1), dot(s, frame.e2)],
    );
    (t[0] * s[1] - t[1] * s[0]).abs()
}
