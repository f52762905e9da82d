//! The projection Π of contract §2.6: Π(x) is the closest point of Γ^b to x, in the reference
//! configuration, found among the faces of Γ^b within a reach (the gap tolerance) of x.
//!
//! - On one face: a segment, the clamped parameter t = (x − x₀)·e/|e|²; a triangle, the
//!   orthogonal projection on its plane (the 2 × 2 normal equations for ξ, η) when it falls
//!   inside, else the nearest of its three edges; a bilinear quadrilateral, Newton's method on
//!   ½|x(ξ) − p|² (gradient J^T r, Hessian J^T J + r·x_ξη [[0, 1], [1, 0]], from the centre:
//!   one step on a parallelogram, a few on a warped face), else, when the stationary point
//!   falls outside the unit square, the nearest of its four straight edges.
//! - The spatial index: a uniform grid of bins over the bounding box of Γ^b's faces each grown
//!   by the reach, about one face per bin, each face entered in every bin its grown box meets.
//!   A point x within the reach of a face lies in that face's grown box, so the one bin holding
//!   x lists every face that can be Π(x)'s: O(1) work per point on a quasi-uniform interface
//!   and O(n) to build — set-up linear in the interface (issue 45, done-when 5). A box query
//!   (the segmentation's candidates of one face of Γ^a) visits the bins its box meets.
//! - A point with no face within the reach is refused ([`InterfaceError::NoProjection`]): the
//!   faces do not face each other, or the point lies beyond Γ^b.

use super::surface::{FaceKind, InterfaceError, Surface, dot, norm, sub};

/// Where a point projects: face of Γ^b, reference coordinates, the point and its distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    pub face: usize,
    pub xi: [f64; 2],
    pub point: [f64; 3],
    pub distance: f64,
}

const NEWTON_ITERS: usize = 30;
/// Newton's step size (reference coordinates, the face ~1) below which one more step is the
/// last: Newton converges quadratically, so that step leaves ξ at round-off (a fixed tolerance
/// of 1e-14 could not be met by a small face far from the origin, whose ξ is only known to
/// ~1e-16·|x|/h).
pub(crate) const NEWTON_TOL: f64 = 1e-9;
/// How far outside the unit square (reference coordinates) Newton's stationary point may lie
/// and still be taken (clamped): round-off of a point on an edge.
const INSIDE_TOL: f64 = 1e-12;

/// The closest point of face `f` of `s` to `p`: reference coordinates and the point.
pub fn closest_on_face(
    s: &Surface,
    f: usize,
    p: [f64; 3],
) -> Result<([f64; 2], [f64; 3]), InterfaceError> {
    let x = s.face_coords(f);
    let xi = match s.kind {
        FaceKind::Seg2 => [closest_on_segment(x[0], x[1], p), 0.0],
        FaceKind::Tri3 => closest_on_triangle(&x, p),
        FaceKind::Quad4 => closest_on_quad(s, f, p)?,
    };
    Ok((xi, s.point(f, xi)))
}

/// The parameter t ∈ [0, 1] of the closest point of segment x₀x₁ to p.
fn closest_on_segment(x0: [f64; 3], x1: [f64; 3], p: [f64; 3]) -> f64 {
    let e = sub(x1, x0);
    (dot(sub(p, x0), e) / dot(e, e)).clamp(0.0, 1.0)
}

/// Solve the 2 × 2 system [[a, b], [b, c]] y = r (Cramer; the callers' matrices are SPD).
fn solve2(a: f64, b: f64, c: f64, r: [f64; 2]) -> [f64; 2] {
    let det = a * c - b * b;
    [(c * r[0] - b * r[1]) / det, (a * r[1] - b * r[0]) / det]
}

fn closest_on_triangle(x: &[[f64; 3]; 4], p: [f64; 3]) -> [f64; 2] {
    let (e1, e2, r) = (sub(x[1], x[0]), sub(x[2], x[0]), sub(p, x[0]));
    let xi = solve2(
        dot(e1, e1),
        dot(e1, e2),
        dot(e2, e2),
        [dot(e1, r), dot(e2, r)],
    );
    if xi[0] >= 0.0 && xi[1] >= 0.0 && xi[0] + xi[1] <= 1.0 {
        return xi;
    }
    // Outside: the nearest of the three edges (ξ of each edge's point).
    let t01 = closest_on_segment(x[0], x[1], p);
    let t12 = closest_on_segment(x[1], x[2], p);
    let t20 = closest_on_segment(x[2], x[0], p);
    let cands = [[t01, 0.0], [1.0 - t12, t12], [0.0, 1.0 - t20]];
    nearest(
        &cands,
        |xi| {
            let n = FaceKind::Tri3.shape(xi);
            super::surface::combine(x, &n)
        },
        p,
    )
}

/// The candidate ξ whose point is nearest p (the first on a tie).
fn nearest(cands: &[[f64; 2]], point: impl Fn([f64; 2]) -> [f64; 3], p: [f64; 3]) -> [f64; 2] {
    let mut best = (f64::INFINITY, cands[0]);
    for &c in cands {
        let d = norm(sub(point(c), p));
        if d < best.0 {
            best = (d, c);
        }
    }
    best.1
}

fn closest_on_quad(s: &Surface, f: usize, p: [f64; 3]) -> Result<[f64; 2], InterfaceError> {
    let x = s.face_coords(f);
    // ∂²x/∂ξ∂η of the bilinear map (its only second derivative).
    let x_st = [0, 1, 2].map(|c| x[0][c] - x[1][c] + x[2][c] - x[3][c]);
    let mut xi = FaceKind::Quad4.centre();
    let mut converged = false;
    let mut last = false;
    for _ in 0..NEWTON_ITERS {
        let r = sub(s.point(f, xi), p);
        let [ts, tt] = s.tangents(f, xi);
        let g = [dot(ts, r), dot(tt, r)];
        let (a, c) = (dot(ts, ts), dot(tt, tt));
        let mut b = dot(ts, tt) + dot(r, x_st);
        if a * c - b * b <= 0.0 {
            // Not a minimum's Hessian (far from a strongly warped face): Gauss–Newton.
            b = dot(ts, tt);
        }
        let step = solve2(a, b, c, g);
        xi = [xi[0] - step[0], xi[1] - step[1]];
        if !(xi[0].abs() < 10.0 && xi[1].abs() < 10.0) {
            break; // far outside the face: its edges decide
        }
        if last {
            converged = true;
            break;
        }
        last = step[0].abs().max(step[1].abs()) < NEWTON_TOL;
    }
    let inside = xi
        .iter()
        .all(|&v| (-INSIDE_TOL..=1.0 + INSIDE_TOL).contains(&v));
    if converged && inside {
        return Ok(xi.map(|v| v.clamp(0.0, 1.0)));
    }
    // No interior stationary point: the nearest of the four straight edges, provided no
    // direction into the face decreases the distance there (else Newton missed an interior
    // minimum of a strongly warped face: refused rather than guessed).
    let t = [
        closest_on_segment(x[0], x[1], p),
        closest_on_segment(x[1], x[2], p),
        closest_on_segment(x[3], x[2], p),
        closest_on_segment(x[0], x[3], p),
    ];
    let cands = [[t[0], 0.0], [1.0, t[1]], [t[2], 1.0], [0.0, t[3]]];
    let best = nearest(&cands, |xi| s.point(f, xi), p);
    let r = sub(s.point(f, best), p);
    let [ts, tt] = s.tangents(f, best);
    let g = [dot(ts, r), dot(tt, r)];
    let scale = norm(r) * norm(ts).max(norm(tt));
    let descends = (0..2).any(|c| {
        (best[c] <= 0.0 && g[c] < -1e-10 * scale) || (best[c] >= 1.0 && g[c] > 1e-10 * scale)
    });
    if descends {
        return Err(InterfaceError::NoConvergence { face: f });
    }
    Ok(best)
}

/// Γ^b with its bins (module header).
#[derive(Debug, Clone)]
pub struct Projector<'s> {
    surface: &'s Surface,
    reach: f64,
    lo: [f64; 3],
    cell: [f64; 3],
    n: [usize; 3],
    /// CSR of the bins: faces of bin k are `items[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl<'s> Projector<'s> {
    /// The bins of `surface` for points within `reach` of it.
    pub fn new(surface: &'s Surface, reach: f64) -> Projector<'s> {
        let nf = surface.num_faces();
        let boxes: Vec<_> = (0..nf).map(|f| surface.face_box(f, reach)).collect();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (bl, bh) in &boxes {
            for c in 0..3 {
                lo[c] = lo[c].min(bl[c]);
                hi[c] = hi[c].max(bh[c]);
            }
        }
        let mean = (0..nf).map(|f| surface.diameter(f)).sum::<f64>() / nf as f64;
        // Bins of the mean face size, made coarser if a thin box would hold many more bins
        // than faces (a bin count of a few times the face count keeps memory O(n)).
        let mut h = mean;
        let mut n = [1usize; 3];
        loop {
            for c in 0..3 {
                n[c] = (((hi[c] - lo[c]) / h).ceil() as usize).max(1);
            }
            if n[0] * n[1] * n[2] <= 4 * nf + 64 {
                break;
            }
            h *= 1.25;
        }
        let cell = [0, 1, 2].map(|c| (hi[c] - lo[c]) / n[c] as f64);
        let mut p = Projector {
            surface,
            reach,
            lo,
            cell,
            n,
            start: vec![0; n[0] * n[1] * n[2] + 1],
            items: Vec::new(),
        };
        p.fill(&boxes);
        p
    }

    /// Two passes over the faces' boxes: count per bin, then place (CSR).
    fn fill(&mut self, boxes: &[([f64; 3], [f64; 3])]) {
        for (bl, bh) in boxes {
            self.for_bins(*bl, *bh, |k, me| me.start[k + 1] += 1);
        }
        for k in 1..self.start.len() {
            self.start[k] += self.start[k - 1];
        }
        self.items = vec![0; *self.start.last().unwrap_or(&0) as usize];
        let mut next = self.start.clone();
        for (f, (bl, bh)) in boxes.iter().enumerate() {
            self.for_bins(*bl, *bh, |k, me| {
                me.items[next[k] as usize] = f as u32;
                next[k] += 1;
            });
        }
    }

    /// Calls `visit(bin)` for every bin the box [lo, hi] meets (clamped to the grid).
    fn for_bins(&mut self, lo: [f64; 3], hi: [f64; 3], mut visit: impl FnMut(usize, &mut Self)) {
        let (a, b) = (self.bin_of(lo), self.bin_of(hi));
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    visit((i * self.n[1] + j) * self.n[2] + k, self);
                }
            }
        }
    }

    fn bin_of(&self, x: [f64; 3]) -> [usize; 3] {
        [0, 1, 2].map(|c| {
            let t = ((x[c] - self.lo[c]) / self.cell[c]).floor();
            (t.max(0.0) as usize).min(self.n[c] - 1)
        })
    }

    fn in_grid(&self, x: [f64; 3]) -> bool {
        (0..3).all(|c| x[c] >= self.lo[c] && x[c] <= self.lo[c] + self.cell[c] * self.n[c] as f64)
    }

    pub fn surface(&self) -> &'s Surface {
        self.surface
    }

    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// The faces whose grown boxes may meet the box [lo, hi], sorted, each once.
    pub fn candidates(&self, lo: [f64; 3], hi: [f64; 3], out: &mut Vec<usize>) {
        out.clear();
        let (a, b) = (self.bin_of(lo), self.bin_of(hi));
        for i in a[0]..=b[0] {
            for j in a[1]..=b[1] {
                for k in a[2]..=b[2] {
                    let bin = (i * self.n[1] + j) * self.n[2] + k;
                    let r = self.start[bin] as usize..self.start[bin + 1] as usize;
                    out.extend(self.items[r].iter().map(|&f| f as usize));
                }
            }
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Π(p): the closest point of Γ^b within the reach (the lowest face index on a tie).
    pub fn project(&self, p: [f64; 3]) -> Result<Projection, InterfaceError> {
        let none = InterfaceError::NoProjection {
            point: p,
            reach: self.reach,
        };
        if !self.in_grid(p) {
            return Err(none);
        }
        let [i, j, k] = self.bin_of(p);
        let bin = (i * self.n[1] + j) * self.n[2] + k;
        let faces = &self.items[self.start[bin] as usize..self.start[bin + 1] as usize];
        let mut best: Option<Projection> = None;
        for &f in faces {
            let f = f as usize;
            let (xi, point) = closest_on_face(self.surface, f, p)?;
            let distance = norm(sub(point, p));
            let better = best
                .is_none_or(|b| distance < b.distance || (distance == b.distance && f < b.face));
            if distance <= self.reach && better {
                best = Some(Projection {
                    face: f,
                    xi,
                    point,
                    distance,
                });
            }
        }
        best.ok_or(none)
    }
}

/// Π(p) by trying every face of `s` (the tests' independent reference for the bins); a face
/// whose bounding box is farther than the best distance so far cannot be closer and is skipped.
pub fn project_brute(s: &Surface, p: [f64; 3], reach: f64) -> Result<Projection, InterfaceError> {
    let mut best: Option<Projection> = None;
    for f in 0..s.num_faces() {
        let (lo, hi) = s.face_box(f, 0.0);
        let out = [0, 1, 2].map(|c| (lo[c] - p[c]).max(p[c] - hi[c]).max(0.0));
        let bound = norm(out);
        if bound > reach || best.is_some_and(|b| bound > b.distance) {
            continue;
        }
        let (xi, point) = closest_on_face(s, f, p)?;
        let distance = norm(sub(point, p));
        if distance <= reach && best.is_none_or(|b| distance < b.distance) {
            best = Some(Projection {
                face: f,
                xi,
                point,
                distance,
            });
        }
    }
    best.ok_or(InterfaceError::NoProjection { point: p, reach })
}
