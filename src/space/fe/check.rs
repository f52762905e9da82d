//! Whole-mesh checks of a Gmsh mesh, made when it is read (so at plan time, before any run;
//! issue 36): a mesh the engine would run silently wrong on is refused with its reason.
//!
//! - Conformity. Every face of a cell (an edge in 2D, a triangle or quadrilateral in 3D, with
//!   its midside and face-centre nodes) is a face of at most one other cell; the two cells lie
//!   on either side of it (its vertex cycle, oriented outwards, is reversed in the other cell —
//!   with det J > 0 in both, same-side neighbours overlap); and both list the same nodes on it
//!   (a P2/Q2 edge whose midside node the neighbour does not share is a crack in the field).
//!   In 3D the midside node of every edge is also shared by every cell around the edge. A cell
//!   listed twice (the same vertices) is refused as such. Faces are bucketed by their smallest
//!   vertex, so the check is linear in the mesh size and holds no per-face key table.
//! - Coincident nodes: distinct nodes closer than 10⁻¹⁰ of the body's size (a crack made of
//!   duplicated nodes: two cells meet there but share no node). A hash grid of cell 2·tol, each
//!   node compared with the 2^d cells nearest to it, which hold every node within tol.
//! - Boundary groups: an element of `contact` or `clamped` has the type of the cells' faces
//!   (2-/3-node lines in 2D, 3-/6-node triangles or 4-/9-node quadrilaterals in 3D, the cells'
//!   degree) and is a face of exactly one cell, with the same nodes.
//! - det J > 0 on the whole of each cell, certified rather than sampled. det J is a polynomial
//!   on the reference cell: degree 2 on a P2 triangle, 3 on a P2 tetrahedron, (1, 1) on a Q1
//!   quadrilateral, (3, 3) on a Q2 one, (2, 2, 2) on a Q1 hexahedron, (5, 5, 5) on a Q2 one. Its
//!   Bernstein (Bézier) coefficients on the cell come from its values at the lattice of that
//!   degree (a fixed linear map); the polynomial lies between its smallest and largest
//!   coefficient (the Bernstein basis is a non-negative partition of unity), so coefficients
//!   above the degeneracy threshold certify the cell. Otherwise the cell is subdivided (longest
//!   edge bisection of simplices, halving of boxes) and each piece certified the same way — the
//!   coefficients converge to the values quadratically in the piece's size; a lattice value at
//!   or below the threshold refuses the cell as inverted or degenerate at that point, and a cell
//!   still uncertified after [`MAX_PIECES`] pieces is refused as such. Affine cells (P1, and P2
//!   with straight edges) have constant det J: every coefficient equal, certified at once.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use super::element_kind::{ElementKind, det_from_gradients};
use super::gmsh_error::GmshError;
use super::msh::type_name;

/// A cell's local face: its vertices as a cycle oriented outwards, and all its nodes.
#[derive(Debug, Clone)]
struct LocalFace {
    cycle: Vec<usize>,
    nodes: Vec<usize>,
}

/// The local faces and (3D, degree 2) edges of a cell kind, engine local order.
fn local_faces(kind: ElementKind) -> (Vec<LocalFace>, Vec<[usize; 3]>) {
    let r = kind.reference_nodes();
    let d = kind.dim();
    let nn = r.len();
    let is_vertex = |a: usize| {
        if kind.is_simplex() {
            a <= d
        } else {
            r[a][..d].iter().all(|x| x.abs() == 1.0)
        }
    };
    let lam = |p: [f64; 3], v: usize| {
        if v == 0 {
            1.0 - p[..d].iter().sum::<f64>()
        } else {
            p[v - 1]
        }
    };
    let mut centroid = [0.0; 3];
    let verts: Vec<usize> = (0..nn).filter(|&a| is_vertex(a)).collect();
    for &a in &verts {
        for k in 0..3 {
            centroid[k] += r[a][k] / verts.len() as f64;
        }
    }
    let mut faces = Vec::new();
    let mut sets: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
    if kind.is_simplex() {
        for v in 0..=d {
            let nodes: Vec<usize> = (0..nn).filter(|&a| lam(r[a], v).abs() < 1e-12).collect();
            let cycle: Vec<usize> = (0..=d).filter(|&a| a != v).collect();
            sets.push((cycle, nodes));
        }
    } else {
        for k in 0..d {
            for s in [-1.0, 1.0] {
                let nodes: Vec<usize> = (0..nn).filter(|&a| r[a][k] == s).collect();
                let (i, j) = match (d, k) {
                    (2, 0) => (1, 1),
                    (2, _) => (0, 0),
                    (_, 0) => (1, 2),
                    (_, 1) => (0, 2),
                    _ => (0, 1),
                };
                let corner = |u: f64, w: f64| {
                    *nodes
                        .iter()
                        .find(|&&a| is_vertex(a) && r[a][i] == u && r[a][j] == w)
                        .expect("a corner of the face")
                };
                let cycle = if d == 2 {
                    vec![corner(-1.0, -1.0), corner(1.0, 1.0)]
                } else {
                    vec![
                        corner(-1.0, -1.0),
                        corner(1.0, -1.0),
                        corner(1.0, 1.0),
                        corner(-1.0, 1.0),
                    ]
                };
                sets.push((cycle, nodes));
            }
        }
    }
    for (mut cycle, nodes) in sets {
        let p = |a: usize| r[a];
        let mut fc = [0.0; 3];
        for &a in &cycle {
            for k in 0..3 {
                fc[k] += p(a)[k] / cycle.len() as f64;
            }
        }
        let out = [
            fc[0] - centroid[0],
            fc[1] - centroid[1],
            fc[2] - centroid[2],
        ];
        let t = |a: usize, b: usize| [p(b)[0] - p(a)[0], p(b)[1] - p(a)[1], p(b)[2] - p(a)[2]];
        // The outward normal of a positively oriented cell's boundary traversed this way: in
        // 2D the right-hand normal of the edge, in 3D the right-hand rule of the cycle.
        let n = if d == 2 {
            let e = t(cycle[0], cycle[1]);
            [e[1], -e[0], 0.0]
        } else {
            let (u, v) = (t(cycle[0], cycle[1]), t(cycle[0], cycle[2]));
            [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ]
        };
        if n[0] * out[0] + n[1] * out[1] + n[2] * out[2] < 0.0 {
            cycle.reverse();
        }
        faces.push(LocalFace { cycle, nodes });
    }
    let mut edges = Vec::new();
    if d == 3 && kind.degree() == 2 {
        for (x, &a) in verts.iter().enumerate() {
            for &b in &verts[x + 1..] {
                let differ = (0..3).filter(|&k| r[a][k] != r[b][k]).count();
                if !kind.is_simplex() && differ != 1 {
                    continue;
                }
                let mid = [
                    0.5 * (r[a][0] + r[b][0]),
                    0.5 * (r[a][1] + r[b][1]),
                    0.5 * (r[a][2] + r[b][2]),
                ];
                if let Some(m) = (0..nn).find(|&m| r[m] == mid) {
                    edges.push([a, b, m]);
                }
            }
        }
    }
    (faces, edges)
}

/// Items bucketed by their smallest vertex (CSR over nodes).
struct Buckets {
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Buckets {
    fn new(num_nodes: usize, n: usize, min_vertex: impl Fn(usize) -> usize) -> Buckets {
        let mut start = vec![0u32; num_nodes + 1];
        for i in 0..n {
            start[min_vertex(i) + 1] += 1;
        }
        for k in 0..num_nodes {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; n];
        for i in 0..n {
            let s = &mut fill[min_vertex(i)];
            items[*s as usize] = i as u32;
            *s += 1;
        }
        Buckets { start, items }
    }

    fn of(&self, node: usize) -> &[u32] {
        &self.items[self.start[node] as usize..self.start[node + 1] as usize]
    }
}

/// A mesh's cells with their faces bucketed, for the conformity and boundary-group checks.
pub(crate) struct Topology<'a> {
    kind: ElementKind,
    nn: usize,
    elements: &'a [usize],
    node_tags: &'a [u64],
    element_tags: &'a [u64],
    faces: Vec<LocalFace>,
    edges: Vec<[usize; 3]>,
    /// Face i = (cell i / nf, local face i % nf), bucketed by its smallest vertex.
    buckets: Buckets,
}

impl<'a> Topology<'a> {
    pub(crate) fn new(
        kind: ElementKind,
        elements: &'a [usize],
        node_tags: &'a [u64],
        element_tags: &'a [u64],
    ) -> Topology<'a> {
        let (faces, edges) = local_faces(kind);
        let nn = kind.num_nodes();
        let nf = faces.len();
        let ne = elements.len() / nn;
        let buckets = Buckets::new(node_tags.len(), ne * nf, |i| {
            let cell = &elements[(i / nf) * nn..];
            faces[i % nf]
                .cycle
                .iter()
                .map(|&a| cell[a])
                .min()
                .unwrap_or(0)
        });
        Topology {
            kind,
            nn,
            elements,
            node_tags,
            element_tags,
            faces,
            edges,
            buckets,
        }
    }

    fn cell(&self, c: usize) -> &[usize] {
        &self.elements[c * self.nn..(c + 1) * self.nn]
    }

    /// Face i's vertex cycle (node ids).
    fn cycle(&self, i: usize) -> Vec<usize> {
        let nf = self.faces.len();
        let cell = self.cell(i / nf);
        self.faces[i % nf].cycle.iter().map(|&a| cell[a]).collect()
    }

    fn sorted(mut v: Vec<usize>) -> Vec<usize> {
        v.sort_unstable();
        v
    }

    /// Face i's nodes, sorted.
    fn face_nodes(&self, i: usize) -> Vec<usize> {
        let nf = self.faces.len();
        let cell = self.cell(i / nf);
        Self::sorted(self.faces[i % nf].nodes.iter().map(|&a| cell[a]).collect())
    }

    fn tags(&self, nodes: &[usize]) -> Vec<u64> {
        nodes.iter().map(|&n| self.node_tags[n]).collect()
    }

    /// Duplicate cells, conformity and orientation of shared faces, shared midside nodes.
    pub(crate) fn check(&self, file: &str) -> Result<(), GmshError> {
        self.check_duplicate_cells(file)?;
        self.check_faces(file)?;
        self.check_edge_midsides(file)
    }

    /// A cell listed twice: the same vertex set.
    fn check_duplicate_cells(&self, file: &str) -> Result<(), GmshError> {
        let f = || file.to_string();
        let ne = self.elements.len() / self.nn;
        let nv = if self.kind.is_simplex() {
            self.kind.dim() + 1
        } else {
            1 << self.kind.dim()
        };
        let vertex_local: Vec<usize> = {
            let mut v: Vec<usize> = self.faces.iter().flat_map(|f| f.cycle.clone()).collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        debug_assert_eq!(vertex_local.len(), nv);
        let key = |c: usize| Self::sorted(vertex_local.iter().map(|&a| self.cell(c)[a]).collect());
        let cells = Buckets::new(self.node_tags.len(), ne, |c| {
            vertex_local
                .iter()
                .map(|&a| self.cell(c)[a])
                .min()
                .unwrap_or(0)
        });
        for n in 0..self.node_tags.len() {
            let b = cells.of(n);
            if b.len() < 2 {
                continue;
            }
            let mut keyed: Vec<(Vec<usize>, usize)> =
                b.iter().map(|&c| (key(c as usize), c as usize)).collect();
            keyed.sort_unstable();
            for w in keyed.windows(2) {
                if w[0].0 == w[1].0 {
                    return Err(GmshError::DuplicateCell {
                        file: f(),
                        element: self.element_tags[w[1].1],
                        first: self.element_tags[w[0].1],
                    });
                }
            }
        }
        Ok(())
    }

    /// Every face shared by at most two cells, which lie on either side of it and list the
    /// same nodes on it.
    fn check_faces(&self, file: &str) -> Result<(), GmshError> {
        let f = || file.to_string();
        let nf = self.faces.len();
        for n in 0..self.node_tags.len() {
            let b = self.buckets.of(n);
            if b.len() < 2 {
                continue;
            }
            let mut keyed: Vec<(Vec<usize>, usize)> = b
                .iter()
                .map(|&i| (Self::sorted(self.cycle(i as usize)), i as usize))
                .collect();
            keyed.sort_unstable();
            let mut s = 0;
            while s < keyed.len() {
                let mut e = s + 1;
                while e < keyed.len() && keyed[e].0 == keyed[s].0 {
                    e += 1;
                }
                let group: Vec<usize> = keyed[s..e].iter().map(|x| x.1).collect();
                let cell_tag = |i: usize| self.element_tags[i / nf];
                if group.len() > 2 {
                    return Err(GmshError::FaceOverShared {
                        file: f(),
                        nodes: self.tags(&keyed[s].0),
                        cells: group.iter().take(4).map(|&i| cell_tag(i)).collect(),
                    });
                }
                if let [a, b] = group[..] {
                    let (ca, mut cb) = (self.cycle(a), self.cycle(b));
                    cb.reverse();
                    let k = cb.len();
                    // An edge (k = 2) is a directed segment, not a cycle: rotating it would
                    // reverse it.
                    let opposite = if k == 2 {
                        ca == cb
                    } else {
                        (0..k).any(|r| (0..k).all(|x| ca[x] == cb[(x + r) % k]))
                    };
                    if !opposite {
                        return Err(GmshError::SameSide {
                            file: f(),
                            a: cell_tag(a),
                            b: cell_tag(b),
                            nodes: self.tags(&keyed[s].0),
                        });
                    }
                    let (na, nb) = (self.face_nodes(a), self.face_nodes(b));
                    if na != nb {
                        let inner = |v: &[usize]| {
                            let inner: Vec<usize> =
                                v.iter().copied().filter(|x| !ca.contains(x)).collect();
                            self.tags(&inner)
                        };
                        return Err(GmshError::NotConforming {
                            file: f(),
                            a: cell_tag(a),
                            b: cell_tag(b),
                            vertices: self.tags(&keyed[s].0),
                            na: inner(&na),
                            nb: inner(&nb),
                        });
                    }
                }
                s = e;
            }
        }
        Ok(())
    }

    /// 3D degree 2: every cell around an edge has its midside node.
    fn check_edge_midsides(&self, file: &str) -> Result<(), GmshError> {
        let f = || file.to_string();
        let ne = self.elements.len() / self.nn;
        if !self.edges.is_empty() {
            let ned = self.edges.len();
            let ends = |i: usize| {
                let cell = self.cell(i / ned);
                let [a, b, m] = self.edges[i % ned];
                (cell[a].min(cell[b]), cell[a].max(cell[b]), cell[m])
            };
            let edges = Buckets::new(self.node_tags.len(), ne * ned, |i| ends(i).0);
            for n in 0..self.node_tags.len() {
                let mut seen: Vec<(usize, usize, usize)> = Vec::new();
                for &i in edges.of(n) {
                    let (a, b, m) = ends(i as usize);
                    if let Some(&(_, _, c)) = seen.iter().find(|x| x.0 == b) {
                        if self.cell(c).iter().all(|&x| x != m) {
                            let other = self
                                .edges
                                .iter()
                                .map(|e| {
                                    let cell = self.cell(c);
                                    (
                                        cell[e[0]].min(cell[e[1]]),
                                        cell[e[0]].max(cell[e[1]]),
                                        cell[e[2]],
                                    )
                                })
                                .find(|e| e.0 == a && e.1 == b)
                                .map_or(m, |e| e.2);
                            return Err(GmshError::NotConforming {
                                file: f(),
                                a: self.element_tags[c],
                                b: self.element_tags[i as usize / ned],
                                vertices: self.tags(&[a, b]),
                                na: self.tags(&[other]),
                                nb: self.tags(&[m]),
                            });
                        }
                    } else {
                        seen.push((b, m, i as usize / ned));
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether a boundary group's element of Gmsh type `element_type` with nodes `ids` (Gmsh's
    /// local order, vertices first) is a face of exactly one cell, with the same nodes.
    pub(crate) fn boundary_face(&self, element_type: i32, ids: &[usize]) -> Result<(), String> {
        let d = self.kind.dim();
        let p = self.kind.degree();
        let expected: &[i32] = match (d, p, self.kind.is_simplex()) {
            (2, 1, _) => &[1],
            (2, _, _) => &[8],
            (_, 1, true) => &[2],
            (_, _, true) => &[9],
            (_, 1, false) => &[3],
            _ => &[10],
        };
        if !expected.contains(&element_type) {
            return Err(format!(
                "a {}, but the faces of the mesh's {}s are {}s",
                type_name(element_type),
                self.kind.name(),
                type_name(expected[0])
            ));
        }
        let nv = match element_type {
            1 | 8 => 2,
            2 | 9 => 3,
            _ => 4,
        };
        let key = Self::sorted(ids[..nv].to_vec());
        let matches: Vec<usize> = self
            .buckets
            .of(key[0])
            .iter()
            .map(|&i| i as usize)
            .filter(|&i| Self::sorted(self.cycle(i)) == key)
            .collect();
        let nf = self.faces.len();
        match matches[..] {
            [] => Err(format!(
                "its vertices {:?} are no face of any cell",
                self.tags(&key)
            )),
            [i] => {
                if self.face_nodes(i) == Self::sorted(ids.to_vec()) {
                    Ok(())
                } else {
                    Err(format!(
                        "its nodes {:?} are not those of the face of element {} ({:?})",
                        self.tags(ids),
                        self.element_tags[i / nf],
                        self.tags(&self.face_nodes(i))
                    ))
                }
            }
            _ => Err(format!(
                "it is an interior face (between elements {} and {}), not on the body's boundary",
                self.element_tags[matches[0] / nf],
                self.element_tags[matches[1] / nf]
            )),
        }
    }
}

/// FxHash (rustc's): one multiply per word, for the grid of [`coincident_nodes`].
#[derive(Default)]
struct Fx(u64);

impl Hasher for Fx {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u64(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_i64(&mut self, w: i64) {
        self.write_u64(w as u64);
    }
}

/// The corners (lowest, highest coordinate per axis) of the box around the points `c`: the
/// body's size, which the tolerances of the coincident-node and 2D-plane checks are relative to.
pub(crate) fn bounding_box(c: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in c {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Relative distance under which two distinct nodes coincide: far below any cell a mesh
/// generator makes (a cell that small is refused as degenerate, relative det J 10⁻¹⁰), far
/// above the rounding of coordinates written with 16 digits.
pub(crate) const COINCIDENT: f64 = 1e-10;

/// The first pair of distinct nodes closer than [`COINCIDENT`] × the body's size, with their
/// distance.
///
/// Pairs for which `apart` holds (nodes of two bodies, which may touch) are let through.
pub(crate) fn coincident_nodes(
    dim: usize,
    coords: &[[f64; 3]],
    apart: &dyn Fn(usize, usize) -> bool,
) -> Result<(), (usize, usize, f64)> {
    let (lo, hi) = bounding_box(coords);
    let size = (0..dim).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    if coords.len() < 2 || size <= 0.0 {
        return Ok(());
    }
    let tol = COINCIDENT * size;
    let cell = 2.0 * tol;
    // Grid coordinates from the box's corner: at most 1/(2·10⁻¹⁰) = 5·10⁹ per axis.
    let key = |p: [f64; 3]| {
        let mut k = [0i64; 3];
        let mut half = [false; 3];
        for a in 0..dim {
            let g = (p[a] - lo[a]) / cell;
            k[a] = g.floor() as i64;
            half[a] = g - g.floor() >= 0.5;
        }
        (k, half)
    };
    let mut head: HashMap<[i64; 3], u32, BuildHasherDefault<Fx>> =
        HashMap::with_capacity_and_hasher(coords.len(), Default::default());
    let mut next = vec![u32::MAX; coords.len()];
    for (i, &p) in coords.iter().enumerate() {
        let (k, _) = key(p);
        if let Some(h) = head.insert(k, i as u32) {
            next[i] = h;
        }
    }
    for (i, &p) in coords.iter().enumerate() {
        let (k, half) = key(p);
        for m in 0..(1usize << dim) {
            let mut q = k;
            for a in 0..dim {
                if m >> a & 1 == 1 {
                    q[a] += if half[a] { 1 } else { -1 };
                }
            }
            let mut j = head.get(&q).copied().unwrap_or(u32::MAX);
            while j != u32::MAX {
                let jj = j as usize;
                if jj != i {
                    let c = coords[jj];
                    let r = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2))
                        .sqrt();
                    if r <= tol && !apart(i, jj) {
                        return Err((i.min(jj), i.max(jj), r));
                    }
                }
                j = next[jj];
            }
        }
    }
    Ok(())
}

/// Pieces a cell may be cut into before it is refused as not certified: a cell whose det J
/// dips to 10⁻³ of its mean is certified after a few levels; a budget bounds the cost of a
/// nearly degenerate one.
pub const MAX_PIECES: usize = 256;

/// Relative det J under which a cell is degenerate (as the point checks of `GmshMesh`).
const DEGENERATE: f64 = 1e-10;

/// The Bernstein basis of det J's degree on a kind's reference cell.
struct Bernstein {
    /// Lattice points of the reference cell (simplex: the unit simplex; box: [−1, 1]^d).
    lattice: Vec<[f64; 3]>,
    /// Simplex: the inverse of the collocation matrix V[i][j] = B_j(lattice_i), row-major.
    /// Box: the 1D inverse ((n+1) × (n+1)), applied along each axis.
    inverse: Vec<f64>,
    /// Polynomial degree (per axis for boxes).
    n: usize,
    simplex: bool,
    dim: usize,
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// Invert a small dense matrix (Gauss–Jordan with partial pivoting).
fn invert(mut a: Vec<f64>, n: usize) -> Vec<f64> {
    let mut inv = vec![0.0; n * n];
    for i in 0..n {
        inv[i * n + i] = 1.0;
    }
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&x, &y| a[x * n + col].abs().total_cmp(&a[y * n + col].abs()))
            .unwrap_or(col);
        for k in 0..n {
            a.swap(col * n + k, piv * n + k);
            inv.swap(col * n + k, piv * n + k);
        }
        let p = a[col * n + col];
        for k in 0..n {
            a[col * n + k] /= p;
            inv[col * n + k] /= p;
        }
        for r in 0..n {
            if r != col {
                let m = a[r * n + col];
                if m != 0.0 {
                    for k in 0..n {
                        a[r * n + k] -= m * a[col * n + k];
                        inv[r * n + k] -= m * inv[col * n + k];
                    }
                }
            }
        }
    }
    inv
}

impl Bernstein {
    fn new(kind: ElementKind) -> Option<Bernstein> {
        let d = kind.dim();
        let (n, simplex) = match kind {
            ElementKind::Tri3 | ElementKind::Tet4 => return None,
            ElementKind::Tri6 => (2, true),
            ElementKind::Tet10 => (3, true),
            ElementKind::Quad4 => (1, false),
            ElementKind::Quad9 => (3, false),
            ElementKind::Hex8 => (2, false),
            ElementKind::Hex27 => (5, false),
        };
        if simplex {
            // Multi-indices α (d + 1 entries, sum n); lattice point ξ_k = α_{k+1}/n.
            let mut alphas: Vec<[usize; 4]> = Vec::new();
            for a1 in 0..=n {
                for a2 in 0..=n - a1 {
                    if d == 2 {
                        alphas.push([n - a1 - a2, a1, a2, 0]);
                    } else {
                        for a3 in 0..=n - a1 - a2 {
                            alphas.push([n - a1 - a2 - a3, a1, a2, a3]);
                        }
                    }
                }
            }
            let lattice: Vec<[f64; 3]> = alphas
                .iter()
                .map(|a| {
                    [
                        a[1] as f64 / n as f64,
                        a[2] as f64 / n as f64,
                        a[3] as f64 / n as f64,
                    ]
                })
                .collect();
            let m = alphas.len();
            let mut v = vec![0.0; m * m];
            for (i, p) in lattice.iter().enumerate() {
                let lam = [1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]];
                for (j, a) in alphas.iter().enumerate() {
                    let mut coef = 1.0;
                    let mut rest = n;
                    let mut b = 1.0;
                    for k in 0..=d {
                        coef *= binomial(rest, a[k]);
                        rest -= a[k];
                        b *= lam[k].powi(a[k] as i32);
                    }
                    v[i * m + j] = coef * b;
                }
            }
            Some(Bernstein {
                lattice,
                inverse: invert(v, m),
                n,
                simplex,
                dim: d,
            })
        } else {
            let t: Vec<f64> = (0..=n).map(|i| i as f64 / n as f64).collect();
            let mut v = vec![0.0; (n + 1) * (n + 1)];
            for (i, &x) in t.iter().enumerate() {
                for j in 0..=n {
                    v[i * (n + 1) + j] =
                        binomial(n, j) * x.powi(j as i32) * (1.0 - x).powi((n - j) as i32);
                }
            }
            let mut lattice = Vec::new();
            let m = n + 1;
            let zs = if d == 3 { m } else { 1 };
            for c in 0..zs {
                for b in 0..m {
                    for a in 0..m {
                        lattice.push([
                            2.0 * t[a] - 1.0,
                            2.0 * t[b] - 1.0,
                            if d == 3 { 2.0 * t[c] - 1.0 } else { 0.0 },
                        ]);
                    }
                }
            }
            Some(Bernstein {
                lattice,
                inverse: invert(v, m),
                n,
                simplex,
                dim: d,
            })
        }
    }

    /// Bernstein coefficients from the values at the lattice (of the piece).
    fn coefficients(&self, values: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let m = values.len();
        if self.simplex {
            for i in 0..m {
                out.push((0..m).map(|j| self.inverse[i * m + j] * values[j]).sum());
            }
            return;
        }
        // Tensor: the 1D inverse along each axis in turn (x fastest in the lattice).
        let q = self.n + 1;
        out.extend_from_slice(values);
        let mut tmp = vec![0.0; m];
        let mut stride = 1;
        for _ in 0..self.dim {
            for (idx, t) in tmp.iter_mut().enumerate() {
                let i = (idx / stride) % q;
                let base = idx - i * stride;
                *t = (0..q)
                    .map(|j| self.inverse[i * q + j] * out[base + j * stride])
                    .sum();
            }
            out.copy_from_slice(&tmp);
            stride *= q;
        }
    }
}

/// A piece of the reference cell: a simplex (its vertices) or a box (its corners lo, hi).
#[derive(Clone)]
enum Piece {
    Simplex(Vec<[f64; 3]>),
    Box([f64; 3], [f64; 3]),
}

impl Piece {
    /// The whole reference cell of `kind`.
    fn root(kind: ElementKind) -> Piece {
        let d = kind.dim();
        if kind.is_simplex() {
            let mut v = vec![[0.0; 3]];
            for k in 0..d {
                let mut e = [0.0; 3];
                e[k] = 1.0;
                v.push(e);
            }
            Piece::Simplex(v)
        } else {
            let mut lo = [0.0; 3];
            let mut hi = [0.0; 3];
            for k in 0..d {
                lo[k] = -1.0;
                hi[k] = 1.0;
            }
            Piece::Box(lo, hi)
        }
    }

    /// The Bernstein lattice of `bern` mapped onto this piece (reference coordinates).
    fn lattice(&self, bern: &Bernstein, d: usize) -> Vec<[f64; 3]> {
        match self {
            Piece::Simplex(v) => bern
                .lattice
                .iter()
                .map(|p| {
                    let lam = [1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]];
                    let mut q = [0.0; 3];
                    for (k, vk) in v.iter().enumerate() {
                        for a in 0..3 {
                            q[a] += lam[k] * vk[a];
                        }
                    }
                    q
                })
                .collect(),
            Piece::Box(lo, hi) => bern
                .lattice
                .iter()
                .map(|p| {
                    let mut q = [0.0; 3];
                    for a in 0..d {
                        q[a] = lo[a] + 0.5 * (p[a] + 1.0) * (hi[a] - lo[a]);
                    }
                    q
                })
                .collect(),
        }
    }

    /// Cut the piece in two (a simplex: bisection of its longest edge) or 2^d (a box: halving
    /// along each axis), pushed onto `stack`.
    fn subdivide(self, d: usize, stack: &mut Vec<Piece>) {
        match self {
            Piece::Simplex(v) => {
                // Bisect the longest edge.
                let mut best = (0, 1, -1.0);
                for a in 0..v.len() {
                    for b in a + 1..v.len() {
                        let l: f64 = (0..3).map(|k| (v[a][k] - v[b][k]).powi(2)).sum();
                        if l > best.2 {
                            best = (a, b, l);
                        }
                    }
                }
                let (a, b, _) = best;
                let m = [
                    0.5 * (v[a][0] + v[b][0]),
                    0.5 * (v[a][1] + v[b][1]),
                    0.5 * (v[a][2] + v[b][2]),
                ];
                let mut one = v.clone();
                one[a] = m;
                let mut two = v;
                two[b] = m;
                stack.push(Piece::Simplex(one));
                stack.push(Piece::Simplex(two));
            }
            Piece::Box(lo, hi) => {
                for m in 0..(1usize << d) {
                    let (mut l, mut h) = (lo, hi);
                    for a in 0..d {
                        let mid = 0.5 * (lo[a] + hi[a]);
                        if m >> a & 1 == 1 {
                            l[a] = mid;
                        } else {
                            h[a] = mid;
                        }
                    }
                    stack.push(Piece::Box(l, h));
                }
            }
        }
    }
}

/// Why a cell's det J is not certified positive.
pub(crate) enum JacobianFailure {
    Inverted {
        cell: usize,
        det: f64,
        xi: [f64; 3],
    },
    Degenerate {
        cell: usize,
        det: f64,
        relative: f64,
        xi: [f64; 3],
    },
    NotCertified {
        cell: usize,
        min: f64,
        pieces: usize,
    },
}

impl JacobianFailure {
    pub(crate) fn into_gmsh(self, file: String, element_tags: &[u64]) -> GmshError {
        match self {
            JacobianFailure::Inverted { cell, det, xi } => GmshError::Inverted {
                file,
                element: element_tags[cell],
                det,
                xi,
            },
            JacobianFailure::Degenerate {
                cell,
                det,
                relative,
                xi,
            } => GmshError::Degenerate {
                file,
                element: element_tags[cell],
                det,
                relative,
                xi,
            },
            JacobianFailure::NotCertified { cell, min, pieces } => GmshError::NotCertified {
                file,
                element: element_tags[cell],
                min,
                pieces,
            },
        }
    }
}

/// Certify det J > 0 on every cell (module header).
pub(crate) fn certify_jacobians(
    kind: ElementKind,
    coords: &[[f64; 3]],
    elements: &[usize],
) -> Result<(), JacobianFailure> {
    let Some(bern) = Bernstein::new(kind) else {
        return Ok(());
    };
    let d = kind.dim();
    let nn = kind.num_nodes();
    let root_grads: Vec<Vec<[f64; 3]>> = bern
        .lattice
        .iter()
        .map(|&xi| kind.shape_gradients(xi))
        .collect();
    let ref_measure = if kind.is_simplex() {
        0.5
    } else {
        2f64.powi(-(d as i32))
    };
    let mut x = vec![[0.0; 3]; nn];
    let mut values = vec![0.0; bern.lattice.len()];
    let mut coefs = Vec::with_capacity(values.len());
    let root = Piece::root(kind);
    for (c, cell) in elements.chunks_exact(nn).enumerate() {
        for (xa, &n) in x.iter_mut().zip(cell) {
            *xa = coords[n];
        }
        let mut diam: f64 = 0.0;
        for a in 0..nn {
            for b in a + 1..nn {
                let r = (0..3).map(|k| (x[a][k] - x[b][k]).powi(2)).sum::<f64>();
                diam = diam.max(r.sqrt());
            }
        }
        let threshold = DEGENERATE * diam.powi(d as i32) * ref_measure;
        let mut stack = vec![root.clone()];
        let mut pieces = 0;
        let mut worst = f64::INFINITY;
        while let Some(piece) = stack.pop() {
            pieces += 1;
            // The lattice of the piece and det J there.
            let points: Vec<[f64; 3]> = if pieces == 1 {
                bern.lattice.clone()
            } else {
                piece.lattice(&bern, d)
            };
            for (i, &xi) in points.iter().enumerate() {
                let det = if pieces == 1 {
                    det_from_gradients(d, &x, &root_grads[i])
                } else {
                    det_from_gradients(d, &x, &kind.shape_gradients(xi))
                };
                if det.is_nan() || det.abs() <= threshold {
                    return Err(JacobianFailure::Degenerate {
                        cell: c,
                        det,
                        relative: det / (threshold / DEGENERATE),
                        xi,
                    });
                }
                if det < 0.0 {
                    return Err(JacobianFailure::Inverted { cell: c, det, xi });
                }
                values[i] = det;
            }
            bern.coefficients(&values, &mut coefs);
            let min = coefs.iter().copied().fold(f64::INFINITY, f64::min);
            if min > threshold {
                continue;
            }
            worst = worst.min(min);
            if pieces + stack.len() >= MAX_PIECES {
                return Err(JacobianFailure::NotCertified {
                    cell: c,
                    min: worst / (threshold / DEGENERATE),
                    pieces,
                });
            }
            piece.subdivide(d, &mut stack);
        }
    }
    Ok(())
}
