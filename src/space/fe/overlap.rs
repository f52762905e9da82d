//! The geometric check of a Gmsh mesh (issue 42): no two cells of the body intersect other than
//! along what they share — a face, an edge, a vertex — or along a boundary they merely touch.
//! The other whole-mesh checks (`check.rs`) are topological: a cell laid over others without
//! sharing a face with them passes them all, and the engine would count that region twice.
//!
//! - Pieces. Each cell is cut into straight-sided simplices (triangles in 2D, tetrahedra in 3D):
//!   a P1 cell is itself; a Q1 quadrilateral (convex: det J > 0 at its corners) two triangles;
//!   a Q1 hexahedron twelve tetrahedra, each a triangle of a face with the cell's centroid, a
//!   face's quadrilateral cut along the diagonal through its vertex of smallest node id (so two
//!   cells sharing a face — bilinear, in general not plane — cut it alike and their pieces meet
//!   along the same triangles); a P2 triangle the four triangles of its six nodes, a P2
//!   tetrahedron the eight tetrahedra of its ten (four at the corners, the inner octahedron cut
//!   along one diagonal), a Q2 cell the 4 or 8 Q1 cells of its 9 or 27 nodes, cut as above.
//!   Why pieces on the nodes for the curved cells: two neighbours share the nodes of their
//!   common face, so their pieces share the same straight faces and meet exactly, as the cells
//!   do; the pieces depart from the curved cell by O(h²κ) only inside it, where no other cell
//!   is. Testing the cells' convex hulls instead would refuse every curved mesh (the hull of a
//!   cell with a convex edge reaches into the neighbour across that edge).
//! - Broad phase. The pieces are sorted along a Morton curve of their centroids (a radix sort,
//!   linear), grouped by [`LEAF`] consecutive pieces into leaves, and the leaves' boxes paired
//!   up level by level into a bounding-box tree; the tree is joined with itself (two subtrees
//!   are compared only if their boxes overlap), so the work is O(n log n) for any grading of the
//!   mesh, and O(n) pairs of pieces reach the exact test on a mesh of well-shaped cells.
//! - Exact test. Two convex pieces overlap by their penetration depth: the smallest
//!   translation that separates them, which is the smallest overlap of their projections on the
//!   separating axes of the separating-axis theorem — the normals of the pieces' edges (2D) or
//!   faces, and the cross products of an edge of each (3D). Pieces of one cell are not compared.
//!   Two cells overlap when two of their pieces do by more than [`OVERLAP`] × the smaller
//!   piece's size. Shared faces, edges and vertices give a depth of 0 up to round-off (a shared
//!   face's plane separates the pieces exactly), and so do cells touching along a boundary.

use super::check::bounding_box;
use super::element_kind::ElementKind;

/// Relative penetration depth under which two pieces merely touch: a fraction of the smaller
/// piece's size (its longest bounding-box side). Above round-off by far: the depth of pieces
/// that share a face, an edge or a vertex is computed from coordinates relative to one of their
/// vertices, so its error is ~10⁻¹⁶ of the pieces' size; a hanging node written with 9
/// significant digits lies within ~10⁻⁹ of the body's size of the edge it hangs on. Below any
/// overlap that matters by far: a layer 10⁻⁶ of a cell thick adds 10⁻⁶ of the cell's measure,
/// under the engine's quadrature errors, while the overlaps a bad mesh makes (a cell laid over
/// its neighbours, a node pushed through the boundary) are a sizeable part of a cell.
pub(crate) const OVERLAP: f64 = 1e-6;

/// Pieces per leaf of the tree: small enough that the all-pairs test inside a leaf pair is
/// cheap, large enough that the tree's boxes cost little next to the pieces.
const LEAF: usize = 4;

/// Two overlapping cells (indices, `a` < `b`), the depth of their deepest overlapping pieces
/// and that depth relative to the smaller piece.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Overlap {
    pub a: usize,
    pub b: usize,
    pub depth: f64,
    pub relative: f64,
}

/// The first pair of cells found overlapping (module header), if any.
pub(crate) fn overlapping_cells(
    kind: ElementKind,
    coords: &[[f64; 3]],
    elements: &[usize],
) -> Result<(), Overlap> {
    let pieces = Pieces::new(kind, coords, elements);
    let n = pieces.len();
    if n < 2 {
        return Ok(());
    }
    let order = morton_order(&pieces, coords);
    let tree = Tree::new(&pieces, &order);
    tree.self_join(&pieces, &order)
}

/// A cell's straight-sided simplices (module header): vertex indices into the mesh's nodes
/// (below `coords.len()`) or into `extra` (the hexahedra's centroids), and the cell of each.
struct Pieces<'a> {
    dim: usize,
    coords: &'a [[f64; 3]],
    extra: Vec<[f64; 3]>,
    /// `dim + 1` vertices per piece.
    verts: Vec<u32>,
    owner: Vec<u32>,
}

impl<'a> Pieces<'a> {
    fn new(kind: ElementKind, coords: &'a [[f64; 3]], elements: &[usize]) -> Pieces<'a> {
        let nn = kind.num_nodes();
        let dim = kind.dim();
        let mut p = Pieces {
            dim,
            coords,
            extra: Vec::new(),
            verts: Vec::new(),
            owner: Vec::new(),
        };
        let ne = elements.len() / nn;
        match kind {
            ElementKind::Tri3 | ElementKind::Tet4 => {
                // The cells themselves (the 10⁶-node case: no copy beyond the u32 indices).
                p.verts = elements.iter().map(|&i| i as u32).collect();
                p.owner = (0..ne as u32).collect();
                return p;
            }
            _ => {}
        }
        for (c, cell) in elements.chunks_exact(nn).enumerate() {
            let c = c as u32;
            match kind {
                ElementKind::Tri6 => {
                    for t in [[0, 3, 5], [1, 4, 3], [2, 5, 4], [3, 4, 5]] {
                        p.push(c, &t.map(|a| cell[a]));
                    }
                }
                ElementKind::Tet10 => {
                    // Corners, then the octahedron of the midpoints around its diagonal m01–m32
                    // (nodes 4 and 8), whose equator is m20, m30, m31, m12 (6, 7, 9, 5).
                    for t in [
                        [0, 4, 6, 7],
                        [1, 4, 5, 9],
                        [2, 5, 6, 8],
                        [3, 7, 8, 9],
                        [4, 8, 6, 7],
                        [4, 8, 7, 9],
                        [4, 8, 9, 5],
                        [4, 8, 5, 6],
                    ] {
                        p.push(c, &t.map(|a| cell[a]));
                    }
                }
                ElementKind::Quad4 => p.quad(c, [cell[0], cell[1], cell[3], cell[2]]),
                ElementKind::Quad9 => {
                    for (a, b) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let at = |i: usize, j: usize| cell[(a + i) + 3 * (b + j)];
                        p.quad(c, [at(0, 0), at(1, 0), at(1, 1), at(0, 1)]);
                    }
                }
                ElementKind::Hex8 => {
                    let mut corners = [0; 8];
                    corners.copy_from_slice(cell);
                    p.hex(c, corners);
                }
                _ => {
                    for s in 0..8 {
                        let (a, b, e) = (s & 1, s >> 1 & 1, s >> 2);
                        let corners: [usize; 8] = std::array::from_fn(|k| {
                            let (i, j, l) = (k & 1, k >> 1 & 1, k >> 2);
                            cell[(a + i) + 3 * (b + j) + 9 * (e + l)]
                        });
                        p.hex(c, corners);
                    }
                }
            }
        }
        p
    }

    fn len(&self) -> usize {
        self.owner.len()
    }

    fn point(&self, v: u32) -> [f64; 3] {
        let v = v as usize;
        if v < self.coords.len() {
            self.coords[v]
        } else {
            self.extra[v - self.coords.len()]
        }
    }

    fn push(&mut self, cell: u32, verts: &[usize]) {
        self.verts.extend(verts.iter().map(|&v| v as u32));
        self.owner.push(cell);
    }

    /// A 2D quadrilateral (vertices in cyclic order) as two triangles, cut along a diagonal
    /// inside it: the one whose two triangles have the quadrilateral's orientation (both do
    /// for a convex one; for a non-convex one only the diagonal from its reflex vertex).
    fn quad(&mut self, cell: u32, q: [usize; 4]) {
        let x = q.map(|v| self.coords[v]);
        let area = |a: usize, b: usize, c: usize| {
            (x[b][0] - x[a][0]) * (x[c][1] - x[a][1]) - (x[b][1] - x[a][1]) * (x[c][0] - x[a][0])
        };
        let (s, t) = (area(0, 1, 2), area(0, 2, 3));
        if s * t > 0.0 || area(1, 2, 3) * area(1, 3, 0) <= 0.0 {
            self.push(cell, &[q[0], q[1], q[2]]);
            self.push(cell, &[q[0], q[2], q[3]]);
        } else {
            self.push(cell, &[q[1], q[2], q[3]]);
            self.push(cell, &[q[1], q[3], q[0]]);
        }
    }

    /// A trilinear hexahedron (corners in tensor order, k = i + 2j + 4l) as twelve tetrahedra:
    /// each face cut along its diagonal through the vertex of smallest node id, each triangle
    /// joined to the centroid of the corners (appended to `extra`).
    fn hex(&mut self, cell: u32, corners: [usize; 8]) {
        let mut centre = [0.0; 3];
        for &v in &corners {
            for k in 0..3 {
                centre[k] += self.coords[v][k] / 8.0;
            }
        }
        let centre_id = self.coords.len() + self.extra.len();
        self.extra.push(centre);
        for axis in 0..3 {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            for side in 0..2 {
                let at = |a: usize, b: usize| {
                    let mut ijk = [0; 3];
                    ijk[axis] = side;
                    ijk[u] = a;
                    ijk[w] = b;
                    corners[ijk[0] + 2 * ijk[1] + 4 * ijk[2]]
                };
                let f = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
                let m = (0..4).min_by_key(|&k| f[k]).unwrap_or(0);
                let g = |k: usize| f[(m + k) % 4];
                self.push(cell, &[g(0), g(1), g(2), centre_id]);
                self.push(cell, &[g(0), g(2), g(3), centre_id]);
            }
        }
    }

    /// Piece `p`'s vertices.
    fn vertices(&self, p: usize) -> [[f64; 3]; 4] {
        let nv = self.dim + 1;
        let mut x = [[0.0; 3]; 4];
        for (k, &v) in self.verts[p * nv..(p + 1) * nv].iter().enumerate() {
            x[k] = self.point(v);
        }
        x
    }
}

/// Axis-aligned box: lowest and highest corner.
#[derive(Clone, Copy)]
struct Aabb {
    lo: [f64; 3],
    hi: [f64; 3],
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    fn of(x: &[[f64; 3]]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in x {
            for k in 0..3 {
                b.lo[k] = b.lo[k].min(p[k]);
                b.hi[k] = b.hi[k].max(p[k]);
            }
        }
        b
    }

    fn union(self, o: Aabb) -> Aabb {
        Aabb {
            lo: std::array::from_fn(|k| self.lo[k].min(o.lo[k])),
            hi: std::array::from_fn(|k| self.hi[k].max(o.hi[k])),
        }
    }

    /// Whether the boxes overlap by more than `tol` along every axis (of `dim`): otherwise
    /// the projections of whatever they hold overlap by at most `tol` on that axis, so the
    /// penetration depth is at most `tol`.
    fn overlap(&self, o: &Aabb, dim: usize, tol: f64) -> bool {
        (0..dim).all(|k| self.hi[k].min(o.hi[k]) - self.lo[k].max(o.lo[k]) > tol)
    }

    fn size(&self, dim: usize) -> f64 {
        (0..dim)
            .map(|k| self.hi[k] - self.lo[k])
            .fold(0.0, f64::max)
    }
}

/// The pieces in Morton order of their centroids (16 bits per axis in 2D, 10 in 3D), by a
/// two-pass radix sort of 16-bit digits.
fn morton_order(pieces: &Pieces, coords: &[[f64; 3]]) -> Vec<u32> {
    let dim = pieces.dim;
    let nv = dim + 1;
    let (lo, hi) = bounding_box(coords);
    let bits = if dim == 2 { 16 } else { 10 };
    let top = ((1u32 << bits) - 1) as f64;
    let scale: [f64; 3] = std::array::from_fn(|k| {
        let e = hi[k] - lo[k];
        if e > 0.0 { top / e } else { 0.0 }
    });
    let n = pieces.len();
    let mut keyed: Vec<(u32, u32)> = (0..n)
        .map(|p| {
            let x = pieces.vertices(p);
            let mut code = 0u32;
            for k in 0..dim {
                let c = x[..nv].iter().map(|q| q[k]).sum::<f64>() / nv as f64;
                let q = ((c - lo[k]) * scale[k]).clamp(0.0, top) as u32;
                for b in 0..bits {
                    code |= (q >> b & 1) << (b * dim + k);
                }
            }
            (code, p as u32)
        })
        .collect();
    let mut tmp = vec![(0u32, 0u32); n];
    for shift in [0, 16] {
        let mut count = vec![0usize; 1 << 16];
        for &(c, _) in &keyed {
            count[(c >> shift & 0xffff) as usize] += 1;
        }
        let mut sum = 0;
        for c in count.iter_mut() {
            let k = *c;
            *c = sum;
            sum += k;
        }
        for &e in &keyed {
            let slot = &mut count[(e.0 >> shift & 0xffff) as usize];
            tmp[*slot] = e;
            *slot += 1;
        }
        std::mem::swap(&mut keyed, &mut tmp);
    }
    keyed.into_iter().map(|(_, p)| p).collect()
}

/// A piece gathered for the exact test: vertices, box, size (longest box side), cell.
#[derive(Clone, Copy)]
struct Gathered {
    x: [[f64; 3]; 4],
    bbox: Aabb,
    size: f64,
    owner: u32,
}

/// The bounding-box tree over the pieces in Morton order: level 0 the leaves ([`LEAF`]
/// consecutive pieces each), level k + 1 node i the union of level k nodes 2i and 2i + 1.
struct Tree {
    levels: Vec<Vec<Aabb>>,
}

/// A pending comparison of the self-join: a subtree with itself, or two subtrees (level, node).
enum Task {
    Within(usize, usize),
    Across((usize, usize), (usize, usize)),
}

impl Tree {
    fn new(pieces: &Pieces, order: &[u32]) -> Tree {
        let nv = pieces.dim + 1;
        let leaves: Vec<Aabb> = order
            .chunks(LEAF)
            .map(|chunk| {
                chunk.iter().fold(Aabb::EMPTY, |b, &p| {
                    b.union(Aabb::of(&pieces.vertices(p as usize)[..nv]))
                })
            })
            .collect();
        let mut levels = vec![leaves];
        while levels.last().is_some_and(|l| l.len() > 1) {
            let below = levels.last().map_or(&[][..], |l| &l[..]);
            let up: Vec<Aabb> = below
                .chunks(2)
                .map(|c| c.iter().fold(Aabb::EMPTY, |b, &x| b.union(x)))
                .collect();
            levels.push(up);
        }
        Tree { levels }
    }

    /// Compare every pair of pieces whose boxes overlap (module header), subtree against
    /// subtree, depth first; the first overlapping pair of cells ends the search.
    fn self_join(&self, pieces: &Pieces, order: &[u32]) -> Result<(), Overlap> {
        let dim = pieces.dim;
        let gather = |leaf: usize, out: &mut Vec<Gathered>| {
            out.clear();
            let end = ((leaf + 1) * LEAF).min(order.len());
            for &p in &order[leaf * LEAF..end] {
                let p = p as usize;
                let x = pieces.vertices(p);
                let bbox = Aabb::of(&x[..dim + 1]);
                out.push(Gathered {
                    x,
                    bbox,
                    size: bbox.size(dim),
                    owner: pieces.owner[p],
                });
            }
        };
        let (mut ga, mut gb) = (Vec::with_capacity(LEAF), Vec::with_capacity(LEAF));
        let top = self.levels.len() - 1;
        let mut stack = vec![Task::Within(top, 0)];
        while let Some(task) = stack.pop() {
            match task {
                Task::Within(0, i) => {
                    gather(i, &mut ga);
                    for (k, a) in ga.iter().enumerate() {
                        for b in &ga[k + 1..] {
                            test_pair(dim, a, b)?;
                        }
                    }
                }
                Task::Within(l, i) => {
                    let below = &self.levels[l - 1];
                    let (c0, c1) = (2 * i, 2 * i + 1);
                    stack.push(Task::Within(l - 1, c0));
                    if c1 < below.len() {
                        stack.push(Task::Within(l - 1, c1));
                        stack.push(Task::Across((l - 1, c0), (l - 1, c1)));
                    }
                }
                Task::Across((l, i), (m, j)) => {
                    if !self.levels[l][i].overlap(&self.levels[m][j], dim, 0.0) {
                        continue;
                    }
                    if l == 0 && m == 0 {
                        gather(i, &mut ga);
                        gather(j, &mut gb);
                        for a in &ga {
                            for b in &gb {
                                test_pair(dim, a, b)?;
                            }
                        }
                        continue;
                    }
                    // Split the higher subtree (the larger one in a balanced tree).
                    let ((l, i), other) = if l >= m {
                        ((l, i), (m, j))
                    } else {
                        ((m, j), (l, i))
                    };
                    for c in [2 * i, 2 * i + 1] {
                        if c < self.levels[l - 1].len() {
                            stack.push(Task::Across((l - 1, c), other));
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

/// The exact test of two gathered pieces of different cells.
fn test_pair(dim: usize, a: &Gathered, b: &Gathered) -> Result<(), Overlap> {
    if a.owner == b.owner {
        return Ok(());
    }
    let tol = OVERLAP * a.size.min(b.size);
    if !a.bbox.overlap(&b.bbox, dim, tol) {
        return Ok(());
    }
    let depth = if dim == 2 {
        penetration_2d(&a.x, &b.x, tol)
    } else {
        penetration_3d(&a.x, &b.x, tol)
    };
    match depth {
        Some(depth) => {
            let (c, d) = (a.owner.min(b.owner), a.owner.max(b.owner));
            Err(Overlap {
                a: c as usize,
                b: d as usize,
                depth,
                relative: depth / a.size.min(b.size),
            })
        }
        None => Ok(()),
    }
}

/// Coordinates relative to `origin` (a vertex of the pair): the round-off of the projections
/// is then relative to the pieces' size, not to their distance from the origin of the file.
fn relative_to<const N: usize>(x: &[[f64; 3]; 4], origin: [f64; 3]) -> [[f64; 3]; N] {
    std::array::from_fn(|i| std::array::from_fn(|k| x[i][k] - origin[k]))
}

/// The overlap of the projections of `a` and `b` on `axis`, divided by |axis|; None if the
/// axis is degenerate (|axis|² ≤ `tiny`).
fn projected_overlap(a: &[[f64; 3]], b: &[[f64; 3]], axis: [f64; 3], tiny: f64) -> Option<f64> {
    let n2 = axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2];
    if n2 <= tiny {
        return None;
    }
    let dot = |p: &[f64; 3]| p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
    let range = |x: &[[f64; 3]]| {
        x.iter()
            .map(dot)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let ((alo, ahi), (blo, bhi)) = (range(a), range(b));
    Some((ahi.min(bhi) - alo.max(blo)) / n2.sqrt())
}

/// The penetration depth of two triangles if it exceeds `tol` (module header): the smallest
/// overlap of their projections on the normals of their six edges.
fn penetration_2d(a: &[[f64; 3]; 4], b: &[[f64; 3]; 4], tol: f64) -> Option<f64> {
    let o = a[0];
    let (a, b): ([[f64; 3]; 3], [[f64; 3]; 3]) = (relative_to(a, o), relative_to(b, o));
    let mut depth = f64::INFINITY;
    for t in [&a, &b] {
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            let axis = [t[i][1] - t[j][1], t[j][0] - t[i][0], 0.0];
            if let Some(d) = projected_overlap(&a, &b, axis, 0.0) {
                if d <= tol {
                    return None;
                }
                depth = depth.min(d);
            }
        }
    }
    depth.is_finite().then_some(depth)
}

fn cross(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

fn sub(u: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    [u[0] - v[0], u[1] - v[1], u[2] - v[2]]
}

/// The penetration depth of two tetrahedra if it exceeds `tol` (module header): the face
/// normals of both first (two pieces sharing a face are separated by its plane), then the cross
/// products of an edge of each; (nearly) parallel edges give no axis — the faces' normals
/// already cover their directions.
fn penetration_3d(a: &[[f64; 3]; 4], b: &[[f64; 3]; 4], tol: f64) -> Option<f64> {
    let o = a[0];
    let (a, b): ([[f64; 3]; 4], [[f64; 3]; 4]) = (relative_to(a, o), relative_to(b, o));
    const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    let size2 = |t: &[[f64; 3]; 4]| {
        EDGES
            .iter()
            .map(|&(i, j)| {
                let e = sub(t[j], t[i]);
                e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
            })
            .fold(0.0, f64::max)
    };
    // Axes shorter than this are degenerate: 10⁻²⁴ of the product of two longest edges'
    // squares, i.e. edges (or a face's sides) parallel to 10⁻¹².
    let tiny = 1e-24 * size2(&a).max(size2(&b)).powi(2);
    let mut depth = f64::INFINITY;
    let mut try_axis = |axis: [f64; 3]| -> bool {
        match projected_overlap(&a, &b, axis, tiny) {
            Some(d) if d <= tol => false,
            Some(d) => {
                depth = depth.min(d);
                true
            }
            None => true,
        }
    };
    for t in [&a, &b] {
        for (i, j, k) in [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)] {
            if !try_axis(cross(sub(t[j], t[i]), sub(t[k], t[i]))) {
                return None;
            }
        }
    }
    for &(i, j) in &EDGES {
        let ea = sub(a[j], a[i]);
        for &(k, l) in &EDGES {
            if !try_axis(cross(ea, sub(b[l], b[k]))) {
                return None;
            }
        }
    }
    depth.is_finite().then_some(depth)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pad<const N: usize>(x: [[f64; 3]; N]) -> [[f64; 3]; 4] {
        std::array::from_fn(|i| if i < N { x[i] } else { [0.0; 3] })
    }

    #[test]
    fn triangles_sharing_an_edge_or_a_vertex_or_touching_do_not_overlap() {
        let a = pad([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // Shared edge, shared vertex, touching along a boundary (a hanging node at (0.5, 0)).
        for b in [
            [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            [[0.5, 0.0, 0.0], [1.0, -1.0, 0.0], [0.0, -1.0, 0.0]],
        ] {
            assert_eq!(penetration_2d(&a, &pad(b), 0.0), None, "{b:?}");
        }
        // Shifted by 0.1 in x onto `a`: its projections overlap by 1 on y, 0.9 on x and
        // 0.9/√2 on the hypotenuse's normal (1, 1)/√2 — the depth, the smallest of the three.
        let b = pad([[0.1, 0.0, 0.0], [1.1, 0.0, 0.0], [0.1, 1.0, 0.0]]);
        let d = penetration_2d(&a, &b, 0.0).expect("overlapping");
        // Round-off of a few ulps of 0.64.
        assert!((d - 0.9 / 2f64.sqrt()).abs() < 1e-14, "{d}");
    }

    #[test]
    fn tetrahedra_sharing_a_face_an_edge_or_a_vertex_do_not_overlap() {
        let a = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        for b in [
            // Face 1-2-3 shared, apex beyond it.
            [
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 1.0],
            ],
            // Edge 0-1 shared, the rest below z = 0 and y < 0.
            [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, -1.0, -0.2],
                [0.3, -0.2, -1.0],
            ],
            // Vertex 3 shared only, the other corners above.
            [
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 2.0],
                [-1.0, 1.0, 2.0],
                [0.0, -1.0, 2.0],
            ],
        ] {
            assert_eq!(penetration_3d(&a, &b, 0.0), None, "{b:?}");
        }
        // The same tetrahedron translated by (0.1, 0.1, 0.1): along the slanted face's normal
        // (1,1,1)/√3 the projections are [0, 1/√3] and [0.3/√3, 1.3/√3]: overlap 0.7/√3; along
        // the axes 0.9 each. The depth is 0.7/√3 (edge-cross axes give at least that).
        let b = a.map(|p| p.map(|v| v + 0.1));
        let d = penetration_3d(&a, &b, 0.0).expect("overlapping");
        assert!((d - 0.7 / 3f64.sqrt()).abs() < 1e-14, "{d}");
    }

    #[test]
    fn edge_crossing_tetrahedra_need_the_edge_axes() {
        // a: an edge along y at z = 0 and one along x at z = 0.45; b: one along y at z = 0.55
        // and one along x at z = 1.5. a's top edge passes over b's bottom edge: the plane
        // z = 0.5 separates them, and its normal is an edge-edge axis (x × y); no face normal
        // separates them (a's face through its top edge and (0, −1, 0), normal (0, 0.9, −2),
        // projects a onto [−0.9, 0.9] and b onto [−3.1, −0.2]).
        let a = [
            [0.0, -1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.45],
            [1.0, 0.0, 0.45],
        ];
        let b = [
            [0.0, -1.0, 0.55],
            [0.0, 1.0, 0.55],
            [-1.0, 0.0, 1.5],
            [1.0, 0.0, 1.5],
        ];
        assert_eq!(penetration_3d(&a, &b, 0.0), None);
        // Lowered by 0.2, b's bottom edge (z = 0.35) passes under a's top edge (z = 0.45): the
        // edges cross, the pieces interpenetrate.
        let low = b.map(|p| [p[0], p[1], p[2] - 0.2]);
        assert!(penetration_3d(&a, &low, 0.0).is_some());
    }
}
