//! Several bodies as one mesh: the nodes and elements of each body in turn, renumbered by an
//! offset (contract §1.10, §2.6: "one global dof numbering with each body's block").
//!
//! Why one [`Mesh`] rather than one matrix per body: assembly, the pattern, the factorisation
//! and every time loop of the engine then take two bodies exactly as they take one — the bodies
//! share no element, so their blocks of K and M do not couple, and only the contact rows
//! connect them.

use super::mesh::Mesh;

/// The union of bodies of one dimension and one element kind.
#[derive(Debug, Clone, PartialEq)]
pub struct BodiesMesh {
    dim: usize,
    nodes_per_element: usize,
    coords: Vec<[f64; 3]>,
    /// Element e's nodes at `elements[e·k..(e+1)·k]`, k = nodes per element.
    elements: Vec<usize>,
    /// First node and first element of each body, and the totals last.
    node_start: Vec<usize>,
    element_start: Vec<usize>,
}

impl BodiesMesh {
    /// The bodies in order (body i's node n is node `node_start(i) + n`); every body has the
    /// same dimension and element kind.
    ///
    /// # Panics
    /// On bodies of different dimensions or element kinds, or no body (a programming error).
    pub fn new(bodies: &[&dyn Mesh]) -> BodiesMesh {
        let first = bodies.first().expect("at least one body");
        let (dim, k) = (first.dim(), first.nodes_per_element());
        let mut m = BodiesMesh {
            dim,
            nodes_per_element: k,
            coords: Vec::new(),
            elements: Vec::new(),
            node_start: vec![0],
            element_start: vec![0],
        };
        for b in bodies {
            assert!(
                b.dim() == dim && b.nodes_per_element() == k,
                "bodies of one mesh share dimension and element kind"
            );
            let offset = m.coords.len();
            m.coords.extend((0..b.num_nodes()).map(|n| b.coord(n)));
            for e in 0..b.num_elements() {
                m.elements
                    .extend(b.element_nodes(e).iter().map(|&n| n + offset));
            }
            m.node_start.push(m.coords.len());
            m.element_start.push(m.elements.len() / k);
        }
        m
    }

    /// The bodies of one mesh whose nodes carry their body (`node_body[n]`, 0, 1, …; no cell
    /// spans two): body 0's nodes first, each body's in their order, then the cells likewise
    /// (a cell's body is its nodes'). Also returns each old node's new id. A mesh whose bodies
    /// are already in order (body 0's nodes and cells first) keeps its numbering.
    pub fn split(mesh: &dyn Mesh, node_body: &[u8]) -> (BodiesMesh, Vec<usize>) {
        let bodies = node_body
            .iter()
            .map(|&b| usize::from(b) + 1)
            .max()
            .unwrap_or(1);
        let k = mesh.nodes_per_element();
        let mut m = BodiesMesh {
            dim: mesh.dim(),
            nodes_per_element: k,
            coords: Vec::with_capacity(mesh.num_nodes()),
            elements: Vec::with_capacity(mesh.num_elements() * k),
            node_start: vec![0],
            element_start: vec![0],
        };
        let mut new_id = vec![usize::MAX; mesh.num_nodes()];
        for body in 0..bodies {
            for n in (0..mesh.num_nodes()).filter(|&n| usize::from(node_body[n]) == body) {
                new_id[n] = m.coords.len();
                m.coords.push(mesh.coord(n));
            }
            m.node_start.push(m.coords.len());
        }
        for body in 0..bodies {
            for e in 0..mesh.num_elements() {
                let nodes = mesh.element_nodes(e);
                if usize::from(node_body[nodes[0]]) == body {
                    m.elements.extend(nodes.iter().map(|&n| new_id[n]));
                }
            }
            m.element_start.push(m.elements.len() / k);
        }
        (m, new_id)
    }

    /// The global id of body `body`'s node `node`.
    pub fn node(&self, body: usize, node: usize) -> usize {
        self.node_start[body] + node
    }

    /// The body an element belongs to.
    pub fn element_body(&self, e: usize) -> usize {
        self.element_start[1..].partition_point(|&s| s <= e)
    }

    /// The body a node belongs to.
    pub fn node_body(&self, n: usize) -> usize {
        self.node_start[1..].partition_point(|&s| s <= n)
    }

    /// Body `body`'s first element (its element e is `element_start(body) + e`).
    pub fn element_start(&self, body: usize) -> usize {
        self.element_start[body]
    }
}

impl Mesh for BodiesMesh {
    fn dim(&self) -> usize {
        self.dim
    }
    fn num_nodes(&self) -> usize {
        self.coords.len()
    }
    fn num_elements(&self) -> usize {
        self.elements.len() / self.nodes_per_element
    }
    fn nodes_per_element(&self) -> usize {
        self.nodes_per_element
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        let k = self.nodes_per_element;
        &self.elements[e * k..(e + 1) * k]
    }
    fn coord(&self, node: usize) -> [f64; 3] {
        self.coords[node]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::fe::BoxMesh;

    /// Two boxes of 2 × 1 and 1 × 1 squares: 6 + 4 nodes, 2 + 1 elements, the second body's
    /// ids shifted by the first's counts.
    #[test]
    fn bodies_are_renumbered_in_turn() {
        let a = BoxMesh::new(&[2.0, 1.0], &[2, 1]);
        let b = BoxMesh::new(&[1.0, 1.0], &[1, 1]);
        let m = BodiesMesh::new(&[&a, &b]);
        assert_eq!((m.num_nodes(), m.num_elements()), (10, 3));
        assert_eq!(m.element_nodes(2), &[6, 7, 8, 9]);
        assert_eq!(m.node(1, 3), 9);
        assert_eq!((m.element_body(1), m.element_body(2)), (0, 1));
        assert_eq!((m.node_body(5), m.node_body(6)), (0, 1));
        assert_eq!(m.coord(9), [1.0, 1.0, 0.0]);
        // Split again by the node bodies: the same mesh, the same numbering.
        let nb: Vec<u8> = (0..10).map(|n| m.node_body(n) as u8).collect();
        let (s, id) = BodiesMesh::split(&m, &nb);
        assert_eq!(s, m);
        assert_eq!(id, (0..10).collect::<Vec<_>>());
        // Bodies listed out of order: B's nodes and cell move behind A's.
        let swapped: Vec<u8> = nb.iter().map(|b| 1 - b).collect();
        let (s, id) = BodiesMesh::split(&m, &swapped);
        assert_eq!((id[6], id[0]), (0, 4));
        assert_eq!(s.element_nodes(0), &[0, 1, 2, 3]);
        assert_eq!((s.element_body(0), s.element_body(1)), (0, 1));
    }
}
