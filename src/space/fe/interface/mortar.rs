//! The mortar matrices of contract §2.6 on the segmentation (`segment.rs`):
//!
//!   D_ki = ∫_Γa ψ_k φ^a_i,   M_kj = ∫_Γa ψ_k (φ^b_j∘Π),   g̃⁰_k = ∫_Γa ψ_k g,
//!
//! g(x) = (Π(x) − x)·n_a the reference gap, each integral summed piece by piece with the piece's
//! rule (exact on affine faces). Rows k and columns i are Γ^a's nodes, columns j Γ^b's.
//!
//! The multiplier basis ψ (`mortar_basis`):
//! - `standard`: ψ_k = φ^a_k;
//! - `dual` (Wohlmuth 2000): on each face e of Γ^a, ψ_k = Σ_l A_kl φ_l with A_e = D_e M_e⁻¹,
//!   D_e = diag(∫_e φ_k), (M_e)_kl = ∫_e φ_k φ_l — so ∫_e ψ_k φ_i = δ_ki ∫_e φ_i and D is
//!   diagonal with D_kk = ∫φ_k wherever the segmentation covers Γ^a. ψ_k is discontinuous
//!   across faces, which the mortar rows do not mind (they are integrals).
//!
//! With `interface_quadrature = "element"` ([`mortar_matrices_element`]) the same integrals
//! are taken with Γ^a's own face rule, φ^b_j∘Π at the projected rule points: D is then exact
//! and M is not (φ^b_j∘Π has kinks inside a face of Γ^a where Γ^b's faces meet) — what an
//! element-by-element code computes, which the contact patch test exposes (contract §6).
//!
//! Why integrate D on the pieces too (not on Γ^a's faces): then Σ_i D_ki = Σ_j M_kj = ∫ψ_k
//! over the covered part exactly (Σ_i φ^a_i = Σ_j φ^b_j = 1 at every point), so a rigid
//! translation makes no weighted gap and every row acts equally and oppositely on the two
//! bodies (the momentum invariant of §2.6), even where Γ^a reaches beyond Γ^b.

use nalgebra::DMatrix;

use super::super::quadrature::{collapsed_simplex_rule, gauss_legendre_any};
use super::projection::Projector;
use super::segment::{PiecePoint, Segmentation};
use super::surface::{FaceKind, InterfaceError, Surface, dot, sub};

/// The multiplier basis of the mortar rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    Standard,
    Dual,
}

/// A sparse matrix by rows (CSR), columns sorted within a row.
#[derive(Debug, Clone, PartialEq)]
pub struct SparseRows {
    pub n_rows: usize,
    pub n_cols: usize,
    pub start: Vec<usize>,
    pub col: Vec<usize>,
    pub val: Vec<f64>,
}

impl SparseRows {
    /// Σ of the triplets (r, c, v) per entry.
    pub fn from_triplets(
        n_rows: usize,
        n_cols: usize,
        mut t: Vec<(usize, usize, f64)>,
    ) -> SparseRows {
        t.sort_unstable_by_key(|&(r, c, _)| (r, c));
        let mut start = vec![0; n_rows + 1];
        let (mut col, mut val): (Vec<usize>, Vec<f64>) = (Vec::new(), Vec::new());
        let mut last = None;
        for (r, c, v) in t {
            if last == Some((r, c)) {
                *val.last_mut().expect("an entry") += v;
            } else {
                start[r + 1] += 1;
                col.push(c);
                val.push(v);
                last = Some((r, c));
            }
        }
        for r in 0..n_rows {
            start[r + 1] += start[r];
        }
        SparseRows {
            n_rows,
            n_cols,
            start,
            col,
            val,
        }
    }

    /// The stored entries of row r: (column, value).
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        (self.start[r]..self.start[r + 1]).map(|k| (self.col[k], self.val[k]))
    }

    /// Entry (r, c), 0 when not stored.
    pub fn get(&self, r: usize, c: usize) -> f64 {
        let cols = &self.col[self.start[r]..self.start[r + 1]];
        cols.binary_search(&c)
            .map_or(0.0, |k| self.val[self.start[r] + k])
    }

    pub fn row_sum(&self, r: usize) -> f64 {
        self.row(r).map(|(_, v)| v).sum()
    }
}

/// D, M, the weighted reference gaps g̃⁰_k = ∫ψ_k g and ∫ψ_k, all on the segmentation.
#[derive(Debug, Clone, PartialEq)]
pub struct Mortar {
    pub basis: Basis,
    pub d: SparseRows,
    pub m: SparseRows,
    pub weighted_gap: Vec<f64>,
    pub psi_integral: Vec<f64>,
}

/// n Gauss points on [0, 1].
fn unit_gauss(n: usize) -> Vec<(f64, f64)> {
    gauss_legendre_any(n)
        .into_iter()
        .map(|(t, w)| (0.5 * (t + 1.0), 0.5 * w))
        .collect()
}

/// The n × n tensor Gauss rule on the unit square.
fn square_gauss(n: usize) -> Vec<([f64; 2], f64)> {
    let g = unit_gauss(n);
    g.iter()
        .flat_map(|&(s, ws)| g.iter().map(move |&(t, wt)| ([s, t], ws * wt)))
        .collect()
}

/// Gauss points of a whole face of `kind` (exact for φ_k φ_l J on an affine face).
fn face_rule(kind: FaceKind) -> Vec<([f64; 2], f64)> {
    match kind {
        FaceKind::Seg2 => unit_gauss(2)
            .into_iter()
            .map(|(t, w)| ([t, 0.0], w))
            .collect(),
        FaceKind::Tri3 => collapsed_simplex_rule(2, 2)
            .into_iter()
            .map(|(p, w)| ([p[0], p[1]], w))
            .collect(),
        FaceKind::Quad4 => square_gauss(3),
    }
}

/// ∫_Γa φ_k for every node of `a` (each face with its own rule): the lumped weights, and
/// ∫ψ_k for both bases on a fully covered Γ^a.
pub fn face_integrals(a: &Surface) -> Vec<f64> {
    let rule = face_rule(a.kind);
    let mut out = vec![0.0; a.num_nodes()];
    for f in 0..a.num_faces() {
        for &(xi, w) in &rule {
            let n = a.kind.shape(xi);
            let jw = w * a.jacobian(f, xi);
            for (k, &node) in a.face(f).iter().enumerate() {
                out[node] += jw * n[k];
            }
        }
    }
    out
}

/// The coefficients ψ_k = Σ_l A_kl φ_l of `basis` on face `f` of Γ^a (the module header's
/// A_e = D_e M_e⁻¹ for `dual`, the identity for `standard`).
pub fn basis_coefficients(a: &Surface, f: usize, basis: Basis) -> [[f64; 4]; 4] {
    let p = a.kind.nodes();
    let mut coef = [[0.0; 4]; 4];
    if basis == Basis::Standard {
        for (k, row) in coef.iter_mut().enumerate().take(p) {
            row[k] = 1.0;
        }
        return coef;
    }
    let mut mass = DMatrix::<f64>::zeros(p, p);
    let mut lumped = DMatrix::<f64>::zeros(p, p);
    for &(xi, w) in &face_rule(a.kind) {
        let n = a.kind.shape(xi);
        let jw = w * a.jacobian(f, xi);
        for k in 0..p {
            lumped[(k, k)] += jw * n[k];
            for l in 0..p {
                mass[(k, l)] += jw * n[k] * n[l];
            }
        }
    }
    // A = D M⁻¹ ⇔ Aᵀ = M⁻¹ D (M symmetric): one LU solve. The face mass of a non-degenerate
    // face (checked by `Surface::new`) is SPD.
    let at = mass.lu().solve(&lumped).expect("an SPD face mass");
    for k in 0..p {
        for l in 0..p {
            coef[k][l] = at[(l, k)];
        }
    }
    coef
}

/// The mortar matrices of Γ^a (rows) against Γ^b on the segmentation `seg` (module header).
pub fn mortar_matrices(
    a: &Surface,
    b: &Surface,
    seg: &Segmentation,
    basis: Basis,
) -> Result<Mortar, InterfaceError> {
    let (pa, pb) = (a.kind.nodes(), b.kind.nodes());
    let mut d = Vec::new();
    let mut m = Vec::new();
    let mut weighted_gap = vec![0.0; a.num_nodes()];
    let mut psi_integral = vec![0.0; a.num_nodes()];
    let mut points: Vec<PiecePoint> = Vec::new();
    let mut coef_face = usize::MAX;
    let mut coef = [[0.0; 4]; 4];
    for piece in &seg.pieces {
        if piece.face_a != coef_face {
            coef = basis_coefficients(a, piece.face_a, basis);
            coef_face = piece.face_a;
        }
        points.clear();
        seg.points(a, b, piece, &mut points)?;
        let (mut dl, mut ml) = ([[0.0; 4]; 4], [[0.0; 4]; 4]);
        let (mut gl, mut sl) = ([0.0; 4], [0.0; 4]);
        for q in &points {
            let na = a.kind.shape(q.xi_a);
            let nb = b.kind.shape(q.xi_b);
            let g = dot(sub(q.pi, q.x), q.normal);
            for k in 0..pa {
                let psi: f64 = (0..pa).map(|l| coef[k][l] * na[l]).sum();
                let wk = q.weight * psi;
                for i in 0..pa {
                    dl[k][i] += wk * na[i];
                }
                for j in 0..pb {
                    ml[k][j] += wk * nb[j];
                }
                gl[k] += wk * g;
                sl[k] += wk;
            }
        }
        let (fa, fb) = (a.face(piece.face_a), b.face(piece.face_b));
        for k in 0..pa {
            for i in 0..pa {
                d.push((fa[k], fa[i], dl[k][i]));
            }
            for j in 0..pb {
                m.push((fa[k], fb[j], ml[k][j]));
            }
            weighted_gap[fa[k]] += gl[k];
            psi_integral[fa[k]] += sl[k];
        }
    }
    Ok(Mortar::assemble(
        basis,
        (a, b),
        (d, m),
        weighted_gap,
        psi_integral,
    ))
}

/// Γ^a's own face rule: the trace of its elements' rule, 2 Gauss points per direction (the
/// Q1/P1 elements' 2^d-point rule; GetFEM's order-2 face rule), exact for φ_k φ_l J on an
/// affine face — D is exact, M is not.
fn element_rule(kind: FaceKind) -> Vec<([f64; 2], f64)> {
    match kind {
        FaceKind::Quad4 => square_gauss(2),
        _ => face_rule(kind),
    }
}

/// The mortar matrices with Γ^a's own face rule (`interface_quadrature = "element"`, module
/// header): each rule point x of each face of Γ^a projected by `proj` onto Γ^b (a point with
/// no projection within the reach is refused), the integrands summed there. Σ_i D_ki =
/// Σ_j M_kj = ∫ψ_k still hold at every point (Σ_i φ^a_i = Σ_j φ^b_j = 1), so the rows keep the
/// momentum invariant; only the M entries are inexact.
pub fn mortar_matrices_element(
    a: &Surface,
    proj: &Projector,
    basis: Basis,
) -> Result<Mortar, InterfaceError> {
    let b = proj.surface();
    if a.kind.dim() != b.kind.dim() {
        return Err(InterfaceError::MixedDimensions {
            a: a.kind,
            b: b.kind,
        });
    }
    let (pa, pb) = (a.kind.nodes(), b.kind.nodes());
    let rule = element_rule(a.kind);
    let (mut d, mut m) = (Vec::new(), Vec::new());
    let mut weighted_gap = vec![0.0; a.num_nodes()];
    let mut psi_integral = vec![0.0; a.num_nodes()];
    for f in 0..a.num_faces() {
        let coef = basis_coefficients(a, f, basis);
        let (fa, normal) = (a.face(f), a.normal(f));
        for &(xi, w) in &rule {
            let x = a.point(f, xi);
            let pi = proj.project(x)?;
            let (na, nb) = (a.kind.shape(xi), b.kind.shape(pi.xi));
            let jw = w * a.jacobian(f, xi);
            let g = dot(sub(pi.point, x), normal);
            let fb = b.face(pi.face);
            for k in 0..pa {
                let psi: f64 = (0..pa).map(|l| coef[k][l] * na[l]).sum();
                let wk = jw * psi;
                for i in 0..pa {
                    d.push((fa[k], fa[i], wk * na[i]));
                }
                for j in 0..pb {
                    m.push((fa[k], fb[j], wk * nb[j]));
                }
                weighted_gap[fa[k]] += wk * g;
                psi_integral[fa[k]] += wk;
            }
        }
    }
    Ok(Mortar::assemble(
        basis,
        (a, b),
        (d, m),
        weighted_gap,
        psi_integral,
    ))
}

impl Mortar {
    /// D and M from their (row, column, value) triplets over Γ^a × Γ^a and Γ^a × Γ^b nodes,
    /// with the per-row weighted gaps and ∫ψ_k: what both quadratures end with.
    #[allow(clippy::type_complexity)]
    fn assemble(
        basis: Basis,
        (a, b): (&Surface, &Surface),
        (d, m): (Vec<(usize, usize, f64)>, Vec<(usize, usize, f64)>),
        weighted_gap: Vec<f64>,
        psi_integral: Vec<f64>,
    ) -> Mortar {
        Mortar {
            basis,
            d: SparseRows::from_triplets(a.num_nodes(), a.num_nodes(), d),
            m: SparseRows::from_triplets(a.num_nodes(), b.num_nodes(), m),
            weighted_gap,
            psi_integral,
        }
    }
}
