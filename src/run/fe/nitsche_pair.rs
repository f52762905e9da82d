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
//! Why no tangential rows: friction between two bodies with Nitsche is not implemented (the
//! relative slip's Nitsche term is another operator); the planner refuses it and the factor
//! checks it again.

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
        out[0].push(point(
            a,
            a.sn.iter().copied().chain(zeros.clone()).collect(),
        ));
        out[1].push(point(
            b,
            zeros.iter().copied().chain(b.sn.clone()).collect(),
        ));
    }
    out
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
    use crate::run::fe::nitsche::NitscheOps;
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
            let mut u = vec![0.0; coords.len() * d];
            for (n, x) in coords.iter().enumerate() {
                u[n * d + d - 1] = if n < na {
                    x[0]
                } else {
                    2.0 * x[0] + 0.3 * x[d - 1]
                };
            }
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
                for r in 0..d {
                    let mut t = vec![0.0; u.len()];
                    t.iter_mut().skip(r).step_by(d).for_each(|x| *x = 1.0);
                    for (pt, sn) in [(p, &p.sn), (q, &q.sn)] {
                        assert!(apply(pt, &pt.un, &t).abs() < 1e-15);
                        assert!(apply(pt, sn, &t).abs() < 1e-13);
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
    /// γ0 and the sides.
    fn ops_of(d: usize, theta: f64, sides: NitscheSides, matching: bool) -> (NitscheOps, usize) {
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
        let mut ops = NitscheOps::new(&sided_points(&pts, sides), theta, 0.05);
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
                    let (ops, n) = ops_of(d, theta, sides, matching);
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
}
