//! Meshes: the structured box of Q1 squares/cubes used by `bar2d`/`bar3d`, behind a small
//! [`Mesh`] trait ("an element = its node ids + its node coordinates") so that assembly and the
//! element routines never assume the box's constant Jacobian — a mapped disc or Q2 elements only
//! need another implementation of the trait.
//!
//! Numbering (the contract of the engine): nodes are lexicographic with x fastest, then y, then z;
//! element `e` lists its 2^d nodes in the same tensor order (local node a has offset bit k along
//! axis k), and elements are numbered lexicographically too. The last axis x_d is "vertical":
//! layer k is the slab of elements with x_d ∈ [k h, (k+1) h], layer 0 touches x_d = 0 (Γ_C).

use super::FeError;

/// What assembly needs from a mesh: dimension, nodes, and each element as node ids.
pub trait Mesh {
    /// Space dimension d (2 or 3).
    fn dim(&self) -> usize;
    fn num_nodes(&self) -> usize;
    fn num_elements(&self) -> usize;
    /// Nodes per element (2^d for Q1).
    fn nodes_per_element(&self) -> usize;
    /// Node ids of element `e`, in the element's reference (tensor) order.
    fn element_nodes(&self, e: usize) -> &[usize];
    /// Coordinates of a node (unused trailing components are 0).
    fn coord(&self, node: usize) -> [f64; 3];
}

/// Mass layers of a mesh (contract §2.2, §1.6): layer 0 = the cells with a node in `seed`, layer
/// k + 1 the cells not yet layered that share a node with layer k. Cells of a part never
/// reached (a body not connected to Γ_C) take one layer past the last.
///
/// Why a breadth-first search over the node → cells adjacency rather than a scan of every
/// cell per layer: the scan costs O(cells × layers), quadratic on a tall body (a 1 × n strip
/// has n layers: 13.6 s at n = 80 000, issue 36); here each cell and each node is visited once.
/// The layers are the scan's: a cell first reached from layer k shares a node with it and with
/// no earlier layer.
pub fn mesh_layers(mesh: &dyn Mesh, seed: &[usize]) -> Vec<usize> {
    let ne = mesh.num_elements();
    let nn = mesh.num_nodes();
    // Cells around each node (CSR).
    let mut start = vec![0usize; nn + 1];
    for e in 0..ne {
        for &n in mesh.element_nodes(e) {
            start[n + 1] += 1;
        }
    }
    for k in 0..nn {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut around = vec![0usize; start[nn]];
    for e in 0..ne {
        for &n in mesh.element_nodes(e) {
            around[fill[n]] = e;
            fill[n] += 1;
        }
    }
    let mut layers = vec![usize::MAX; ne];
    let mut node_done = vec![false; nn];
    let mut front: Vec<usize> = Vec::new();
    let mut reach = |n: usize, k: usize, layers: &mut Vec<usize>, next: &mut Vec<usize>| {
        if std::mem::replace(&mut node_done[n], true) {
            return;
        }
        for &e in &around[start[n]..start[n + 1]] {
            if layers[e] == usize::MAX {
                layers[e] = k;
                next.push(e);
            }
        }
    };
    for &n in seed {
        reach(n, 0, &mut layers, &mut front);
    }
    let mut k = 0;
    while !front.is_empty() {
        let mut next = Vec::new();
        for &e in &front {
            for &n in mesh.element_nodes(e) {
                reach(n, k + 1, &mut layers, &mut next);
            }
        }
        front = next;
        k += 1;
    }
    for l in layers.iter_mut().filter(|l| **l == usize::MAX) {
        *l = k;
    }
    layers
}

/// A box [0, L_1] × … × [0, L_d] cut into `cells[k]` equal elements along axis k.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxMesh {
    /// 2 or 3.
    pub dim: usize,
    /// Elements per axis (unused axes = 1).
    pub cells: [usize; 3],
    /// Element side per axis (unused axes = 0).
    pub spacing: [f64; 3],
    /// Node coordinates (third = 0 in 2D). Public so that tests may distort the mesh; the
    /// structured accessors (`node_id`, `nested_in`, …) then describe the topology only.
    pub coords: Vec<[f64; 3]>,
    /// Node ids, the first 2^dim used, tensor order: x fastest, then y, then z.
    pub elements: Vec<[usize; 8]>,
}

impl BoxMesh {
    /// The box of the given extent and cell counts.
    ///
    /// # Panics
    /// On an invalid shape (see [`BoxMesh::try_new`] for the fallible form).
    pub fn new(extent: &[f64], cells: &[usize]) -> BoxMesh {
        match BoxMesh::try_new(extent, cells) {
            Ok(m) => m,
            Err(e) => panic!("BoxMesh::new: {e}"),
        }
    }

    /// The box of the given extent and cell counts: `extent.len() == cells.len()` ∈ {2, 3},
    /// extents finite and > 0, counts ≥ 1.
    pub fn try_new(extent: &[f64], cells: &[usize]) -> Result<BoxMesh, FeError> {
        let dim = extent.len();
        if !(dim == 2 || dim == 3) || cells.len() != dim {
            return Err(FeError::BadMesh(format!(
                "extent has {} entries and cells {}; both must be 2 or 3 (the dimension)",
                extent.len(),
                cells.len()
            )));
        }
        if let Some(l) = extent.iter().find(|l| !(l.is_finite() && **l > 0.0)) {
            return Err(FeError::BadMesh(format!(
                "extent {l} is not a positive finite length"
            )));
        }
        if cells.contains(&0) {
            return Err(FeError::BadMesh("a cell count is 0".into()));
        }
        let mut c = [1usize; 3];
        let mut s = [0.0; 3];
        for k in 0..dim {
            c[k] = cells[k];
            s[k] = extent[k] / cells[k] as f64;
        }
        let np = [c[0] + 1, c[1] + 1, if dim == 3 { c[2] + 1 } else { 1 }];
        let mut coords = Vec::with_capacity(np[0] * np[1] * np[2]);
        for k in 0..np[2] {
            for j in 0..np[1] {
                for i in 0..np[0] {
                    // i·h rather than accumulated sums: the nodes of nested meshes coincide exactly
                    // only up to rounding; index arithmetic, not coordinates, defines nesting.
                    coords.push([
                        extent[0] * i as f64 / c[0] as f64,
                        extent[1] * j as f64 / c[1] as f64,
                        if dim == 3 {
                            extent[2] * k as f64 / c[2] as f64
                        } else {
                            0.0
                        },
                    ]);
                }
            }
        }
        let ne_z = if dim == 3 { c[2] } else { 1 };
        let mut elements = Vec::with_capacity(c[0] * c[1] * ne_z);
        let nid = |i: usize, j: usize, k: usize| i + np[0] * (j + np[1] * k);
        for ez in 0..ne_z {
            for ey in 0..c[1] {
                for ex in 0..c[0] {
                    let mut nodes = [0usize; 8];
                    for (a, node) in nodes.iter_mut().enumerate().take(1 << dim) {
                        *node = nid(ex + (a & 1), ey + ((a >> 1) & 1), ez + ((a >> 2) & 1));
                    }
                    elements.push(nodes);
                }
            }
        }
        Ok(BoxMesh {
            dim,
            cells: c,
            spacing: s,
            coords,
            elements,
        })
    }

    /// The box of the given extent with elements of side `h` on every axis; each extent must be
    /// a whole number of `h` (to 1e-9 relative), else the error says which axis.
    pub fn try_with_spacing(extent: &[f64], h: f64) -> Result<BoxMesh, FeError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(FeError::BadMesh(format!(
                "spacing {h} is not a positive finite length"
            )));
        }
        let mut cells = Vec::with_capacity(extent.len());
        for (k, &l) in extent.iter().enumerate() {
            let n = (l / h).round();
            if n < 1.0 || ((l / h) - n).abs() > 1e-9 * n {
                return Err(FeError::BadMesh(format!(
                    "extent {l} along axis {k} is not a whole number of elements of side {h}"
                )));
            }
            cells.push(n as usize);
        }
        BoxMesh::try_new(extent, &cells)
    }

    /// Nodes per axis (unused axes = 1).
    fn nodes_per_axis(&self) -> [usize; 3] {
        [
            self.cells[0] + 1,
            self.cells[1] + 1,
            if self.dim == 3 { self.cells[2] + 1 } else { 1 },
        ]
    }

    pub fn num_nodes(&self) -> usize {
        self.coords.len()
    }

    pub fn num_elements(&self) -> usize {
        self.elements.len()
    }

    /// 2^dim.
    pub fn nodes_per_element(&self) -> usize {
        1 << self.dim
    }

    /// Node id from its index per axis (lexicographic, x fastest).
    pub fn node_id(&self, idx: [usize; 3]) -> usize {
        let np = self.nodes_per_axis();
        idx[0] + np[0] * (idx[1] + np[1] * idx[2])
    }

    /// Index per axis of a node.
    pub fn node_index(&self, node: usize) -> [usize; 3] {
        let np = self.nodes_per_axis();
        [node % np[0], (node / np[0]) % np[1], node / (np[0] * np[1])]
    }

    /// Index along the vertical axis of element `e`: 0 for the elements touching x_d = 0.
    pub fn element_layer(&self, e: usize) -> usize {
        match self.dim {
            2 => e / self.cells[0],
            _ => e / (self.cells[0] * self.cells[1]),
        }
    }

    /// Number of element layers along x_d (`cells[dim-1]`).
    pub fn num_layers(&self) -> usize {
        self.cells[self.dim - 1]
    }

    /// The nodes with index `index` along `axis`, increasing (e.g. the bottom: `(dim-1, 0)`).
    pub fn nodes_on_plane(&self, axis: usize, index: usize) -> Vec<usize> {
        (0..self.num_nodes())
            .filter(|&n| self.node_index(n)[axis] == index)
            .collect()
    }

    /// |Ω| = Π L_k (of the undistorted box).
    pub fn volume(&self) -> f64 {
        (0..self.dim)
            .map(|k| self.spacing[k] * self.cells[k] as f64)
            .product()
    }

    /// Extent along each used axis.
    pub fn extent(&self) -> Vec<f64> {
        (0..self.dim)
            .map(|k| self.spacing[k] * self.cells[k] as f64)
            .collect()
    }

    /// A nested-dissection elimination order of the nodes (each node once): the index box is cut
    /// recursively across its longest axis by a plane of nodes, which is ordered after the two
    /// halves. A plane of nodes separates the Q1 graph (nodes on either side never share an
    /// element), so the Cholesky fill is O(n log n) in 2D and O(n^{4/3}) in 3D (George 1973).
    pub fn nested_dissection(&self) -> Vec<usize> {
        let np = self.nodes_per_axis();
        let mut order = Vec::with_capacity(self.num_nodes());
        self.dissect([0, 0, 0], np, &mut order);
        order
    }

    fn dissect(&self, lo: [usize; 3], hi: [usize; 3], order: &mut Vec<usize>) {
        let len = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let count = len[0] * len[1] * len[2];
        if count == 0 {
            return;
        }
        let axis = (0..3).max_by_key(|&k| (len[k], 3 - k)).expect("three axes");
        // Small boxes (or a box one separator wide) are eliminated in natural order.
        if count <= 16 || len[axis] < 3 {
            for k in lo[2]..hi[2] {
                for j in lo[1]..hi[1] {
                    for i in lo[0]..hi[0] {
                        order.push(self.node_id([i, j, k]));
                    }
                }
            }
            return;
        }
        let mid = lo[axis] + len[axis] / 2;
        let (mut hi_a, mut lo_b, mut sep_lo, mut sep_hi) = (hi, lo, lo, hi);
        hi_a[axis] = mid;
        lo_b[axis] = mid + 1;
        sep_lo[axis] = mid;
        sep_hi[axis] = mid + 1;
        self.dissect(lo, hi_a, order);
        self.dissect(lo_b, hi, order);
        for k in sep_lo[2]..sep_hi[2] {
            for j in sep_lo[1]..sep_hi[1] {
                for i in sep_lo[0]..sep_hi[0] {
                    order.push(self.node_id([i, j, k]));
                }
            }
        }
    }

    /// For each node of `self`, the id of the same point in the finer `fine`, when `fine` refines
    /// `self` by a whole ratio on every axis of the same box; `None` otherwise.
    pub fn nested_in(&self, fine: &BoxMesh) -> Option<Vec<usize>> {
        if fine.dim != self.dim {
            return None;
        }
        let mut ratio = [1usize; 3];
        for k in 0..self.dim {
            let (lc, lf) = (
                self.spacing[k] * self.cells[k] as f64,
                fine.spacing[k] * fine.cells[k] as f64,
            );
            if (lc - lf).abs() > 1e-12 * lc || !fine.cells[k].is_multiple_of(self.cells[k]) {
                return None;
            }
            ratio[k] = fine.cells[k] / self.cells[k];
        }
        Some(
            (0..self.num_nodes())
                .map(|n| {
                    let i = self.node_index(n);
                    fine.node_id([i[0] * ratio[0], i[1] * ratio[1], i[2] * ratio[2]])
                })
                .collect(),
        )
    }
}

impl Mesh for BoxMesh {
    fn dim(&self) -> usize {
        self.dim
    }
    fn num_nodes(&self) -> usize {
        self.coords.len()
    }
    fn num_elements(&self) -> usize {
        self.elements.len()
    }
    fn nodes_per_element(&self) -> usize {
        1 << self.dim
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        &self.elements[e][..1 << self.dim]
    }
    fn coord(&self, node: usize) -> [f64; 3] {
        self.coords[node]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbering_2d() {
        let m = BoxMesh::new(&[0.1, 1.0], &[2, 20]);
        assert_eq!(m.num_nodes(), 3 * 21);
        assert_eq!(m.num_elements(), 40);
        assert_eq!(m.node_id([2, 1, 0]), 5);
        assert_eq!(m.node_index(5), [2, 1, 0]);
        // Element 3 = (ex 1, ey 1): nodes (1,1) (2,1) (1,2) (2,2).
        assert_eq!(m.element_nodes(3), &[4, 5, 7, 8]);
        assert_eq!(m.element_layer(3), 1);
        assert_eq!(m.num_layers(), 20);
        assert_eq!(m.nodes_on_plane(1, 0), vec![0, 1, 2]);
        assert_eq!(m.nodes_on_plane(0, 2).len(), 21);
        // Coordinates are i·L/n: exact for these binary-unfriendly values up to one rounding.
        assert!((m.coords[8][0] - 0.1).abs() < 1e-16 && (m.coords[8][1] - 0.1).abs() < 1e-16);
        assert!((m.volume() - 0.1).abs() < 1e-16);
    }

    #[test]
    fn numbering_3d() {
        let m = BoxMesh::new(&[0.1, 0.1, 1.0], &[2, 2, 20]);
        assert_eq!(m.num_nodes(), 9 * 21);
        assert_eq!(m.num_elements(), 80);
        // Element 0: the 8 nodes of the first cube in tensor order.
        assert_eq!(m.element_nodes(0), &[0, 1, 3, 4, 9, 10, 12, 13]);
        assert_eq!(m.element_layer(7), 1);
        assert_eq!(m.nodes_on_plane(2, 0), (0..9).collect::<Vec<_>>());
        assert_eq!(m.node_index(m.node_id([1, 2, 3])), [1, 2, 3]);
    }

    #[test]
    fn nesting() {
        let c = BoxMesh::new(&[0.1, 1.0], &[2, 20]);
        let f = BoxMesh::new(&[0.1, 1.0], &[8, 80]);
        let map = c.nested_in(&f).unwrap();
        for (n, &m) in map.iter().enumerate() {
            // Same point up to the rounding of i·L/n on both meshes.
            for k in 0..2 {
                assert!((c.coords[n][k] - f.coords[m][k]).abs() < 1e-15);
            }
        }
        assert!(c.nested_in(&BoxMesh::new(&[0.1, 1.0], &[3, 80])).is_none());
        assert!(c.nested_in(&BoxMesh::new(&[0.2, 1.0], &[8, 80])).is_none());
    }

    #[test]
    fn nested_dissection_is_a_node_permutation() {
        for m in [
            BoxMesh::new(&[0.1, 1.0], &[4, 40]),
            BoxMesh::new(&[1.0, 1.0, 1.0], &[5, 6, 7]),
        ] {
            let mut o = m.nested_dissection();
            // The last node eliminated lies on the top-level separator: the middle plane of the
            // longest axis.
            let last = m.node_index(*o.last().unwrap());
            let axis = m.dim - 1;
            assert_eq!(last[axis], m.cells[axis].div_ceil(2));
            o.sort_unstable();
            assert_eq!(o, (0..m.num_nodes()).collect::<Vec<_>>());
        }
    }

    /// The breadth-first layers equal the definition's scan (layer k + 1 = the cells not yet
    /// layered with a node of an earlier layer), on a box seeded at a corner node: diagonal
    /// layers, and the box's rows when seeded along the bottom.
    #[test]
    fn layers_by_breadth_first_search() {
        let m = BoxMesh::new(&[1.0, 1.0], &[5, 4]);
        let bottom = m.nodes_on_plane(1, 0);
        let layers = mesh_layers(&m, &bottom);
        for e in 0..m.num_elements() {
            assert_eq!(layers[e], m.element_layer(e));
        }
        // Seeded at node 0: cell (i, j) is in layer max(i, j) (shared corners count).
        let corner = mesh_layers(&m, &[0]);
        for e in 0..m.num_elements() {
            assert_eq!(corner[e], (e % 5).max(e / 5), "cell {e}");
        }
        // Nothing seeded: every cell one past the last (empty) layer.
        assert!(mesh_layers(&m, &[]).iter().all(|&l| l == 0));
    }

    #[test]
    fn bad_shapes_are_errors() {
        assert!(BoxMesh::try_new(&[1.0], &[1]).is_err());
        assert!(BoxMesh::try_new(&[1.0, -1.0], &[1, 1]).is_err());
        assert!(BoxMesh::try_new(&[1.0, 1.0], &[1, 0]).is_err());
        let e = BoxMesh::try_with_spacing(&[0.1, 1.0], 0.03).unwrap_err();
        assert!(e.to_string().contains("axis 0"), "{e}");
        let m = BoxMesh::try_with_spacing(&[0.1, 1.0], 0.05).unwrap();
        assert_eq!(m.cells, [2, 20, 1]);
    }
}
