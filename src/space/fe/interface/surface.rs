//! The two sides Γ^a, Γ^b of a two-body interface as face sets (contract §2.6), the shape
//! functions of their faces and the small vector algebra the projection, the segmentation and
//! the mortar matrices share.
//!
//! A side is a list of faces of one kind over its own node numbering 0..n (the caller maps them
//! to body nodes): 2-node segments in 2D, 3-node triangles or 4-node bilinear quadrilaterals in
//! 3D. All faces are parametrised on [0, 1] (segments), the unit triangle ξ, η ≥ 0, ξ + η ≤ 1
//! (N = 1 − ξ − η, ξ, η) or the unit square (N = (1 − ξ)(1 − η), ξ(1 − η), ξη, (1 − ξ)η, the
//! nodes counter-clockwise). A face's normal follows its node order: a 2D segment x₀ → x₁ has
//! n = (t_y, −t_x)/|t| (outward for a counter-clockwise boundary), a 3D face n ∥ x_ξ × x_η
//! (outward for nodes counter-clockwise seen from outside), taken at the face centre for a
//! quadrilateral (exact when it is flat).

/// The kind of the faces of one side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceKind {
    /// 2-node segment (2D interfaces).
    Seg2,
    /// 3-node triangle (3D).
    Tri3,
    /// 4-node bilinear quadrilateral (3D).
    Quad4,
}

impl FaceKind {
    pub fn nodes(self) -> usize {
        match self {
            FaceKind::Seg2 => 2,
            FaceKind::Tri3 => 3,
            FaceKind::Quad4 => 4,
        }
    }

    /// The space dimension of a side made of this kind of face.
    pub fn dim(self) -> usize {
        match self {
            FaceKind::Seg2 => 2,
            FaceKind::Tri3 | FaceKind::Quad4 => 3,
        }
    }

    /// Shape functions at ξ (η ignored on a segment); unused slots are 0.
    pub fn shape(self, xi: [f64; 2]) -> [f64; 4] {
        let [s, t] = xi;
        match self {
            FaceKind::Seg2 => [1.0 - s, s, 0.0, 0.0],
            FaceKind::Tri3 => [1.0 - s - t, s, t, 0.0],
            FaceKind::Quad4 => [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t],
        }
    }

    /// ∂N/∂ξ and ∂N/∂η at ξ.
    pub fn shape_grad(self, xi: [f64; 2]) -> [[f64; 4]; 2] {
        let [s, t] = xi;
        match self {
            FaceKind::Seg2 => [[-1.0, 1.0, 0.0, 0.0], [0.0; 4]],
            FaceKind::Tri3 => [[-1.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 1.0, 0.0]],
            FaceKind::Quad4 => [[-(1.0 - t), 1.0 - t, t, -t], [-(1.0 - s), -s, s, 1.0 - s]],
        }
    }

    /// The reference centre.
    pub fn centre(self) -> [f64; 2] {
        match self {
            FaceKind::Seg2 => [0.5, 0.0],
            FaceKind::Tri3 => [1.0 / 3.0, 1.0 / 3.0],
            FaceKind::Quad4 => [0.5, 0.5],
        }
    }
}

/// Errors of the interface geometry and the mortar matrices.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InterfaceError {
    #[error(
        "interface side {side}: {kind:?} faces live in {expected}D, the side is given in {dim}D"
    )]
    WrongDimension {
        side: char,
        kind: FaceKind,
        expected: usize,
        dim: usize,
    },
    #[error(
        "interface side {side}: the connectivity has {len} entries, not a multiple of {per} nodes per face"
    )]
    BadConnectivity { side: char, len: usize, per: usize },
    #[error("interface side {side}: face {face} names node {node}, the side has {n} nodes")]
    BadNode {
        side: char,
        face: usize,
        node: usize,
        n: usize,
    },
    #[error("interface side {side}: face {face} is degenerate (measure {measure:e})")]
    Degenerate {
        side: char,
        face: usize,
        measure: f64,
    },
    #[error("interface side {side}: no faces")]
    Empty { side: char },
    #[error(
        "interface: the point {point:?} has no projection on Γ^b within the tolerance {reach:e} \
         (the faces do not face each other, or the point lies beyond Γ^b)"
    )]
    NoProjection { point: [f64; 3], reach: f64 },
    #[error(
        "interface: the projection on face {face} of Γ^b did not converge (a strongly warped face)"
    )]
    NoConvergence { face: usize },
    #[error(
        "interface: face {face} of Γ^a is covered {covered:e} by the projected faces of Γ^b, more \
         than its measure {measure:e} (Γ^b folds back within the reach)"
    )]
    Overlap {
        face: usize,
        covered: f64,
        measure: f64,
    },
    #[error("interface: Γ^a has {a:?} faces and Γ^b {b:?} faces; both sides need one dimension")]
    MixedDimensions { a: FaceKind, b: FaceKind },
}

/// One side of the interface: node coordinates (z = 0 in 2D) and faces of one kind.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    pub kind: FaceKind,
    pub coords: Vec<[f64; 3]>,
    /// `kind.nodes()` node indices per face, face after face.
    pub conn: Vec<usize>,
}

impl Surface {
    /// A side checked for shape: `side` ('a' or 'b') names it in errors.
    pub fn new(
        side: char,
        kind: FaceKind,
        coords: Vec<[f64; 3]>,
        conn: Vec<usize>,
    ) -> Result<Surface, InterfaceError> {
        let per = kind.nodes();
        if conn.is_empty() {
            return Err(InterfaceError::Empty { side });
        }
        if !conn.len().is_multiple_of(per) {
            return Err(InterfaceError::BadConnectivity {
                side,
                len: conn.len(),
                per,
            });
        }
        if let Some((k, &node)) = conn.iter().enumerate().find(|(_, n)| **n >= coords.len()) {
            return Err(InterfaceError::BadNode {
                side,
                face: k / per,
                node,
                n: coords.len(),
            });
        }
        if kind.dim() == 2 && coords.iter().any(|x| x[2] != 0.0) {
            return Err(InterfaceError::WrongDimension {
                side,
                kind,
                expected: 2,
                dim: 3,
            });
        }
        let s = Surface { kind, coords, conn };
        for f in 0..s.num_faces() {
            let measure = s.jacobian(f, kind.centre());
            let size = s.diameter(f);
            // A face whose measure is below round-off of its size has no normal (NaN too).
            if measure.is_nan() || measure <= 1e-12 * size.powi(kind.dim() as i32 - 1) {
                return Err(InterfaceError::Degenerate {
                    side,
                    face: f,
                    measure,
                });
            }
        }
        Ok(s)
    }

    pub fn num_faces(&self) -> usize {
        self.conn.len() / self.kind.nodes()
    }

    pub fn num_nodes(&self) -> usize {
        self.coords.len()
    }

    /// The node indices of face `f`.
    pub fn face(&self, f: usize) -> &[usize] {
        let p = self.kind.nodes();
        &self.conn[f * p..(f + 1) * p]
    }

    /// The node coordinates of face `f` (unused slots zero).
    pub fn face_coords(&self, f: usize) -> [[f64; 3]; 4] {
        let mut x = [[0.0; 3]; 4];
        for (slot, &n) in x.iter_mut().zip(self.face(f)) {
            *slot = self.coords[n];
        }
        x
    }

    /// x(ξ) on face `f`.
    pub fn point(&self, f: usize, xi: [f64; 2]) -> [f64; 3] {
        combine(&self.face_coords(f), &self.kind.shape(xi))
    }

    /// The tangents x_ξ, x_η of face `f` at ξ (x_η = 0 on a segment).
    pub fn tangents(&self, f: usize, xi: [f64; 2]) -> [[f64; 3]; 2] {
        let x = self.face_coords(f);
        let g = self.kind.shape_grad(xi);
        [combine(&x, &g[0]), combine(&x, &g[1])]
    }

    /// The surface Jacobian |x_ξ| (segment) or |x_ξ × x_η| of face `f` at ξ.
    pub fn jacobian(&self, f: usize, xi: [f64; 2]) -> f64 {
        let [t, s] = self.tangents(f, xi);
        match self.kind {
            FaceKind::Seg2 => norm(t),
            _ => norm(cross(t, s)),
        }
    }

    /// The unit normal of face `f` (module header: from the node order, at the centre).
    pub fn normal(&self, f: usize) -> [f64; 3] {
        let [t, s] = self.tangents(f, self.kind.centre());
        let n = match self.kind {
            FaceKind::Seg2 => [t[1], -t[0], 0.0],
            _ => cross(t, s),
        };
        scale(n, 1.0 / norm(n))
    }

    /// The largest distance between two nodes of face `f`.
    pub fn diameter(&self, f: usize) -> f64 {
        let nodes = self.face(f);
        let mut d: f64 = 0.0;
        for (i, &p) in nodes.iter().enumerate() {
            for &q in &nodes[i + 1..] {
                d = d.max(norm(sub(self.coords[p], self.coords[q])));
            }
        }
        d
    }

    /// The axis-aligned bounding box of face `f` grown by `grow`.
    pub fn face_box(&self, f: usize, grow: f64) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &n in self.face(f) {
            for c in 0..3 {
                lo[c] = lo[c].min(self.coords[n][c] - grow);
                hi[c] = hi[c].max(self.coords[n][c] + grow);
            }
        }
        (lo, hi)
    }
}

/// Σ_a w_a x_a over the first 4 rows.
pub fn combine(x: &[[f64; 3]; 4], w: &[f64; 4]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (xa, &wa) in x.iter().zip(w) {
        for c in 0..3 {
            out[c] += wa * xa[c];
        }
    }
    out
}

pub fn sub(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [u[0] - v[0], u[1] - v[1], u[2] - v[2]]
}

pub fn add(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [u[0] + v[0], u[1] + v[1], u[2] + v[2]]
}

pub fn scale(u: [f64; 3], s: f64) -> [f64; 3] {
    [u[0] * s, u[1] * s, u[2] * s]
}

pub fn dot(u: [f64; 3], v: [f64; 3]) -> f64 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

pub fn cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

pub fn norm(u: [f64; 3]) -> f64 {
    dot(u, u).sqrt()
}
