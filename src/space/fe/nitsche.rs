//! The contact-boundary operators of Nitsche's method on the disc/ball (SPEC §1.3, §2.3; 003
//! §2): at every quadrature point of the faces of Γ_C, the linear functionals u ↦ u_n and
//! u ↦ σ_n(u) of the element's dofs, the gap and γ_h = γ0·h_K.
//!
//! With the obstacle's normal n = −e_d (SPEC §1.3): u_n = −u_d, σ_n(u) = n·σ(u)n = σ_dd =
//! λ div u + 2μ ∂_d u_d, and the gap of a point is its height x_d above the plane. So
//! P_γ(u) = u_n − γ_h σ_n(u) and P_Θγ(v) = v_n − Θγ_h σ_n(v) are fixed linear combinations of
//! the two rows stored here, and the Nitsche terms of a step,
//!   Σ_q w_q (1/γ_q) [P_γ,q(u) − g_q]_+ P_Θγ,q(v)  and  −Θ Σ_q w_q γ_q σ_n,q(u) σ_n,q(v),
//! only involve the dofs of the elements with a face on Γ_C — what the per-step solve condenses
//! onto (SPEC §4). The face rule has 3 Gauss points per direction (order 5 ≥ 4, 003 §4.2).

use super::ball::BallMesh;
use super::element::map_at;
use super::mesh::Mesh;
use super::sparse::element_coords;

/// One quadrature point of Γ_C with its two linear functionals over `dofs`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPoint {
    /// Quadrature weight × surface element.
    pub weight: f64,
    /// γ_h = γ0·h_K of the point's element.
    pub gamma: f64,
    /// Height x_d of the point above the rigid plane (the gap g of SPEC §1.3).
    pub gap: f64,
    /// Global dofs of the point's element (node-major, d per node).
    pub dofs: Vec<usize>,
    /// u_n = Σ un[k] u[dofs[k]] (= −u_d).
    pub un: Vec<f64>,
    /// σ_n(u) = Σ sn[k] u[dofs[k]] (= λ div u + 2μ ∂_d u_d).
    pub sn: Vec<f64>,
}

/// The contact points of the faces of Γ_C of `mesh` for Lamé (λ, μ) and Nitsche's γ0.
pub fn contact_points(mesh: &BallMesh, lambda: f64, mu: f64, gamma0: f64) -> Vec<ContactPoint> {
    match (mesh.dim, mesh.degree) {
        (2, 1) => points_generic::<2, 4>(mesh, lambda, mu, gamma0),
        (2, 2) => points_generic::<2, 9>(mesh, lambda, mu, gamma0),
        (3, 1) => points_generic::<3, 8>(mesh, lambda, mu, gamma0),
        (3, 2) => points_generic::<3, 27>(mesh, lambda, mu, gamma0),
        (d, p) => unreachable!("BallMesh has dim 2/3 and degree 1/2, not {d}/{p}"),
    }
}

fn points_generic<const D: usize, const NN: usize>(
    mesh: &BallMesh,
    lambda: f64,
    mu: f64,
    gamma0: f64,
) -> Vec<ContactPoint> {
    let mut out = Vec::new();
    for &f in &mesh.contact_faces {
        let face = &mesh.boundary_faces[f];
        let e = face.element;
        let x: [[f64; D]; NN] = element_coords(mesh, e);
        let nodes = mesh.element_nodes(e);
        let dofs: Vec<usize> = nodes
            .iter()
            .flat_map(|&n| (0..D).map(move |i| n * D + i))
            .collect();
        for q in mesh.face_points(face, 3) {
            let mut xi = [0.0; D];
            xi.copy_from_slice(&q.xi[..D]);
            let (n, g, _) = map_at(&x, xi);
            let mut un = vec![0.0; NN * D];
            let mut sn = vec![0.0; NN * D];
            for a in 0..NN {
                un[a * D + D - 1] = -n[a];
                for i in 0..D {
                    sn[a * D + i] = lambda * g[a][i];
                }
                sn[a * D + D - 1] += 2.0 * mu * g[a][D - 1];
            }
            out.push(ContactPoint {
                weight: q.weight,
                gamma: gamma0 * mesh.diameters[e],
                gap: q.x[D - 1],
                dofs: dofs.clone(),
                un,
                sn,
            });
        }
    }
    out
}

/// The global dofs the Nitsche terms involve (the dofs of the elements with a face on Γ_C),
/// increasing: the unknowns of the condensed per-step problem.
pub fn condensed_dofs(points: &[ContactPoint]) -> Vec<usize> {
    let mut d: Vec<usize> = points.iter().flat_map(|p| p.dofs.iter().copied()).collect();
    d.sort_unstable();
    d.dedup();
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn apply(row: &[f64], dofs: &[usize], u: &[f64]) -> f64 {
        row.iter().zip(dofs).map(|(c, &g)| c * u[g]).sum()
    }

    #[test]
    fn linear_fields_give_exact_normal_displacement_and_stress() {
        // u = A x + b is in every isoparametric space: u_n = −(A x_q + b)_d at each point and
        // σ_n = λ tr A + 2μ A_dd exactly; only rounding remains (values ≤ 10³·|A|): 1e-11.
        let a = [[0.3, -0.2, 0.1], [0.15, 0.25, -0.05], [-0.1, 0.2, 0.35]];
        let b = [1.0, -2.0, 0.5];
        let (lam, mu) = (20.0, 20.0);
        for (dim, n_t) in [(2usize, 8usize), (3, 4)] {
            for degree in [1, 2] {
                let mut c = [0.0; 3];
                c[dim - 1] = 25.0;
                let mesh = BallMesh::new(dim, degree, 20.0, c, n_t, 2).unwrap();
                let mut u = vec![0.0; mesh.coords.len() * dim];
                for (n, x) in mesh.coords.iter().enumerate() {
                    for i in 0..dim {
                        u[n * dim + i] = b[i] + (0..dim).map(|j| a[i][j] * x[j]).sum::<f64>();
                    }
                }
                let tr: f64 = (0..dim).map(|i| a[i][i]).sum();
                let want_sn = lam * tr + 2.0 * mu * a[dim - 1][dim - 1];
                let pts = contact_points(&mesh, lam, mu, 1e-3);
                assert_eq!(
                    pts.len(),
                    mesh.contact_faces.len() * 3usize.pow(dim as u32 - 1)
                );
                // The field u = x_d e_d: its u_n at a point is −x_d(q) = −gap (the isoparametric
                // map reproduces x), so the gap is the point's height, in [5, 25] (Γ_C is the
                // lower half of the body whose lowest point is 5 above the plane).
                let mut ud = vec![0.0; u.len()];
                for (n, x) in mesh.coords.iter().enumerate() {
                    ud[n * dim + dim - 1] = x[dim - 1];
                }
                let contact_diameters: Vec<f64> = mesh
                    .contact_faces
                    .iter()
                    .map(|&f| 1e-3 * mesh.diameters[mesh.boundary_faces[f].element])
                    .collect();
                for p in &pts {
                    let sn = apply(&p.sn, &p.dofs, &u);
                    assert!(
                        (sn - want_sn).abs() < 1e-11 * want_sn.abs(),
                        "{sn} {want_sn}"
                    );
                    let un = apply(&p.un, &p.dofs, &ud);
                    assert!((un + p.gap).abs() < 1e-12 * 25.0, "{un} vs −{}", p.gap);
                    assert!(p.gap >= 5.0 - 1e-9 && p.gap <= 25.0 + 1e-9);
                    // γ_h = γ0·h_K of a contact element (the same product, so exact).
                    assert!(contact_diameters.contains(&p.gamma));
                }
                let cd = condensed_dofs(&pts);
                // Every dof of every element touching Γ_C by a face, nothing else.
                let elems: std::collections::BTreeSet<usize> = mesh
                    .contact_faces
                    .iter()
                    .map(|&f| mesh.boundary_faces[f].element)
                    .collect();
                let mut want: Vec<usize> = elems
                    .iter()
                    .flat_map(|&e| mesh.element_nodes(e).to_vec())
                    .flat_map(|n| (0..dim).map(move |i| n * dim + i))
                    .collect();
                want.sort_unstable();
                want.dedup();
                assert_eq!(cd, want);
            }
        }
    }

    #[test]
    fn rigid_rotation_has_no_normal_stress() {
        // ε = 0 for an infinitesimal rotation, so σ_n = 0 at every point (rounding: 1e-12).
        let mesh = BallMesh::new(2, 2, 20.0, [0.0, 25.0, 0.0], 8, 3).unwrap();
        let u: Vec<f64> = mesh
            .coords
            .iter()
            .flat_map(|x| [-(x[1] - 25.0) / 20.0, x[0] / 20.0])
            .collect();
        for p in contact_points(&mesh, 20.0, 20.0, 1e-3) {
            let sn = apply(&p.sn, &p.dofs, &u);
            assert!(sn.abs() < 1e-12 * 40.0, "{sn}");
        }
    }
}
