//! Nitsche's method between two bodies on a matching interface (contract §2.6; issue 44): the
//! quadrature points of Γ^a and Γ^b, each carrying both bodies' traces, in the form the
//! one-body engine's operators take ([`super::nitsche::NitscheOps::new`]).
//!
//! A (above) and B (below) meet on the plane x_d = H_b (the run's gap is added to every point
//! where the operators are made, as for the one-body box). A's outward normal on Γ^a is
//! n = −e_d, B's on Γ^b is +e_d, and the relative normal displacement is the same seen from
//! either side: δ(u) = (u^a − u^b∘π)·(−e_d) = u^b_d − u^a_d (positive when the bodies
//! approach). On the matching interface π is the identity in the horizontal coordinates: A's
//! bottom face of a layer-0 element and B's top face of the element below it are the same
//! square, and the same face rule on both (the reference directions of the two faces are the
//! same horizontal axes) gives the same physical points in the same order, with shape values
//! equal number for number (Q1's factor (1 ∓ ξ_d)/2 is exactly 1 or 0 on either face).
//!
//! Each point q of side i (γ^i = γ0·h_K of its element, h_K the element's diameter as in §2.3)
//! is one engine point over the dofs of both elements (A's then B's), with
//!   un = δ's row, sn = σ_n^i's row (σ_dd of body i's element, zero on the other body's dofs),
//! so P^i_γ = δ − γ^i σ_n^i and P^i_Θγ(v) = δ(v) − Θγ^i σ_n^i(v) are the engine's p and t rows,
//! its contact term Σ_q w_q (1/γ_q)[P_q − g]_+ P_Θγ,q(v) is contract §2.6's Σ_i w_i ∫_Γi …
//! once each point's weight carries w_i ([`sided_points`]), and its Θ-term −Θ Σ_q w_q γ_q
//! s_q s_qᵀ is §2.6's −Σ_i w_i ∫ Θγ^i σ_n^i(u) σ_n^i(v). So the step matrix, the condensed
//! semismooth Newton, the hybrid's kinks, E_Θ, the total force and the patch pressure
//! (1/γ^i)[P^i_γ(u) − g^i]_+ are the one-body engine's, unchanged.
//!
//! Action = reaction: each point's force column −t_q = −(δ − Θγσ_n) has, on the e_d dofs, the
//! entries −N_a on A and +N_b on B (the same numbers) plus σ_n's, whose sum over a body is
//! ∇(Σ_a N_a) = 0 — a rigid translation has δ = 0 and σ = 0 — so the total momentum is an
//! invariant (contract §2.6), up to round-off.
//!
//! Friction (contract §2.5, §2.6; [`slip_rows`]). Every point of either side carries the same
//! tangential rows u_t,c = (u^a − u^b∘π)_c, c < d (A's shape values on A's dofs, minus B's on
//! B's: the relative slip of A, the sign of δ's A-part and of the mixed/penalty rows
//! e_{a,i,t} − e_{b,π(i),t}), and the σ_t rows of its own body as the one-body points make them
//! with n = −e_d: σ_t,c = −σ_cd(u^i), zero on the other body's dofs. Why this sign on B's side
//! too, although B's outward normal is +e_d: Chouly–Mlika–Renard's law on side i reads, with
//! the slip of body i, s^i = (u^i − u^j∘π)_t, and the traction on body i, τ^i = (σ(u^i)n^i)_t,
//!   f^i = proj_{|·| ≤ r}(τ^i − Δs^i/(γ^iτ)),  term  ∫ f^i·(Θγ^iτ^i(v) − s^i(v)) − Θ∫γ^i τ^i(u)·τ^i(v),
//! and all three pieces are invariant under (s, τ, f) → (−s, −τ, −f) (the disc's projection is
//! odd, the products even). On Γ^a, s^a = u_t and τ^a = (σ^a(−e_d))_c = −σ_cd(u^a): the one-body
//! rows. On Γ^b, s^b = −u_t and τ^b = (σ^b e_d)_c = σ_cd(u^b), so the flipped pair is (u_t,
//! −σ_cd(u^b)): again the one-body formula, now on B's element. Both sides' σ_t then measure
//! the tangential traction on A — equal at the exact solution, where σ^a e_d = σ^b e_d (action =
//! reaction: σ^a n^a + σ^b n^b = 0) — and both sides' f_t is the force on A along u_t, so the
//! one-body law, Newton, tally and W_f apply unchanged to both sides (f_t the traction on A,
//! Σ_q w_q f_t,q A's total tangential force, the rows' Γ mean of v_t the relative e_1
//! velocity, as the mixed/penalty rows report). Action = reaction: a point's tangential force
//! column Θγσ_t − u_t has −N_a on A's c-dofs and +N_b on B's (Σ = 0 over the axis) and σ_t's
//! gradients, whose sum over a body vanishes, so the momentum along every axis is an
//! invariant, and −Θ w γ σ_t σ_tᵀ adds nothing to a rigid translation either.
//!
use super::nitsche_interface::PairFaces;
use crate::scene::NitscheSides;
use crate::space::fe::BoxMesh;
use crate::space::fe::nitsche::{
    ContactFace, ContactPoint, box_contact_faces, face_contact_points,
};

/// B's top face x_d = H_b: the face ξ_d = +1 of every element of B's top layer, its vertices
/// in the order of [`box_contact_faces`]' bottom face (the same horizontal parametrisation).
fn top_faces(mesh: &BoxMesh) -> Vec<ContactFace> {
    let d = mesh.dim;
    let vertices: Vec<[f64; 3]> = if d == 2 {
        vec![[-1.0, 1.0, 0.0], [1.0, 1.0, 0.0]]
    } else {
        vec![
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
        ]
    };
    let top = mesh.num_layers() - 1;
    (0..mesh.num_elements())
        .filter(|&e| mesh.element_layer(e) == top)
        .map(|element| ContactFace {
            element,
            vertices: vertices.clone(),
        })
        .collect()
}

/// Both sides' points [Γ^a, Γ^b] with γ0 = 1 (their `gamma` is h_K), unit side weights, gap 0
/// and global dofs of the joined numbering (A's nodes, then B's from node `b_offset`):
/// module header. `lame` is each body's (λ, μ).
pub(super) fn pair_points(
    mesh_a: &BoxMesh,
    mesh_b: &BoxMesh,
    b_offset: usize,
    lame: [(f64, f64); 2],
) -> [Vec<ContactPoint>; 2] {
    let d = mesh_a.dim;
    let side = |mesh: &BoxMesh, faces: &[ContactFace], (l, m): (f64, f64)| {
        face_contact_points(mesh, faces, l, m, 1.0, 0.0)
    };
    let pa = side(mesh_a, &box_contact_faces(mesh_a), lame[0]);
    let pb = side(mesh_b, &top_faces(mesh_b), lame[1]);
    assert_eq!(pa.len(), pb.len(), "a matching interface pairs every point");
    let mut out = [Vec::with_capacity(pa.len()), Vec::with_capacity(pb.len())];
    for (a, b) in pa.iter().zip(&pb) {
        let dofs: Vec<usize> = a
            .dofs
            .iter()
            .copied()
            .chain(b.dofs.iter().map(|&g| g + b_offset * d))
            .collect();
        // δ = −u^a_d + u^b_d: A's own u_n row and the negated one of B (both made for −e_d).
        let delta: Vec<f64> =
            a.un.iter()
                .copied()
                .chain(b.un.iter().map(|x| -x))
                .collect();
        let zeros = vec![0.0; a.sn.len()];
        let point = |own: &ContactPoint, sn: Vec<f64>| ContactPoint {
            weight: own.weight,
            gamma: own.gamma,
            gap: 0.0,
            dofs: dofs.clone(),
            un: delta.clone(),
            sn,
            ut: Vec::new(),
            st: Vec::new(),
        };
        let mut pa = point(a, a.sn.iter().copied().chain(zeros.clone()).collect());
        (pa.ut, pa.st) = slip_rows(a, b, 0);
        let mut pb = point(b, zeros.iter().copied().chain(b.sn.clone()).collect());
        (pb.ut, pb.st) = slip_rows(a, b, 1);
        out[0].push(pa);
        out[1].push(pb);
    }
    out
}

/// The tangential rows of the pair point made from A's trace `a` and B's `b` at the same place
/// (one-body points over their own elements' dofs, d − 1 rows each) for the point of side
/// `own` (0: Γ^a, 1: Γ^b), over the joined dofs [A's, B's] (module header): u_t,c = a's row,
/// then minus b's — the relative slip (u^a − u^b∘π)_c —, and σ_t,c = the own side's one-body
/// row (−σ_cd of its body), zero over the other body's dofs. Row c at [c·k, (c + 1)·k).
fn slip_rows(a: &ContactPoint, b: &ContactPoint, own: usize) -> (Vec<f64>, Vec<f64>) {
    let (ka, kb) = (a.dofs.len(), b.dofs.len());
    let td = a.ut.len() / ka.max(1);
    let (mut ut, mut st) = (
        Vec::with_capacity(td * (ka + kb)),
        Vec::with_capacity(td * (ka + kb)),
    );
    for c in 0..td {
        let (ra, rb) = (c * ka..(c + 1) * ka, c * kb..(c + 1) * kb);
        ut.extend_from_slice(&a.ut[ra.clone()]);
        ut.extend(b.ut[rb.clone()].iter().map(|x| -x));
        if own == 0 {
            st.extend_from_slice(&a.st[ra]);
            st.resize(st.len() + kb, 0.0);
        } else {
            st.resize(st.len() + ka, 0.0);
            st.extend_from_slice(&b.st[rb]);
        }
    }
    (ut, st)
}

/// The blocks' interface as a general one ([`super::nitsche_interface`]): A's bottom faces and
/// B's top faces as cells of the joined mesh (A's cells, then B's), touching (gap 0, the run's
/// added where the operators are made); the projection reaches a tenth of the smaller cell.
pub(super) fn blocks_interface(mesh_a: &BoxMesh, mesh_b: &BoxMesh) -> PairFaces {
    let offset = mesh_a.num_elements();
    let mut b = top_faces(mesh_b);
    b.iter_mut().for_each(|f| f.element += offset);
    PairFaces {
        faces: [box_contact_faces(mesh_a), b],
        reach: 0.1 * mesh_a.spacing[0].min(mesh_b.spacing[0]),
        lowest: 0.0,
    }
}

/// The points of the sides with w_i > 0, each weight times w_i (contract §2.6 `nitsche_sides`:
/// w_a = w_b = ½ unbiased, w_a = 1 and no Γ^b point one-sided).
pub(super) fn sided_points(
    sides: &[Vec<ContactPoint>; 2],
    which: NitscheSides,
) -> Vec<ContactPoint> {
    let mut out = Vec::new();
    for (points, w) in sides.iter().zip(which.weights()) {
        if w > 0.0 {
            out.extend(points.iter().map(|p| ContactPoint {
                weight: w * p.weight,
                ..p.clone()
            }));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::friction::FrictionLaw;
    use crate::run::fe::nitsche::{NitscheOps, point_forces};
    use crate::scene::InterfaceQuadrature;

    fn apply(p: &ContactPoint, row: &[f64], u: &[f64]) -> f64 {
        row.iter().zip(&p.dofs).map(|(c, &g)| c * u[g]).sum()
    }

    /// Two boxes of 3 (× 3) cells across, A on B: the points of both sides pair up at the same
    /// place, δ measures u^b_d − u^a_d, σ_n each side's σ_dd, and a rigid translation has δ = 0
    /// and σ_n = 0. Linear fields are exact in Q1; tolerances are round-off on O(1) values.
    #[test]
    fn both_sides_carry_both_traces() {
        for d in [2usize, 3] {
            let (w, ha, hb) = (1.5, 1.0, 0.5);
            let mut ext = vec![w; d];
            let mut cells = vec![3; d];
            ext[d - 1] = ha;
            cells[d - 1] = 2;
            let mut a = BoxMesh::new(&ext, &cells);
            a.coords.iter_mut().for_each(|c| c[d - 1] += hb);
            ext[d - 1] = hb;
            cells[d - 1] = 1;
            let b = BoxMesh::new(&ext, &cells);
            let na = a.coords.len();
            let coords: Vec<[f64; 3]> = a.coords.iter().chain(&b.coords).copied().collect();
            let ((la, ma), (lb, mb)) = ((0.5, 1.0), (2.0, 3.0));
            let [pa, pb] = pair_points(&a, &b, na, [(la, ma), (lb, mb)]);
            let faces = 3usize.pow(d as u32 - 1);
            assert_eq!(pa.len(), faces * 3usize.pow(d as u32 - 1));
            assert_eq!(pb.len(), pa.len());
            // u = (x·e_1) e_d on A, 2(x·e_1) e_d + 0.3 x_d e_d on B: δ = u^b_d − u^a_d = x_1
            // + 0.3 H_b on the interface; σ_dd = λ div u + 2μ ∂_d u_d = 0 on A, 0.3(λ_b + 2μ_b)
            // on B.
            // Tangentially u_c = α_c x_d on A and β_c x_d on B (c < d; div unchanged): the slip
            // (u^a − u^b)_c = (α_c − β_c)H_b on the interface, and the one-body σ_t,c = −σ_cd =
            // −μ(∂_c u_d + ∂_d u_c): −μ_a(1 + α_1), −μ_a α_2 on A; −μ_b(2 + β_1), −μ_b β_2 on B.
            let (alpha, beta) = ([0.4, -0.7], [-0.2, 0.9]);
            let mut u = vec![0.0; coords.len() * d];
            for (n, x) in coords.iter().enumerate() {
                u[n * d + d - 1] = if n < na {
                    x[0]
                } else {
                    2.0 * x[0] + 0.3 * x[d - 1]
                };
                for c in 0..d - 1 {
                    u[n * d + c] = if n < na { alpha[c] } else { beta[c] } * x[d - 1];
                }
            }
            let k = pa[0].dofs.len();
            let dudc = |c: usize, on_b: bool| match (c, on_b) {
                (0, false) => 1.0,
                (0, true) => 2.0,
                _ => 0.0,
            };
            let mut x1 = vec![0.0; coords.len() * d];
            for (n, x) in coords.iter().enumerate().take(na) {
                x1[n * d + d - 1] = -x[0];
            }
            for (p, q) in pa.iter().zip(&pb) {
                assert_eq!(p.dofs, q.dofs);
                assert_eq!(p.weight, q.weight);
                // A's u_n row alone measures −(−x_1) = x_1 at the point: the place.
                let xa: f64 = apply(p, &p.un, &x1);
                let da = apply(p, &p.un, &u);
                let db = apply(q, &q.un, &u);
                assert!((da - (xa + 0.3 * hb)).abs() < 1e-14, "{da} {xa}");
                assert!((db - da).abs() < 1e-14);
                assert!(apply(p, &p.sn, &u).abs() < 1e-13);
                assert!((apply(q, &q.sn, &u) - 0.3 * (lb + 2.0 * mb)).abs() < 1e-13);
                // Friction: both sides' u_t is the slip of A, each σ_t its own body's −σ_cd.
                for c in 0..d - 1 {
                    let rows = |r: &[f64]| r[c * k..(c + 1) * k].to_vec();
                    let slip = (alpha[c] - beta[c]) * hb;
                    for pt in [p, q] {
                        let ut = apply(pt, &rows(&pt.ut), &u);
                        assert!((ut - slip).abs() < 1e-14, "{ut} {slip}");
                    }
                    let sa = apply(p, &rows(&p.st), &u);
                    let sb = apply(q, &rows(&q.st), &u);
                    assert!(
                        (sa + ma * (dudc(c, false) + alpha[c])).abs() < 1e-13,
                        "{sa}"
                    );
                    assert!((sb + mb * (dudc(c, true) + beta[c])).abs() < 1e-13, "{sb}");
                }
                for r in 0..d {
                    let mut t = vec![0.0; u.len()];
                    t.iter_mut().skip(r).step_by(d).for_each(|x| *x = 1.0);
                    for (pt, sn) in [(p, &p.sn), (q, &q.sn)] {
                        assert!(apply(pt, &pt.un, &t).abs() < 1e-15);
                        assert!(apply(pt, sn, &t).abs() < 1e-13);
                        for c in 0..d - 1 {
                            let (ur, sr) = (&pt.ut[c * k..(c + 1) * k], &pt.st[c * k..(c + 1) * k]);
                            assert!(apply(pt, ur, &t).abs() < 1e-15);
                            assert!(apply(pt, sr, &t).abs() < 1e-13);
                        }
                    }
                }
            }
            let total: f64 = pa.iter().map(|p| p.weight).sum();
            assert!((total - w.powi(d as i32 - 1)).abs() < 1e-14);
            let unbiased = sided_points(&[pa.clone(), pb.clone()], NitscheSides::Unbiased);
            assert_eq!(unbiased.len(), 2 * pa.len());
            assert_eq!(unbiased[0].weight, 0.5 * pa[0].weight);
            let one = sided_points(&[pa.clone(), pb], NitscheSides::A);
            assert_eq!(one, pa);
        }
    }

    /// Two blocks (A 2 × 1 cells, B below it, 2 or 3 across: a matching or a non-matching
    /// interface, issue 45's points with `segment` quadrature) as the engine's operators for Θ,
    /// γ0 and the sides, with friction's tangential rows for the step τ where `tau` is given
    /// (matching only: the general interface's points carry no tangential rows yet).
    fn ops_of(
        d: usize,
        theta: f64,
        sides: NitscheSides,
        matching: bool,
        tau: Option<f64>,
    ) -> (NitscheOps, usize) {
        let mut ext = vec![1.0; d];
        let mut cells = vec![2; d];
        let mut a = BoxMesh::new(&ext, &cells);
        a.coords.iter_mut().for_each(|c| c[d - 1] += 1.0);
        ext[d - 1] = 1.0;
        cells = vec![if matching { 2 } else { 3 }; d];
        cells[d - 1] = 1;
        let b = BoxMesh::new(&ext, &cells);
        let n = (a.coords.len() + b.coords.len()) * d;
        let pts = if matching {
            pair_points(&a, &b, a.coords.len(), [(0.5, 1.0), (2.0, 3.0)])
        } else {
            let joined = crate::space::fe::BodiesMesh::new(&[&a, &b]);
            blocks_interface(&a, &b)
                .points(
                    &joined,
                    [(0.5, 1.0), (2.0, 3.0)],
                    InterfaceQuadrature::Segment,
                )
                .unwrap()
        };
        let points = sided_points(&pts, sides);
        let mut ops = NitscheOps::new(&points, theta, 0.05);
        if let Some(tau) = tau {
            ops = ops.with_friction(&points, tau);
        }
        // A gap that leaves some points open and others closed at the test's states.
        ops.gap
            .iter_mut()
            .enumerate()
            .for_each(|(q, g)| *g = 0.02 * (q % 3) as f64);
        (ops, n)
    }

    /// The contact part of the two-body residual, R(u) = Σ_q φ_q(p_q·u) t_q − Θ Σ_q w_q γ_q
    /// s_q (s_q·u) with t_q = −c_q (the forces and A's Θ-term as the step takes them), and its
    /// Newton matrix J = Σ_{q active} (w_q/γ_q) t_q p_qᵀ − Θ Σ_q w_q γ_q s_q s_qᵀ.
    fn residual(ops: &NitscheOps, u: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; u.len()];
        for q in 0..ops.len() {
            let phi = ops.w[q] / ops.gamma[q] * (ops.apply(&ops.p, q, u) - ops.gap[q]).max(0.0);
            let sig = ops.theta * ops.w[q] * ops.gamma[q] * ops.apply(&ops.s, q, u);
            let k = ops.k;
            for i in 0..k {
                let g = ops.dofs[q * k + i];
                r[g] += -phi * ops.c[q * k + i] - sig * ops.s[q * k + i];
            }
        }
        r
    }

    fn newton_matrix_times(ops: &NitscheOps, u: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; u.len()];
        for q in 0..ops.len() {
            let active = ops.apply(&ops.p, q, u) > ops.gap[q];
            let dp = if active {
                ops.w[q] / ops.gamma[q] * ops.apply(&ops.p, q, x)
            } else {
                0.0
            };
            let ds = ops.theta * ops.w[q] * ops.gamma[q] * ops.apply(&ops.s, q, x);
            let k = ops.k;
            for i in 0..k {
                y[ops.dofs[q * k + i]] += -dp * ops.c[q * k + i] - ds * ops.s[q * k + i];
            }
        }
        y
    }

    /// Issues 44 and 45: the two-body contact residual against its Newton matrix by central
    /// differences, on a matching and a non-matching interface (2 against 3 cells across), at states away from the kinks (every point's P_q − g_q farther than the
    /// step from 0): R is piecewise linear, so the difference quotient is exact up to
    /// round-off, 1e-7 relative (ε = 1e-6 on O(1) values: the quotient's cancellation is
    /// ~1e-16/1e-6). With Θ = 1 the residual is also the gradient of the engine's own energy
    /// term E_Θ − E^h = ½Σ(w/γ)[P − g]_+² − ½Σ wγ σ_n² ([`NitscheOps::energy_terms_and_force`]),
    /// the same bound. And Σ over the e_d dofs of R is 0 for every u: action = reaction
    /// (1e-12 of the forces' size).
    #[test]
    fn residual_matches_its_newton_matrix() {
        let mut rng = fastrand::Rng::with_seed(4401);
        for d in [2usize, 3] {
            for (sides, matching) in [NitscheSides::Unbiased, NitscheSides::A]
                .into_iter()
                .flat_map(|s| [(s, true), (s, false)])
            {
                for theta in [-1.0, 0.0, 1.0] {
                    let (ops, n) = ops_of(d, theta, sides, matching, None);
                    let mut checked = 0;
                    for _ in 0..20 {
                        let u: Vec<f64> = (0..n).map(|_| 0.1 * (rng.f64() - 0.5)).collect();
                        let x: Vec<f64> = (0..n).map(|_| rng.f64() - 0.5).collect();
                        let eps = 1e-6;
                        let off_kinks = (0..ops.len()).all(|q| {
                            let m = (ops.apply(&ops.p, q, &u) - ops.gap[q]).abs();
                            m > 10.0 * eps * ops.apply(&ops.p, q, &x).abs().max(1.0)
                        });
                        if !off_kinks {
                            continue;
                        }
                        checked += 1;
                        let at = |t: f64| -> Vec<f64> {
                            u.iter().zip(&x).map(|(a, b)| a + t * b).collect()
                        };
                        let (rp, rm) = (residual(&ops, &at(eps)), residual(&ops, &at(-eps)));
                        let jx = newton_matrix_times(&ops, &u, &x);
                        let scale = jx.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                        for i in 0..n {
                            let fd = (rp[i] - rm[i]) / (2.0 * eps);
                            assert!((fd - jx[i]).abs() <= 1e-7 * scale, "{i}: {fd} {}", jx[i]);
                        }
                        let r = residual(&ops, &u);
                        let rs = r.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                        let sum: f64 = r.iter().skip(d - 1).step_by(d).sum();
                        assert!(sum.abs() <= 1e-12 * rs, "Σ R_d = {sum:e}");
                        if theta == 1.0 {
                            let e = |v: &[f64]| ops.energy_terms_and_force(v).1.unwrap();
                            let de = (e(&at(eps)) - e(&at(-eps))) / (2.0 * eps);
                            let rx: f64 = r.iter().zip(&x).map(|(a, b)| a * b).sum();
                            assert!((de - rx).abs() <= 1e-7 * rs * n as f64, "{de} {rx}");
                        }
                    }
                    assert!(checked >= 5, "{checked} states off the kinks");
                }
            }
        }
    }

    /// The frictional contact part of the two-body residual at u with the previous step's u^n
    /// (`u_n`), as the engine's step takes it (crate::run::fe::nitsche's header): per point
    /// x = (P_γ·u, P_t·u + k u_t·u^n), λ = Λ(x) by the engine's own [`point_forces`], and
    ///   R(u) = −Σ_q Σ_a λ_q,a C_q,a − Θ Σ_q w_q γ_q (s_q s_qᵀ + Σ_c σ_t,qc σ_t,qcᵀ) u,
    /// C's columns −t_q (normal) and u_t − Θγσ_t (tangential). With `x` given, also the Newton
    /// matrix times x: J x = −Σ_q Σ_a C_q,a Σ_b D_q[a][b] (P_q,b·x) − Θ Σ w γ (…) x, D_q the
    /// engine's derivative block. Returns (R or Jx, how many points are in contact, slide).
    fn friction_residual(
        ops: &NitscheOps,
        law: FrictionLaw,
        u: &[f64],
        u_n: &[f64],
        x: Option<&[f64]>,
    ) -> (Vec<f64>, usize, usize) {
        let f = ops.friction.as_ref().unwrap();
        let (d, k) = (ops.per_point(), ops.k);
        let mut r = vec![0.0; u.len()];
        let (mut on, mut slide) = (0, 0);
        let dot = |row: &[f64], dofs: &[usize], v: &[f64]| -> f64 {
            row.iter().zip(dofs).map(|(a, &g)| a * v[g]).sum()
        };
        for q in 0..ops.len() {
            let mut xq = vec![0.0; d];
            for (a, xa) in xq.iter_mut().enumerate() {
                let (row, dofs) = ops.p_row(q * d + a);
                *xa = dot(row, dofs, u);
                if a > 0 {
                    let ur = &f.ut[(q * f.td + a - 1) * k..(q * f.td + a) * k];
                    *xa += f.kt[q] * dot(ur, dofs, u_n);
                }
            }
            let (mut lambda, mut block) = (vec![0.0; d], vec![0.0; d * d]);
            let (o, s) = point_forces(
                &xq,
                ops.gap[q],
                ops.w[q],
                ops.gamma[q],
                law,
                0.0,
                &mut lambda,
                &mut block,
            );
            on += o as usize;
            slide += s as usize;
            let v = x.unwrap_or(u);
            let force: Vec<f64> = match x {
                None => lambda,
                Some(x) => {
                    let px: Vec<f64> = (0..d)
                        .map(|b| {
                            let (row, dofs) = ops.p_row(q * d + b);
                            dot(row, dofs, x)
                        })
                        .collect();
                    (0..d)
                        .map(|a| (0..d).map(|b| block[a * d + b] * px[b]).sum())
                        .collect()
                }
            };
            for a in 0..d {
                let (col, dofs) = ops.c_row(q * d + a);
                let sig = ops.sigma_row(q, a);
                let theta = ops.theta * ops.w[q] * ops.gamma[q] * dot(sig, dofs, v);
                for i in 0..k {
                    r[dofs[i]] += -force[a] * col[i] - theta * sig[i];
                }
            }
        }
        (r, on, slide)
    }

    /// Issue 44: friction with two-body Nitsche — the frictional residual against its Newton
    /// matrix by central differences on the pair points, Coulomb and Tresca, Θ ∈ {−1, 0, 1},
    /// both sides choices, 2D and 3D, at states off the kinks (every point's P_γ − g and, in
    /// contact, |P_t| − r farther than the step's change from 0). Λ is smooth there (linear in
    /// stick and in the normal part, the disc's projection r P̂_t curved in slip), so the
    /// central quotient's error is O(ε²|∂³Λ|) + round-off ~1e-16/ε: with ε = 1e-6 on O(1)
    /// values, 1e-7 of the matrix product's size bounds both. And Σ over each axis' dofs of
    /// R is 0 for every u (action = reaction along e_d and along the tangential axes: the
    /// unit form of the momentum invariant), 1e-12 of the forces' size (their round-off).
    /// Every configuration meets stick and slip points (asserted over each (d, law)).
    #[test]
    fn friction_residual_matches_its_newton_matrix() {
        let mut rng = fastrand::Rng::with_seed(4403);
        let laws = [
            FrictionLaw::Coulomb { coefficient: 0.5 },
            FrictionLaw::Tresca { threshold: 0.3 },
        ];
        for d in [2usize, 3] {
            for law in laws {
                let (mut stick, mut slip) = (0, 0);
                for sides in [NitscheSides::Unbiased, NitscheSides::A] {
                    for theta in [-1.0, 0.0, 1.0] {
                        let (ops, n) = ops_of(d, theta, sides, true, Some(0.5));
                        let mut checked = 0;
                        for _ in 0..40 {
                            let u: Vec<f64> = (0..n).map(|_| 0.1 * (rng.f64() - 0.5)).collect();
                            let u_n: Vec<f64> = (0..n).map(|_| 0.1 * (rng.f64() - 0.5)).collect();
                            let x: Vec<f64> = (0..n).map(|_| rng.f64() - 0.5).collect();
                            let eps = 1e-6;
                            if !off_kinks(&ops, law, &u, &u_n, &x, eps) {
                                continue;
                            }
                            checked += 1;
                            let at = |t: f64| -> Vec<f64> {
                                u.iter().zip(&x).map(|(a, b)| a + t * b).collect()
                            };
                            let rp = friction_residual(&ops, law, &at(eps), &u_n, None).0;
                            let rm = friction_residual(&ops, law, &at(-eps), &u_n, None).0;
                            let (jx, on, s) = friction_residual(&ops, law, &u, &u_n, Some(&x));
                            stick += on - s;
                            slip += s;
                            let scale = jx.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                            for i in 0..n {
                                let fd = (rp[i] - rm[i]) / (2.0 * eps);
                                assert!((fd - jx[i]).abs() <= 1e-7 * scale, "{i}: {fd} {}", jx[i]);
                            }
                            let r = friction_residual(&ops, law, &u, &u_n, None).0;
                            let rs = r.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
                            for c in 0..d {
                                let sum: f64 = r.iter().skip(c).step_by(d).sum();
                                assert!(sum.abs() <= 1e-12 * rs, "axis {c}: Σ R = {sum:e}");
                            }
                        }
                        assert!(checked >= 5, "{checked} states off the kinks");
                    }
                }
                eprintln!("d = {d}, {law:?}: {stick} stick and {slip} slip point-states");
                assert!(stick > 0 && slip > 0, "stick {stick}, slip {slip}");
            }
        }
    }

    /// Whether every point of `ops` at u (previous step u^n) stays on one side of its kinks
    /// along u ± εx: P_γ − g and, in normal contact, |P_t| − r move by less than their
    /// distance to 0 (a factor 10 of margin on the change, ε|P·x| and ε|P_t·x|(1 + r/|P_t|)).
    fn off_kinks(
        ops: &NitscheOps,
        law: FrictionLaw,
        u: &[f64],
        u_n: &[f64],
        x: &[f64],
        eps: f64,
    ) -> bool {
        let f = ops.friction.as_ref().unwrap();
        let (d, k) = (ops.per_point(), ops.k);
        (0..ops.len()).all(|q| {
            let val = |a: usize, v: &[f64], with_n: bool| -> f64 {
                let (row, dofs) = ops.p_row(q * d + a);
                let mut y: f64 = row.iter().zip(dofs).map(|(c, &g)| c * v[g]).sum();
                if a > 0 && with_n {
                    let ur = &f.ut[(q * f.td + a - 1) * k..(q * f.td + a) * k];
                    y += f.kt[q] * ur.iter().zip(dofs).map(|(c, &g)| c * u_n[g]).sum::<f64>();
                }
                y
            };
            let pen = val(0, u, true) - ops.gap[q];
            let dpen = eps * val(0, x, false).abs();
            if pen.abs() <= 10.0 * dpen.max(eps) {
                return false;
            }
            if pen < 0.0 {
                return true;
            }
            let r = match law {
                FrictionLaw::Coulomb { coefficient } => coefficient * pen / ops.gamma[q],
                FrictionLaw::Tresca { threshold } => threshold,
                FrictionLaw::None => 0.0,
            };
            let pt: Vec<f64> = (1..d).map(|a| val(a, u, true)).collect();
            let dpt: f64 = (1..d).map(|a| val(a, x, false).powi(2)).sum::<f64>().sqrt();
            let norm = pt.iter().map(|v| v * v).sum::<f64>().sqrt();
            let dr = match law {
                FrictionLaw::Coulomb { coefficient } => coefficient * dpen / ops.gamma[q],
                _ => 0.0,
            };
            (norm - r).abs() > 10.0 * (eps * dpt + dr).max(eps)
        })
    }
}
