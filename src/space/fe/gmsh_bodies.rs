//! Two bodies in one Gmsh file (contract §1.10 "Two bodies from Gmsh"; issue 44): the cells of
//! the physical groups `body_a` and `body_b` are the bodies A and B, `contact_a` and
//! `contact_b` their contact faces Γ^a and Γ^b, and the interface must match node to node.
//!
//! The facts checked here, each refused with the file and the node or group at fault:
//! - the bodies share no node (bodies in contact share coordinates, not nodes) and every node
//!   belongs to one of them — so a cell's body is its nodes' body;
//! - Γ^a's nodes are A's and Γ^b's are B's;
//! - matching (node-to-node rows, contract §2.6, n = −e_d): every Γ^a node that is not clamped
//!   has a Γ^b partner with the same horizontal coordinates to 1e-10·h (h the largest cell
//!   diameter) at or below it — shifted by its distance g_i along n it lands on that node —
//!   and no Γ^b node is the partner of two; the partner is not clamped (its row has two free
//!   dofs). A file that breaks this is no error here (issue 45): its interface is
//!   non-matching ([`GmshBodies::unmatched`] holds why, naming the first node at fault with
//!   its coordinates), which the pairings that project take (`node-to-segment`, `mortar`,
//!   `nitsche`; [`super::gmsh_interface`] checks its geometry) and node-to-node refuses at
//!   plan time. Two matched nodes with A below B (the bodies overlap) stay refused here.
//!
//! Why here, in the reader: a run is planned only once its file is read, so a mesh that is no
//! pair of matching bodies is refused at plan time, before anything runs; and the whole-mesh
//! check of coincident nodes (a crack inside one body) needs each node's body, since two
//! bodies touching at g = 0 have coincident nodes on their interface.

use super::gmsh_error::GmshError;

/// Which body each node of a two-body file belongs to, and the matched interface.
#[derive(Debug, Clone, PartialEq)]
pub struct GmshBodies {
    /// 0 for A, 1 for B, per node.
    pub node_body: Vec<u8>,
    /// (Γ^a node, Γ^b node) per row, Γ^a's unclamped nodes increasing.
    pub pairs: Vec<(usize, usize)>,
    /// Each pair's distance along e_d in the file, x^a_d − x^b_d ≥ 0.
    pub distance: Vec<f64>,
    /// Why the interface does not match node to node (then `pairs` and `distance` are
    /// empty): a non-matching interface, for the pairings that project (module header).
    pub unmatched: Option<String>,
}

/// The nodes of each body from its cells' nodes (`a`, `b`: node ids, any order): per node 0
/// (A) or 1 (B). A node in both bodies or in neither is refused.
pub(crate) fn node_bodies(
    file: &str,
    node_tags: &[u64],
    a: &[usize],
    b: &[usize],
) -> Result<Vec<u8>, GmshError> {
    const NONE: u8 = u8::MAX;
    let mut body = vec![NONE; node_tags.len()];
    for &n in a {
        body[n] = 0;
    }
    for &n in b {
        if body[n] == 0 {
            return Err(two(
                file,
                format!(
                    "node {} belongs to a cell of body_a and to a cell of body_b: bodies in contact share coordinates, not nodes (mesh each body on its own)",
                    node_tags[n]
                ),
            ));
        }
        body[n] = 1;
    }
    if let Some(n) = body.iter().position(|&x| x == NONE) {
        return Err(two(
            file,
            format!(
                "node {} belongs to no cell of body_a or body_b: every cell of a two-body mesh is in one of the two groups",
                node_tags[n]
            ),
        ));
    }
    Ok(body)
}

fn two(file: &str, reason: String) -> GmshError {
    GmshError::TwoBodies {
        file: file.to_string(),
        reason,
    }
}

/// What [`match_interface`] reads: the mesh's nodes, each node's body, the two contact
/// groups' nodes (increasing), the clamped nodes (increasing) and h.
pub(crate) struct Interface<'a> {
    pub file: &'a str,
    pub dim: usize,
    pub coords: &'a [[f64; 3]],
    pub node_tags: &'a [u64],
    pub node_body: Vec<u8>,
    pub contact_a: &'a [usize],
    pub contact_b: &'a [usize],
    pub clamped: &'a [usize],
    pub h: f64,
}

/// The matched interface (module header), or the first node that breaks it.
pub(crate) fn match_interface(i: Interface<'_>) -> Result<GmshBodies, GmshError> {
    let (file, d) = (i.file, i.dim);
    let tag = |n: usize| i.node_tags[n];
    let at = |n: usize| {
        let c = i.coords[n];
        format!("({}, {}, {})", c[0], c[1], c[2])
    };
    for (group, nodes, body) in [("contact_a", i.contact_a, 0), ("contact_b", i.contact_b, 1)] {
        if let Some(&n) = nodes.iter().find(|&&n| i.node_body[n] != body) {
            return Err(two(
                file,
                format!(
                    "node {} of \"{group}\" at {} is a node of body_{}: Γ^a must lie on body_a and Γ^b on body_b",
                    tag(n),
                    at(n),
                    if body == 0 { "b" } else { "a" }
                ),
            ));
        }
    }
    let clamped = |n: usize| i.clamped.binary_search(&n).is_ok();
    let tol = 1e-10 * i.h;
    // Γ^b sorted by its first coordinate: the candidates of a Γ^a node are a window of it.
    let mut gb: Vec<usize> = i.contact_b.to_vec();
    gb.sort_by(|&p, &q| i.coords[p][0].total_cmp(&i.coords[q][0]));
    let mut taken = vec![usize::MAX; i.coords.len()];
    let (mut pairs, mut distance) = (Vec::new(), Vec::new());
    for &a in i.contact_a.iter().filter(|&&n| !clamped(n)) {
        let xa = i.coords[a];
        let lo = gb.partition_point(|&q| i.coords[q][0] < xa[0] - tol);
        let partner = gb[lo..]
            .iter()
            .take_while(|&&q| i.coords[q][0] <= xa[0] + tol)
            .copied()
            .find(|&q| (1..d - 1).all(|k| (i.coords[q][k] - xa[k]).abs() <= tol));
        let Some(b) = partner else {
            return Ok(unmatched(
                i.node_body,
                format!(
                    "node {} of \"contact_a\" at {} has no node of \"contact_b\" below it along e_d (to 1e-10·h = {tol:e}): the interface does not match node to node",
                    tag(a),
                    at(a)
                ),
            ));
        };
        let g = xa[d - 1] - i.coords[b][d - 1];
        if g < -tol {
            return Err(two(
                file,
                format!(
                    "node {} of \"contact_a\" at {} lies {:e} below its partner {} of \"contact_b\" at {}: the bodies overlap (A must start above B, a gap ≥ 0)",
                    tag(a),
                    at(a),
                    -g,
                    tag(b),
                    at(b)
                ),
            ));
        }
        if clamped(b) {
            return Ok(unmatched(
                i.node_body,
                format!(
                    "node {} of \"contact_b\" at {}, the partner of node {} of \"contact_a\", is clamped: a node-to-node row needs both nodes free",
                    tag(b),
                    at(b),
                    tag(a)
                ),
            ));
        }
        if taken[b] != usize::MAX {
            return Ok(unmatched(
                i.node_body,
                format!(
                    "node {} of \"contact_b\" at {} is below two nodes of \"contact_a\", {} and {}: one partner per node",
                    tag(b),
                    at(b),
                    tag(taken[b]),
                    tag(a)
                ),
            ));
        }
        taken[b] = a;
        pairs.push((a, b));
        distance.push(g.max(0.0));
    }
    if pairs.is_empty() {
        return Err(two(
            file,
            "every node of \"contact_a\" is clamped: no contact row is left".into(),
        ));
    }
    Ok(GmshBodies {
        node_body: i.node_body,
        pairs,
        distance,
        unmatched: None,
    })
}

/// A two-body file whose interface does not match node to node, and why.
fn unmatched(node_body: Vec<u8>, why: String) -> GmshBodies {
    GmshBodies {
        node_body,
        pairs: Vec::new(),
        distance: Vec::new(),
        unmatched: Some(why),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit squares' facing edges, 3 nodes each: A's bottom at y = 1 + g over B's top at
    /// y = 1. Matched at g = 0 and g = 0.1 (the distances exact differences of the doubles),
    /// refused with a node out of line, overlapping, or a node in both bodies.
    #[test]
    fn interface_matches_node_to_node() {
        let coords = |g: f64, shift: f64| -> Vec<[f64; 3]> {
            (0..3)
                .map(|k| {
                    [
                        0.5 * k as f64 + if k == 1 { shift } else { 0.0 },
                        1.0 + g,
                        0.0,
                    ]
                })
                .chain((0..3).map(|k| [0.5 * k as f64, 1.0, 0.0]))
                .collect()
        };
        let tags: Vec<u64> = (1..=6).collect();
        let body = || node_bodies("f.msh", &tags, &[0, 1, 2], &[3, 4, 5]).unwrap();
        let run = |c: &[[f64; 3]]| {
            match_interface(Interface {
                file: "f.msh",
                dim: 2,
                coords: c,
                node_tags: &tags,
                node_body: body(),
                contact_a: &[0, 1, 2],
                contact_b: &[3, 4, 5],
                clamped: &[],
                h: 0.5,
            })
        };
        let m = run(&coords(0.0, 0.0)).unwrap();
        assert_eq!(m.pairs, vec![(0, 3), (1, 4), (2, 5)]);
        assert_eq!(m.distance, vec![0.0; 3]);
        let c = coords(0.1, 0.0);
        let m = run(&c).unwrap();
        assert_eq!(m.distance, vec![c[0][1] - 1.0; 3]);
        let e = run(&coords(0.0, 1e-6)).unwrap().unmatched.unwrap();
        assert!(
            e.contains("node 2 of \"contact_a\" at (0.500001, 1, 0)"),
            "{e}"
        );
        let e = run(&coords(-0.01, 0.0)).unwrap_err().to_string();
        assert!(e.contains("the bodies overlap"), "{e}");
        let e = node_bodies("f.msh", &tags, &[0, 1, 2, 3], &[3, 4, 5]).unwrap_err();
        assert!(
            e.to_string()
                .contains("node 4 belongs to a cell of body_a and to a cell of body_b")
        );
    }
}
