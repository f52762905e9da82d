//! The structured mapped meshes of the disc and the ball (contract §1.3, `disc2d`/`sphere3d`):
//! a five-block O-grid of the disc and a seven-block cubed sphere of the ball, with isoparametric
//! Q1 or Q2 elements, the boundary faces of Γ_C and their quadrature.
//!
//! Blocks (centre c, radius R, inner half-side a = R/2):
//! - the central block: the square/cube c + [−a, a]^d, mapped linearly, n_t elements per axis;
//! - one outer block per face of that square/cube (axis k, side σ = ±1): with s ∈ [0, 1] the
//!   radial and t ∈ [−1, 1]^{d−1} the tangential reference coordinates,
//!   x = c + (1 − s) P_in(t) + s P_out(t), where P_in is the inner face (P_in,k = σa, the others
//!   a·t) and P_out = R w/|w| with w_k = σ, the others tan(π t/4) — the equiangular projection
//!   of the face onto the circle/sphere. n_r elements radially, n_t per tangential axis.
//!
//! Adjacent blocks agree on their shared faces (both evaluate the same formula there), so the
//! mesh is conforming; nodes are merged by position (to 1e-8 R, far below any node spacing).
//! Every node, Q2 mid-edge/face/cell nodes included, is the image of its reference lattice point
//! under the block map, so the degree-2 nodes on the boundary lie on the exact circle/sphere and
//! the interior ones follow the blockwise mapping. Each block's reference axes are oriented so
//! that det J > 0 (axis 0 is reversed in the blocks where the natural order is left-handed).
//!
//! Γ_C is the boundary below the centre's height (contract §1.3). n_t is always even, so the
//! equator is a union of element edges (no face straddles it) and the lowest point of the ball
//! is a node. Sizes from a nominal h: n_t = 2·max(1, round(πR/(4h))) (an arc of the boundary per
//! element ≈ h) and n_r = max(1, round((R − a)/h)) (radial thickness ≈ h, rounded half up: the
//! outer elements stay close to isotropic, which Nitsche's method needs — γ_h = γ0·h_K uses the
//! diameter, while the inverse trace inequality it must beat scales with the thickness normal
//! to Γ_C; with n_r = 2 at h = 8 the Q2 ball loses coercivity at Θ = 1, γ0 = 1e-3). The
//! paper's disc (R = 20, h = 4) gives n_t = 8, n_r = 3, 160 elements; its ball (h = 8) n_t = 4,
//! n_r = 1, 160 elements (the paper's 3D mesh has 400).
//!
//! Mass layers (contract §2.2): layer 0 = the elements with a node on Γ_C (so that every Γ_C node
//! is massless when layer 0 is), layer k + 1 = the remaining elements sharing a node with layer
//! k.

use std::collections::HashMap;
use std::f64::consts::FRAC_PI_4;

use super::FeError;
use super::element::{gauss_legendre, lagrange_1d};
use super::mesh::Mesh;

/// A face of an element on the boundary circle/sphere.
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryFace {
    pub element: usize,
    /// The element's reference axis normal to the face, and the end: ξ_axis = −1 (0) or +1 (1).
    pub axis: usize,
    pub end: usize,
    /// Local indices (in the element) of the face's nodes, in tensor order over the remaining
    /// reference axes (ascending, the first fastest).
    pub local: Vec<usize>,
    /// Global node ids of the face, in the same order.
    pub nodes: Vec<usize>,
}

/// A quadrature point of a boundary face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FacePoint {
    /// Reference coordinates in the element (unused trailing components 0).
    pub xi: [f64; 3],
    /// Physical position.
    pub x: [f64; 3],
    /// Quadrature weight times the surface (length) element of the discrete face.
    pub weight: f64,
    /// Unit outward normal of the body at the point (of the discrete, isoparametric face).
    pub normal: [f64; 3],
}

/// The mapped disc (dim 2) or ball (dim 3).
#[derive(Debug, Clone, PartialEq)]
pub struct BallMesh {
    pub dim: usize,
    /// 1 (Q1) or 2 (Q2).
    pub degree: usize,
    pub radius: f64,
    pub centre: [f64; 3],
    /// Half-side a of the central square/cube.
    pub inner_half: f64,
    /// Elements per side of the central block (and tangentially in the outer blocks), even.
    pub n_t: usize,
    /// Elements across the outer blocks (radially).
    pub n_r: usize,
    pub coords: Vec<[f64; 3]>,
    /// Node ids of the elements, (degree+1)^dim per element, flat.
    pub elements: Vec<usize>,
    /// Every face on the circle/sphere.
    pub boundary_faces: Vec<BoundaryFace>,
    /// Indices into `boundary_faces` of the faces of Γ_C.
    pub contact_faces: Vec<usize>,
    /// The nodes of Γ_C (closed: the equator's nodes included), increasing.
    pub contact_nodes: Vec<usize>,
    /// Mass layer of each element (module header).
    pub layers: Vec<usize>,
    /// Diameter h_K of each element (largest distance between two of its vertices).
    pub diameters: Vec<f64>,
}

/// A block of the mesh: the central square/cube, or the outer block on side σ of axis k.
#[derive(Debug, Clone, Copy)]
enum Block {
    Central,
    Outer { axis: usize, sign: f64 },
}

impl BallMesh {
    /// (n_t, n_r) for a nominal element size h (module header).
    pub fn counts_for_size(radius: f64, h: f64) -> (usize, usize) {
        let a = 0.5 * radius;
        let n_t = 2 * ((std::f64::consts::PI * radius / (4.0 * h)).round() as usize).max(1);
        let n_r = (((radius - a) / h).round() as usize).max(1);
        (n_t, n_r)
    }

    /// The mesh with nominal element size h.
    pub fn with_size(
        dim: usize,
        degree: usize,
        radius: f64,
        centre: [f64; 3],
        h: f64,
    ) -> Result<BallMesh, FeError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(FeError::BadMesh(format!(
                "element size h = {h} is not a positive finite length"
            )));
        }
        if !(radius.is_finite() && radius > 0.0) || h > 2.0 * radius {
            return Err(FeError::BadMesh(format!(
                "element size h = {h} vs radius {radius}: need 0 < h ≤ 2R"
            )));
        }
        let (n_t, n_r) = Self::counts_for_size(radius, h);
        BallMesh::new(dim, degree, radius, centre, n_t, n_r)
    }

    /// The mesh with n_t (even, ≥ 2) elements per side of the central block and n_r ≥ 1 across
    /// the outer blocks.
    pub fn new(
        dim: usize,
        degree: usize,
        radius: f64,
        centre: [f64; 3],
        n_t: usize,
        n_r: usize,
    ) -> Result<BallMesh, FeError> {
        if !(dim == 2 || dim == 3) {
            return Err(FeError::BadMesh(format!(
                "dimension {dim}: the disc is 2D, the ball 3D"
            )));
        }
        if !(degree == 1 || degree == 2) {
            return Err(FeError::BadMesh(format!(
                "degree {degree}: elements of degree 1 (Q1) or 2 (Q2)"
            )));
        }
        if !(radius.is_finite() && radius > 0.0) || centre.iter().any(|c| !c.is_finite()) {
            return Err(FeError::BadMesh(format!(
                "radius {radius} and centre {centre:?} must be finite, the radius positive"
            )));
        }
        if n_t < 2 || !n_t.is_multiple_of(2) || n_r < 1 {
            return Err(FeError::BadMesh(format!(
                "n_t = {n_t} must be even and ≥ 2, n_r = {n_r} ≥ 1"
            )));
        }
        let p = degree;
        let n1 = p + 1;
        let npe = n1.pow(dim as u32);
        let a = 0.5 * radius;
        let mut blocks = vec![Block::Central];
        for axis in 0..dim {
            for sign in [-1.0, 1.0] {
                blocks.push(Block::Outer { axis, sign });
            }
        }
        let mut mesh = BallMesh {
            dim,
            degree,
            radius,
            centre,
            inner_half: a,
            n_t,
            n_r,
            coords: Vec::new(),
            elements: Vec::new(),
            boundary_faces: Vec::new(),
            contact_faces: Vec::new(),
            contact_nodes: Vec::new(),
            layers: Vec::new(),
            diameters: Vec::new(),
        };
        let tol = 1e-8 * radius;
        let mut index: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for block in blocks {
            let cells: Vec<usize> = match block {
                Block::Central => vec![n_t; dim],
                Block::Outer { .. } => {
                    let mut c = vec![n_t; dim];
                    c[0] = n_r;
                    c
                }
            };
            let lat: Vec<usize> = cells.iter().map(|c| c * p + 1).collect();
            let total: usize = lat.iter().product();
            // Global id of every lattice point of the block (axis 0 fastest).
            let mut ids = Vec::with_capacity(total);
            for q in 0..total {
                let mut j = [0usize; 3];
                let mut r = q;
                for k in 0..dim {
                    j[k] = r % lat[k];
                    r /= lat[k];
                }
                let x = mesh.block_point(block, &j, &lat);
                ids.push(merge_node(&mut mesh.coords, &mut index, x, tol, dim));
            }
            let flip = mesh.block_orientation(block) < 0.0;
            let ncells: usize = cells.iter().product();
            for ec in 0..ncells {
                let mut e_idx = [0usize; 3];
                let mut r = ec;
                for k in 0..dim {
                    e_idx[k] = r % cells[k];
                    r /= cells[k];
                }
                let e = mesh.elements.len() / npe;
                for loc in 0..npe {
                    let mut i = [0usize; 3];
                    let mut r = loc;
                    for ik in i.iter_mut().take(dim) {
                        *ik = r % n1;
                        r /= n1;
                    }
                    if flip {
                        i[0] = p - i[0];
                    }
                    let mut q = 0;
                    for k in (0..dim).rev() {
                        q = q * lat[k] + e_idx[k] * p + i[k];
                    }
                    mesh.elements.push(ids[q]);
                }
                if matches!(block, Block::Outer { .. }) && e_idx[0] == n_r - 1 {
                    // The face s = 1 is the reference face ξ_0 = +1, or −1 if axis 0 is reversed.
                    let end = if flip { 0 } else { 1 };
                    let local: Vec<usize> = (0..npe).filter(|l| (l % n1) == end * p).collect();
                    let nodes = local.iter().map(|&l| mesh.elements[e * npe + l]).collect();
                    mesh.boundary_faces.push(BoundaryFace {
                        element: e,
                        axis: 0,
                        end,
                        local,
                        nodes,
                    });
                }
            }
        }
        mesh.finish();
        Ok(mesh)
    }

    /// Γ_C, the layers and the diameters, once nodes and elements are in place.
    fn finish(&mut self) {
        let d = self.dim;
        let cd = self.centre[d - 1];
        let mut on_contact = vec![false; self.coords.len()];
        for (f, face) in self.boundary_faces.iter().enumerate() {
            let mean: f64 = face
                .nodes
                .iter()
                .map(|&n| self.coords[n][d - 1])
                .sum::<f64>()
                / face.nodes.len() as f64;
            if mean < cd {
                self.contact_faces.push(f);
                for &n in &face.nodes {
                    on_contact[n] = true;
                }
            }
        }
        self.contact_nodes = (0..self.coords.len()).filter(|&n| on_contact[n]).collect();
        // Layers: breadth-first over shared nodes from the elements touching Γ_C.
        self.layers = super::mesh::mesh_layers(&*self, &self.contact_nodes);
        let ne = self.num_elements();
        let npe = self.nodes_per_element();
        let p = self.degree;
        let corners: Vec<usize> = (0..npe)
            .filter(|&l| {
                let mut r = l;
                (0..d).all(|_| {
                    let i = r % (p + 1);
                    r /= p + 1;
                    i == 0 || i == p
                })
            })
            .collect();
        self.diameters = (0..ne)
            .map(|e| {
                let nodes = self.element_nodes(e);
                let mut m = 0.0f64;
                for (i, &a) in corners.iter().enumerate() {
                    for &b in &corners[i + 1..] {
                        m = m.max(dist(&self.coords[nodes[a]], &self.coords[nodes[b]]));
                    }
                }
                m
            })
            .collect();
    }

    /// The image of lattice point `j` (lattice sizes `lat`) of a block.
    fn block_point(&self, block: Block, j: &[usize; 3], lat: &[usize]) -> [f64; 3] {
        let d = self.dim;
        let a = self.inner_half;
        // t ∈ [−1, 1] from an integer ratio, so that blocks sharing a face compute the same value.
        let t = |k: usize| (2 * j[k]) as f64 / (lat[k] - 1) as f64 - 1.0;
        let mut x = self.centre;
        match block {
            Block::Central => {
                for k in 0..d {
                    x[k] += a * t(k);
                }
            }
            Block::Outer { axis, sign } => {
                let s = j[0] as f64 / (lat[0] - 1) as f64;
                let mut p_in = [0.0; 3];
                let mut w = [0.0; 3];
                p_in[axis] = sign * a;
                w[axis] = sign;
                for (l, g) in (0..d).filter(|&g| g != axis).enumerate() {
                    let tl = t(l + 1);
                    p_in[g] = a * tl;
                    // tan(±π/4) = ±1 exactly, so the diagonal edges of adjacent blocks coincide.
                    w[g] = if tl.abs() == 1.0 {
                        tl
                    } else {
                        (FRAC_PI_4 * tl).tan()
                    };
                }
                let norm = w.iter().map(|v| v * v).sum::<f64>().sqrt();
                for k in 0..d {
                    x[k] += (1.0 - s) * p_in[k] + s * self.radius * w[k] / norm;
                }
            }
        }
        x
    }

    /// The sign of det ∂x/∂(reference) of a block, by central differences at its centre (the
    /// maps are smooth with det ≠ 0, so the sign is the block's orientation).
    fn block_orientation(&self, block: Block) -> f64 {
        let d = self.dim;
        // A fine virtual lattice: points 2n ± 1 around the centre 2n of [0, 4n].
        let n = 1000usize;
        let lat = vec![4 * n + 1; d];
        let mut jac = [[0.0; 3]; 3];
        for k in 0..d {
            let mut jp = [2 * n; 3];
            let mut jm = [2 * n; 3];
            jp[k] += 1;
            jm[k] -= 1;
            let xp = self.block_point(block, &jp, &lat);
            let xm = self.block_point(block, &jm, &lat);
            for i in 0..d {
                jac[i][k] = xp[i] - xm[i];
            }
        }
        if d == 2 {
            jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]
        } else {
            jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1])
                - jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0])
                + jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0])
        }
    }

    pub fn num_elements(&self) -> usize {
        self.elements.len() / self.nodes_per_element()
    }

    /// (degree + 1)^dim.
    pub fn nodes_per_element(&self) -> usize {
        (self.degree + 1).pow(self.dim as u32)
    }

    /// πR² or (4/3)πR³: the measure of the exact disc/ball.
    pub fn exact_measure(&self) -> f64 {
        let r = self.radius;
        if self.dim == 2 {
            std::f64::consts::PI * r * r
        } else {
            4.0 / 3.0 * std::f64::consts::PI * r * r * r
        }
    }

    /// The node with the smallest x_d (the lowest point, on the vertical axis through the centre).
    pub fn lowest_node(&self) -> usize {
        let d = self.dim;
        (0..self.coords.len())
            .min_by(|&a, &b| self.coords[a][d - 1].total_cmp(&self.coords[b][d - 1]))
            .expect("a mesh has nodes")
    }

    /// ∫_ΓC N_b dS / |Γ_C| for each node b of `contact_nodes` (same order; sum 1): the weights
    /// of the mean of a nodal field over Γ_C, with the faces' quadrature of order 5.
    pub fn contact_node_weights(&self) -> Vec<f64> {
        let d = self.dim;
        let n1 = self.degree + 1;
        let mut w = vec![0.0; self.coords.len()];
        let mut total = 0.0;
        for &f in &self.contact_faces {
            let face = &self.boundary_faces[f];
            let free: Vec<usize> = (0..d).filter(|&k| k != face.axis).collect();
            for q in self.face_points(face, 3) {
                total += q.weight;
                for (b, &node) in face.nodes.iter().enumerate() {
                    let mut r = b;
                    let mut nb = 1.0;
                    for &ax in &free {
                        nb *= lagrange_1d(n1, r % n1, q.xi[ax]).0;
                        r /= n1;
                    }
                    w[node] += nb * q.weight;
                }
            }
        }
        self.contact_nodes.iter().map(|&n| w[n] / total).collect()
    }

    /// The Gauss points of boundary face `face` (`points` per direction; 3 gives order 5 ≥ 4,
    /// contract §1.3), with the weight times the discrete face's length/area element and the unit
    /// normal pointing out of the body (away from the centre: the body is star-shaped about it).
    pub fn face_points(&self, face: &BoundaryFace, points: usize) -> Vec<FacePoint> {
        let d = self.dim;
        let n1 = self.degree + 1;
        let rule = gauss_legendre(points);
        let m = points.pow(d as u32 - 1);
        let free: Vec<usize> = (0..d).filter(|&k| k != face.axis).collect();
        let mut out = Vec::with_capacity(m);
        for q in 0..m {
            let mut uv = [0.0; 2];
            let mut w = 1.0;
            let mut r = q;
            for u in uv.iter_mut().take(d - 1) {
                let (x, wk) = rule[r % points];
                *u = x;
                w *= wk;
                r /= points;
            }
            let mut x = [0.0; 3];
            let mut tang = [[0.0; 3]; 2];
            for (b, &node) in face.nodes.iter().enumerate() {
                let mut f = [1.0; 2];
                let mut df = [0.0; 2];
                let mut r = b;
                for k in 0..d - 1 {
                    (f[k], df[k]) = lagrange_1d(n1, r % n1, uv[k]);
                    r /= n1;
                }
                let nb: f64 = f[..d - 1].iter().product();
                let c = self.coords[node];
                for i in 0..d {
                    x[i] += nb * c[i];
                    for k in 0..d - 1 {
                        let dk: f64 = (0..d - 1)
                            .map(|l| if l == k { df[l] } else { f[l] })
                            .product();
                        tang[k][i] += dk * c[i];
                    }
                }
            }
            let mut normal = if d == 2 {
                [tang[0][1], -tang[0][0], 0.0]
            } else {
                cross(&tang[0], &tang[1])
            };
            let len = normal.iter().map(|v| v * v).sum::<f64>().sqrt();
            let outward: f64 = (0..d).map(|i| normal[i] * (x[i] - self.centre[i])).sum();
            let s = if outward < 0.0 { -1.0 } else { 1.0 } / len;
            normal.iter_mut().for_each(|v| *v *= s);
            let mut xi = [0.0; 3];
            xi[face.axis] = if face.end == 1 { 1.0 } else { -1.0 };
            for (k, &ax) in free.iter().enumerate() {
                xi[ax] = uv[k];
            }
            out.push(FacePoint {
                xi,
                x,
                weight: w * len,
                normal,
            });
        }
        out
    }
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q) * (p - q))
        .sum::<f64>()
        .sqrt()
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The id of the node at x: an existing node within `tol` (looked up in the neighbouring cells
/// of a grid of side `tol`, so rounding across a cell boundary cannot split a node), else a new
/// one.
fn merge_node(
    coords: &mut Vec<[f64; 3]>,
    index: &mut HashMap<[i64; 3], Vec<usize>>,
    x: [f64; 3],
    tol: f64,
    dim: usize,
) -> usize {
    let key = |x: &[f64; 3]| x.map(|v| (v / tol).round() as i64);
    let k0 = key(&x);
    let span = |k: usize| if k < dim { -1..=1 } else { 0..=0 };
    for dx in span(0) {
        for dy in span(1) {
            for dz in span(2) {
                if let Some(list) = index.get(&[k0[0] + dx, k0[1] + dy, k0[2] + dz])
                    && let Some(&n) = list.iter().find(|&&n| dist(&coords[n], &x) <= tol)
                {
                    return n;
                }
            }
        }
    }
    coords.push(x);
    let id = coords.len() - 1;
    index.entry(k0).or_default().push(id);
    id
}

impl Mesh for BallMesh {
    fn dim(&self) -> usize {
        self.dim
    }
    fn num_nodes(&self) -> usize {
        self.coords.len()
    }
    fn num_elements(&self) -> usize {
        BallMesh::num_elements(self)
    }
    fn nodes_per_element(&self) -> usize {
        BallMesh::nodes_per_element(self)
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        let npe = self.nodes_per_element();
        &self.elements[e * npe..(e + 1) * npe]
    }
    fn coord(&self, node: usize) -> [f64; 3] {
        self.coords[node]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_of_the_paper_settings() {
        // Module header: the disc R = 20, h = 4 and the ball h = 8.
        assert_eq!(BallMesh::counts_for_size(20.0, 4.0), (8, 3));
        assert_eq!(BallMesh::counts_for_size(20.0, 8.0), (4, 1));
        let disc = BallMesh::with_size(2, 2, 20.0, [0.0, 25.0, 0.0], 4.0).unwrap();
        assert_eq!(disc.num_elements(), 8 * 8 + 4 * 8 * 3);
        // Nodes of the Q2 O-grid: (2·8+1)² in the square, 4 × (2·8)·(2·3) more outside (each
        // outer block's inner row is shared with the square, one diagonal column with a
        // neighbour).
        assert_eq!(disc.coords.len(), 17 * 17 + 4 * 16 * 6);
        let ball = BallMesh::with_size(3, 1, 20.0, [0.0, 0.0, 25.0], 8.0).unwrap();
        assert_eq!(ball.num_elements(), 64 + 6 * 16);
        // Q1 nodes: 5³ in the cube, and on the one outer shell the 6·4² + 2 vertices of a cubed
        // sphere with 4 × 4 cells per face.
        assert_eq!(ball.coords.len(), 125 + (6 * 16 + 2));
    }

    #[test]
    fn contact_boundary_and_layers() {
        let disc = BallMesh::new(2, 1, 20.0, [0.0, 25.0, 0.0], 8, 3).unwrap();
        // 4 × 8 faces on the circle, half of them below the centre; their 16 + 1 nodes.
        assert_eq!(disc.boundary_faces.len(), 32);
        assert_eq!(disc.contact_faces.len(), 16);
        assert_eq!(disc.contact_nodes.len(), 17);
        // The lowest node is on the circle at (0, 5): the gap of contract §1.3.
        let low = disc.coords[disc.lowest_node()];
        assert!(low[0].abs() < 1e-12 && (low[1] - 5.0).abs() < 1e-12);
        // Layer 0: the 16 ring elements below the equator and the 2 above it that share an
        // equator node.
        assert_eq!(disc.layers.iter().filter(|&&l| l == 0).count(), 18);
        assert!(disc.layers.iter().all(|&l| l < usize::MAX));
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(BallMesh::new(2, 3, 1.0, [0.0; 3], 4, 2).is_err());
        assert!(BallMesh::new(2, 1, 1.0, [0.0; 3], 3, 2).is_err());
        assert!(BallMesh::new(4, 1, 1.0, [0.0; 3], 4, 2).is_err());
        assert!(BallMesh::with_size(2, 1, 20.0, [0.0; 3], -1.0).is_err());
        assert!(BallMesh::with_size(2, 1, 20.0, [0.0; 3], 50.0).is_err());
    }
}
