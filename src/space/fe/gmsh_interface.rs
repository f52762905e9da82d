//! The faces Γ^a, Γ^b of a two-body Gmsh file as the interface geometry the blocks' non-matching
//! pairings take (contract §1.10 "Two bodies from Gmsh", §2.6; issue 45): each contact group's
//! faces as a [`Surface`] of their vertices, oriented outward of its own body (each face's
//! normal points away from its cell's centroid, whatever the file's node order), over the
//! group's vertex nodes in increasing file order (so a file written in the blocks' node order
//! gives the blocks' row order).
//!
//! [`file_interface`] checks, once, in the reference configuration, that the faces face each
//! other — what every projecting pairing (`node-to-segment`, `mortar`, `nitsche`) needs:
//! every Γ^a vertex not clamped has its closest point Π(x) of Γ^b within h (the file's
//! largest cell diameter: the gap tolerance of a file, whose bodies are drawn touching or
//! close), Π(x) − x is along Γ^b's normal there (else Π left Γ^b: the point lies beyond Γ^b's
//! edge), and A does not lie inside B ((x − Π(x))·n^b ≥ −1e-10·h). Its lowest and farthest
//! distance give the rows' gaps beyond the run's `gap` (the closest point at the run's gap,
//! as the matched files' closest pair) and the projection's reach.
//!
//! Why Π on the straight vertex faces: the interface library's faces are affine or bilinear;
//! a degree-2 cell's face is reported ([`FileInterface::curved`]) so a method that needs the
//! face's own nodes (the rows of `node-to-segment` and `mortar`) can refuse it.

use super::Mesh;
use super::gmsh::GmshMesh;
use super::interface::surface::{cross, dot, norm, scale, sub};
use super::interface::{FaceKind, Projector, Surface};
use super::nitsche::gmsh_contact_faces;

/// One contact group of a file as a surface, with each surface node's node in the file.
#[derive(Debug, Clone)]
pub struct FileSide {
    pub surface: Surface,
    pub nodes: Vec<usize>,
}

/// A two-body file's interface (module header).
#[derive(Debug, Clone)]
pub struct FileInterface {
    /// Γ^a (`contact_a`) and Γ^b (`contact_b`).
    pub sides: [FileSide; 2],
    /// The smallest and largest distance (x − Π(x))·n^b over Γ^a's vertices not clamped.
    pub lowest: f64,
    pub farthest: f64,
    /// Whether the faces have more nodes than their vertices (degree-2 cells).
    pub curved: bool,
}

/// Group `name`'s faces as a surface oriented outward of its cells (module header); `side`
/// ('a', 'b') names it in the surface's errors. Also whether a face has nodes beyond its
/// vertices.
fn file_side(mesh: &GmshMesh, name: &str, side: char) -> Result<(FileSide, bool), String> {
    let file = &mesh.file;
    let group = mesh
        .group(name)
        .ok_or_else(|| format!("{file}: no group \"{name}\""))?;
    let cells = gmsh_contact_faces(mesh, group)?;
    let d = mesh.dim;
    let vertices = |f: &[usize]| match (d, f.len()) {
        (2, _) => 2,
        (_, 3 | 6) => 3,
        _ => 4,
    };
    let kind = match (d, group.elements.first().map_or(0, |f| vertices(f))) {
        (2, _) => FaceKind::Seg2,
        (_, 3) => FaceKind::Tri3,
        _ => FaceKind::Quad4,
    };
    if let Some(f) = group.elements.iter().find(|f| vertices(f) != kind.nodes()) {
        return Err(format!(
            "{file}: the group \"{name}\" mixes triangular and quadrilateral faces (nodes {:?}): an interface side takes one kind of face",
            f.iter().map(|&n| mesh.node_tags[n]).collect::<Vec<_>>()
        ));
    }
    let mut nodes: Vec<usize> = group
        .elements
        .iter()
        .flat_map(|f| f[..kind.nodes()].iter().copied())
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    let local = |n: usize| nodes.binary_search(&n).expect("a vertex of the group");
    let mut conn = Vec::with_capacity(group.elements.len() * kind.nodes());
    let mut curved = false;
    for (face, cell) in group.elements.iter().zip(&cells) {
        curved |= face.len() > kind.nodes();
        let mut v: Vec<usize> = face[..kind.nodes()].iter().map(|&n| local(n)).collect();
        // Outward: the normal of the vertices' order against the cell's centroid.
        let en = mesh.element_nodes(cell.element);
        let mut c = [0.0; 3];
        for &n in en {
            (0..3).for_each(|k| c[k] += mesh.coords[n][k] / en.len() as f64);
        }
        let x: Vec<[f64; 3]> = v.iter().map(|&k| mesh.coords[nodes[k]]).collect();
        let normal = match kind {
            FaceKind::Seg2 => {
                let t = sub(x[1], x[0]);
                [t[1], -t[0], 0.0]
            }
            _ => cross(sub(x[1], x[0]), sub(x[2], x[0])),
        };
        let centre = scale(
            x.iter()
                .fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]),
            1.0 / x.len() as f64,
        );
        if dot(normal, sub(centre, c)) < 0.0 {
            match kind {
                FaceKind::Seg2 => v.reverse(),
                _ => v[1..].reverse(),
            }
        }
        conn.extend(v);
    }
    let coords = nodes.iter().map(|&n| mesh.coords[n]).collect();
    let surface = Surface::new(side, kind, coords, conn)
        .map_err(|e| format!("{file}: the group \"{name}\": {e}"))?;
    Ok((FileSide { surface, nodes }, curved))
}

/// The interface of a two-body file, checked (module header); the error names the file, the
/// node and why.
pub fn file_interface(mesh: &GmshMesh) -> Result<FileInterface, String> {
    let file = &mesh.file;
    let (a, curved_a) = file_side(mesh, "contact_a", 'a')?;
    let (b, curved_b) = file_side(mesh, "contact_b", 'b')?;
    let clamped = mesh.group("clamped").map_or(&[][..], |g| &g.nodes[..]);
    let h = mesh.h;
    let projector = Projector::new(&b.surface, h);
    let (mut lowest, mut farthest) = (f64::INFINITY, f64::NEG_INFINITY);
    for (k, &x) in a.surface.coords.iter().enumerate() {
        let node = a.nodes[k];
        if clamped.binary_search(&node).is_ok() {
            continue;
        }
        let at = format!(
            "node {} of \"contact_a\" at ({}, {}, {})",
            mesh.node_tags[node], x[0], x[1], x[2]
        );
        let p = projector.project(x).map_err(|_| {
            format!(
                "{file}: {at} has no point of \"contact_b\" within h = {h:e} (the file's largest cell): the faces do not face each other"
            )
        })?;
        let n = b.surface.normal(p.face);
        let v = sub(x, p.point);
        let g = dot(v, n);
        let off = norm(sub(v, scale(n, g)));
        if off > 1e-8 * h {
            return Err(format!(
                "{file}: {at}: its closest point of \"contact_b\" lies {off:e} aside from its normal, on the edge of \"contact_b\": the projection leaves Γ^b (Γ^a reaches beyond Γ^b)"
            ));
        }
        if g < -1e-10 * h {
            return Err(format!(
                "{file}: {at} lies {:e} inside body_b: the bodies overlap (A must start outside B, a gap ≥ 0)",
                -g
            ));
        }
        lowest = lowest.min(g.max(0.0));
        farthest = farthest.max(g.max(0.0));
    }
    if !lowest.is_finite() {
        return Err(format!(
            "{file}: every node of \"contact_a\" is clamped: no contact row is left"
        ));
    }
    Ok(FileInterface {
        sides: [a, b],
        lowest,
        farthest,
        curved: curved_a || curved_b,
    })
}
