//! The contact-boundary operators of Nitsche's method on the disc/ball (contract §1.3, §2.3; 003
//! §2): at every quadrature point of the faces of Γ_C, the linear functionals u ↦ u_n and
//! u ↦ σ_n(u) of the element's dofs, the gap and γ_h = γ0·h_K.
//!
//! With the obstacle's normal n = −e_d (contract §1.3): u_n = −u_d, σ_n(u) = n·σ(u)n = σ_dd =
//! λ div u + 2μ ∂_d u_d, and the gap of a point is its height x_d above the plane. So
//! P_γ(u) = u_n − γ_h σ_n(u) and P_Θγ(v) = v_n − Θγ_h σ_n(v) are fixed linear combinations of
//! the two rows stored here, and the Nitsche terms of a step,
//!   Σ_q w_q (1/γ_q) [P_γ,q(u) − g_q]_+ P_Θγ,q(v)  and  −Θ Σ_q w_q γ_q σ_n,q(u) σ_n,q(v),
//! only involve the dofs of the elements with a face on Γ_C — what the per-step solve condenses
//! onto (contract §4). The face rule has 3 Gauss points per direction (order 5 ≥ 4, 003 §4.2).
//!
//! Friction (contract §1.8, §2.5) needs the tangential parts too, in the directions e_i, i < d
//! (e_1 in 2D, e_1 and e_2 in 3D): u_t,i = u_i and σ_t,i(u) = (σ(u)n)_i = −σ_id =
//! −μ(∂_i u_d + ∂_d u_i) (the tangential part of the traction σ(u)n, n = −e_d). They are d − 1
//! more rows of each kind per point, made with the same shape values and gradients.
//!
//! Any other mesh (the bars' box, a Gmsh mesh: [`face_contact_points`]) gives its Γ_C as
//! [`ContactFace`]s: an element and the reference coordinates of the vertices of its face on
//! Γ_C. Every supported reference face is flat (a segment, a triangle, an axis-aligned square),
//! so ξ(s) = ξ_0 + Σ_k s_k (ξ_k − ξ_0) is an exact affine parametrisation of it (for a square,
//! ξ_1 and ξ_3 the neighbours of ξ_0); the physical tangents are t_k = J(ξ)(ξ_k − ξ_0) and the
//! surface element |t_1| (2D) or |t_1 × t_2| (3D), so curved P2/Q2 faces are integrated on their
//! own geometry. The rule in s: 3 Gauss points on [0, 1] per direction (segments, squares) and
//! the collapsed 3 × 3 Gauss rule on triangles (s = (1+a)/2, t = (1−s)(1+b)/2, Jacobian
//! (1−s)/4): all of degree 5, as the ball's. h_K is the element's diameter (its largest
//! node-to-node distance, the Gmsh mesh's h per cell).

use super::ball::BallMesh;
use super::element::{det_inv, gauss_legendre, map_at, physical_gradients, shape};
use super::gmsh::{GmshMesh, PhysicalGroup};
use super::mesh::{BoxMesh, Mesh};
use super::simplex::simplex_shape;
use super::sparse::element_coords;

/// One quadrature point of Γ_C with its two linear functionals over `dofs`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPoint {
    /// Quadrature weight × surface element.
    pub weight: f64,
    /// γ_h = γ0·h_K of the point's element.
    pub gamma: f64,
    /// Height x_d of the point above the rigid plane (the gap g of contract §1.3).
    pub gap: f64,
    /// Global dofs of the point's element (node-major, d per node).
    pub dofs: Vec<usize>,
    /// u_n = Σ un[k] u[dofs[k]] (= −u_d).
    pub un: Vec<f64>,
    /// σ_n(u) = Σ sn[k] u[dofs[k]] (= λ div u + 2μ ∂_d u_d).
    pub sn: Vec<f64>,
    /// The tangential rows, d − 1 of them, each over `dofs` (row i at [i·k, (i+1)·k)):
    /// u_t,i = u_i, and σ_t,i(u) = −μ(∂_i u_d + ∂_d u_i) (module header).
    pub ut: Vec<f64>,
    pub st: Vec<f64>,
}

/// The tangential rows of one point: u_t,i = Σ_a N_a u_{a,i} and σ_t,i = −μ(∂_i u_d + ∂_d u_i),
/// from the shape values `n` and physical gradients `g` of its element's NN nodes.
fn tangential_rows<const D: usize, const NN: usize>(
    n: &[f64; NN],
    g: &[[f64; D]; NN],
    mu: f64,
) -> (Vec<f64>, Vec<f64>) {
    let k = NN * D;
    let mut ut = vec![0.0; (D - 1) * k];
    let mut st = vec![0.0; (D - 1) * k];
    for i in 0..D - 1 {
        for a in 0..NN {
            ut[i * k + a * D + i] = n[a];
            st[i * k + a * D + D - 1] = -mu * g[a][i];
            st[i * k + a * D + i] = -mu * g[a][D - 1];
        }
    }
    (ut, st)
}

/// The contact point of weight `weight`, γ_h `gamma` and gap `gap` on an element with dofs
/// `dofs`, its functionals from the shape values `n` and physical gradients `g` there:
/// u_n = −u_d, σ_n(u) = λ div u + 2μ ∂_d u_d, and the tangential rows.
fn contact_point<const D: usize, const NN: usize>(
    n: &[f64; NN],
    g: &[[f64; D]; NN],
    (lambda, mu): (f64, f64),
    dofs: &[usize],
    weight: f64,
    gamma: f64,
    gap: f64,
) -> ContactPoint {
    let mut un = vec![0.0; NN * D];
    let mut sn = vec![0.0; NN * D];
    for a in 0..NN {
        un[a * D + D - 1] = -n[a];
        for i in 0..D {
            sn[a * D + i] = lambda * g[a][i];
        }
        sn[a * D + D - 1] += 2.0 * mu * g[a][D - 1];
    }
    let (ut, st) = tangential_rows::<D, NN>(n, g, mu);
    ContactPoint {
        weight,
        gamma,
        gap,
        dofs: dofs.to_vec(),
        un,
        sn,
        ut,
        st,
    }
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
            out.push(contact_point(
                &n,
                &g,
                (lambda, mu),
                &dofs,
                q.weight,
                gamma0 * mesh.diameters[e],
                q.x[D - 1],
            ));
        }
    }
    out
}

/// A face of Γ_C on a general mesh: its element and the reference coordinates of the face's
/// vertices (2 in 2D; 3, or 4 around the square, in 3D).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactFace {
    pub element: usize,
    pub vertices: Vec<[f64; 3]>,
}

/// The bottom face x_d = 0 of the box: the face ξ_d = −1 of every element of layer 0.
pub fn box_contact_faces(mesh: &BoxMesh) -> Vec<ContactFace> {
    let d = mesh.dim;
    let vertices: Vec<[f64; 3]> = if d == 2 {
        vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]]
    } else {
        vec![
            [-1.0, -1.0, -1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, -1.0],
        ]
    };
    (0..mesh.num_elements())
        .filter(|&e| mesh.element_layer(e) == 0)
        .map(|element| ContactFace {
            element,
            vertices: vertices.clone(),
        })
        .collect()
}

/// The faces of a Gmsh mesh's group (its boundary lines in 2D, triangles or quadrilaterals in
/// 3D): each matched with the cell that has all its vertices (Gmsh's local order lists a
/// boundary element's vertices first, around the face), the vertices' reference coordinates
/// read from the cell's local nodes.
pub fn gmsh_contact_faces(
    mesh: &GmshMesh,
    group: &PhysicalGroup,
) -> Result<Vec<ContactFace>, String> {
    let d = mesh.dim;
    if group.dim + 1 != d {
        return Err(format!(
            "{}: the group \"{}\" has entities of dimension {}, not the boundary faces (dimension {}) that Nitsche's and the penalty's quadrature of Γ_C integrates over",
            mesh.file,
            group.name,
            group.dim,
            d - 1
        ));
    }
    let nn = mesh.kind.num_nodes();
    let reference = mesh.kind.reference_nodes();
    // Cells by node, for the cells around a face's first vertex.
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); mesh.coords.len()];
    for (c, nodes) in mesh.elements.chunks_exact(nn).enumerate() {
        for &n in nodes {
            around[n].push(c);
        }
    }
    let mut out = Vec::with_capacity(group.elements.len());
    for face in &group.elements {
        let nv = match (d, face.len()) {
            (2, _) => 2,
            (_, 3 | 6) => 3,
            _ => 4,
        };
        let verts = &face[..nv.min(face.len())];
        let found = around[verts[0]].iter().find_map(|&c| {
            let cell = &mesh.elements[c * nn..(c + 1) * nn];
            let local: Option<Vec<usize>> = verts
                .iter()
                .map(|v| cell.iter().position(|n| n == v))
                .collect();
            local.map(|l| (c, l))
        });
        let Some((element, local)) = found else {
            return Err(format!(
                "{}: a face of the group \"{}\" (nodes {:?}) is no face of any cell",
                mesh.file,
                group.name,
                verts.iter().map(|&n| mesh.node_tags[n]).collect::<Vec<_>>()
            ));
        };
        out.push(ContactFace {
            element,
            vertices: local.iter().map(|&a| reference[a]).collect(),
        });
    }
    Ok(out)
}

/// The contact points of `faces` on any mesh (see the module header), for Lamé (λ, μ) and γ0;
/// the gap of a point is its height x_d above `plane` (the obstacle's height minus the run's
/// gap for the box and Gmsh meshes, where the run adds it). Dofs are global (node·d + i).
pub fn face_contact_points(
    mesh: &dyn Mesh,
    faces: &[ContactFace],
    lambda: f64,
    mu: f64,
    gamma0: f64,
    plane: f64,
) -> Vec<ContactPoint> {
    let args = (faces, lambda, mu, gamma0, plane);
    match (mesh.dim(), mesh.nodes_per_element()) {
        (2, 4) => faces_generic::<2, 4>(mesh, args, shape::<2, 4>),
        (2, 9) => faces_generic::<2, 9>(mesh, args, shape::<2, 9>),
        (3, 8) => faces_generic::<3, 8>(mesh, args, shape::<3, 8>),
        (3, 27) => faces_generic::<3, 27>(mesh, args, shape::<3, 27>),
        (2, 3) => faces_generic::<2, 3>(mesh, args, simplex_shape::<2, 3>),
        (2, 6) => faces_generic::<2, 6>(mesh, args, simplex_shape::<2, 6>),
        (3, 4) => faces_generic::<3, 4>(mesh, args, simplex_shape::<3, 4>),
        (3, 10) => faces_generic::<3, 10>(mesh, args, simplex_shape::<3, 10>),
        (d, k) => unreachable!("no element of dimension {d} with {k} nodes"),
    }
}

/// The reference face rule in s (module header): (s, weight) with s ∈ [0, 1]^{nv−1} or the
/// unit triangle, for a face of `nv` vertices.
fn face_rule(nv: usize) -> Vec<([f64; 2], f64)> {
    let g: Vec<(f64, f64)> = gauss_legendre(3)
        .iter()
        .map(|&(x, w)| (0.5 * (1.0 + x), 0.5 * w))
        .collect();
    match nv {
        2 => g.iter().map(|&(s, w)| ([s, 0.0], w)).collect(),
        3 => {
            let mut out = Vec::with_capacity(9);
            for &(s, ws) in &g {
                for &(b, wb) in &g {
                    out.push(([s, (1.0 - s) * b], ws * wb * (1.0 - s)));
                }
            }
            out
        }
        _ => {
            let mut out = Vec::with_capacity(9);
            for &(t, wt) in &g {
                for &(s, ws) in &g {
                    out.push(([s, t], ws * wt));
                }
            }
            out
        }
    }
}

type ShapeFn<const D: usize, const NN: usize> = fn([f64; D]) -> ([f64; NN], [[f64; D]; NN]);

fn faces_generic<const D: usize, const NN: usize>(
    mesh: &dyn Mesh,
    (faces, lambda, mu, gamma0, plane): (&[ContactFace], f64, f64, f64, f64),
    shape_at: ShapeFn<D, NN>,
) -> Vec<ContactPoint> {
    let mut out = Vec::new();
    for face in faces {
        let e = face.element;
        let x: [[f64; D]; NN] = element_coords(mesh, e);
        let nodes = mesh.element_nodes(e);
        let mut diameter: f64 = 0.0;
        for a in 0..NN {
            for b in a + 1..NN {
                let r: f64 = (0..D).map(|i| (x[a][i] - x[b][i]).powi(2)).sum();
                diameter = diameter.max(r.sqrt());
            }
        }
        let dofs: Vec<usize> = nodes
            .iter()
            .flat_map(|&n| (0..D).map(move |i| n * D + i))
            .collect();
        let v = &face.vertices;
        let nv = v.len();
        // The reference directions ξ_k − ξ_0 of the parametrisation (the square's two
        // neighbours of ξ_0: vertices 1 and 3).
        let dirs: Vec<[f64; 3]> = match nv {
            2 => vec![sub3(v[1], v[0])],
            3 => vec![sub3(v[1], v[0]), sub3(v[2], v[0])],
            _ => vec![sub3(v[1], v[0]), sub3(v[3], v[0])],
        };
        for (s, w) in face_rule(nv) {
            let mut xi = [0.0; D];
            for (i, xk) in xi.iter_mut().enumerate() {
                *xk = v[0][i] + dirs.iter().zip(s).map(|(dk, sk)| sk * dk[i]).sum::<f64>();
            }
            let (n, dn) = shape_at(xi);
            let mut jac = [[0.0; D]; D];
            let mut xq = [0.0; D];
            for a in 0..NN {
                for i in 0..D {
                    xq[i] += n[a] * x[a][i];
                    for j in 0..D {
                        jac[i][j] += x[a][i] * dn[a][j];
                    }
                }
            }
            let tangent = |dk: &[f64; 3]| -> [f64; 3] {
                let mut t = [0.0; 3];
                for (i, ti) in t.iter_mut().enumerate().take(D) {
                    *ti = (0..D).map(|j| jac[i][j] * dk[j]).sum();
                }
                t
            };
            let area = if D == 2 {
                norm3(tangent(&dirs[0]))
            } else {
                norm3(cross3(tangent(&dirs[0]), tangent(&dirs[1])))
            };
            let (_, jinv) = det_inv(&jac);
            let grads = physical_gradients(&jinv, &dn);
            out.push(contact_point(
                &n,
                &grads,
                (lambda, mu),
                &dofs,
                w * area,
                gamma0 * diameter,
                xq[D - 1] - plane,
            ));
        }
    }
    out
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm3(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
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
                // Tangential rows (friction): σ_t,i = −μ(A_id + A_di) and u_t,i = (A x_q + b)_i,
                // with x_q recovered from the field u = x_d e_d (u_n = −x_d) and the rows'
                // u_t of the field x ↦ x_i; same rounding bound.
                let k = dim * mesh.element_nodes(0).len();
                for p in &pts {
                    assert_eq!((p.ut.len(), p.st.len()), ((dim - 1) * k, (dim - 1) * k));
                    let mut xq = [0.0; 3];
                    for (j, xj) in xq.iter_mut().enumerate().take(dim) {
                        let mut f = vec![0.0; u.len()];
                        for (n, x) in mesh.coords.iter().enumerate() {
                            f[n * dim] = x[j];
                        }
                        *xj = apply(&p.ut[..k], &p.dofs, &f);
                    }
                    for i in 0..dim - 1 {
                        let (ur, sr) = (&p.ut[i * k..(i + 1) * k], &p.st[i * k..(i + 1) * k]);
                        let want_st = -mu * (a[i][dim - 1] + a[dim - 1][i]);
                        let st = apply(sr, &p.dofs, &u);
                        assert!(
                            (st - want_st).abs() < 1e-11 * want_sn.abs(),
                            "{st} {want_st}"
                        );
                        let want_ut = b[i] + (0..dim).map(|j| a[i][j] * xq[j]).sum::<f64>();
                        let ut = apply(ur, &p.dofs, &u);
                        assert!((ut - want_ut).abs() < 1e-11 * 25.0, "{ut} {want_ut}");
                    }
                }
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
