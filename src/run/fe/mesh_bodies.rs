//! Two bodies from a Gmsh file (contract §1.10 "Two bodies from Gmsh"; issue 44) as the same
//! engine data as the blocks ([`BodiesSpec`] → [`super::bodies::bodies_parts`]): the file's
//! nodes split by body into one numbering ([`BodiesMesh::split`]: A's, then B's), the matched
//! pairs the reader found ([`crate::space::fe::GmshBodies`]) as node-to-node rows, each body's
//! material, B's velocity, the `clamped` nodes and A's `loaded` face.
//!
//! The gap: the file gives the bodies' shapes and their relative place; the run's `gap` is the
//! initial distance of the closest pair, as §1.6's `gap` is the distance from the closest Γ_C
//! node to the plane. Row i's gap is g + (d_i − min_j d_j), d_i its distance along e_d in the
//! file — so a file drawn with the bodies touching (d_i = 0, the blocks' geometry) runs at
//! exactly the run's gap, and a sweep over `gap` shares one geometry.
//!
//! The weights: each face of Γ^a (and of `loaded`) spreads its measure evenly over its nodes
//! ([`face_node_weights`], the one-body meshes' Γ_C weights: the trapezoidal weights for
//! 2-node lines and 4-node quadrilaterals of a uniform lattice); the penalty's γ = h per row is
//! the largest measure^{1/(d−1)} of the Γ^a faces at its node — the side of a square face, the
//! blocks' h on the blocks' lattice.

use super::bodies::{BlocksParts, BodiesSpec, bodies_parts};
use super::nitsche_interface::PairFaces;
use crate::scene::{FeSetup, MeshBodies};
use crate::space::fe::mesh::mesh_layers;
use crate::space::fe::nitsche::{ContactFace, gmsh_contact_faces};
use crate::space::fe::{BodiesMesh, GmshMesh, Mesh};

/// The measure of each face of a face group (its vertices' straight line or flat polygon, Gmsh's
/// order: the vertices first), in a mesh of dimension `d`.
pub(super) fn face_measure(mesh: &GmshMesh, face: &[usize]) -> f64 {
    let c = |i: usize| mesh.coords[face[i]];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        let x = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
    };
    match (mesh.dim, face.len()) {
        (2, _) => {
            let v = sub(c(1), c(0));
            (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
        }
        (_, 3 | 6) => 0.5 * cross(sub(c(1), c(0)), sub(c(2), c(0))),
        // Quadrilateral faces, Gmsh order (vertices around the face first): two triangles.
        _ => {
            0.5 * cross(sub(c(1), c(0)), sub(c(2), c(0)))
                + 0.5 * cross(sub(c(2), c(0)), sub(c(3), c(0)))
        }
    }
}

/// ∫φ_i per node of the mesh over a face group: each face's measure spread evenly over its
/// nodes.
pub(super) fn face_node_weights(mesh: &GmshMesh, faces: &[Vec<usize>]) -> Vec<f64> {
    let mut node_weight = vec![0.0; mesh.coords.len()];
    for face in faces {
        let measure = face_measure(mesh, face);
        for &n in face {
            node_weight[n] += measure / face.len() as f64;
        }
    }
    node_weight
}

/// The engine's parts of a two-body file (module header).
pub(super) fn mesh_bodies_parts(
    s: &FeSetup,
    mesh: &GmshMesh,
    keys: &MeshBodies,
) -> Result<BlocksParts, String> {
    let file = &mesh.file;
    let gb = mesh
        .bodies
        .as_ref()
        .ok_or_else(|| format!("{file}: not a two-body mesh"))?;
    let d = mesh.dim;
    let (bm, id) = BodiesMesh::split(mesh, &gb.node_body);
    let group = |name: &str| mesh.group(name);
    let mut clamped = vec![false; bm.num_nodes()];
    if let Some(g) = group("clamped") {
        for &n in &g.nodes {
            clamped[id[n]] = true;
        }
    }
    let face_a = group("contact_a").ok_or_else(|| format!("{file}: no group \"contact_a\""))?;
    let face_b = group("contact_b").ok_or_else(|| format!("{file}: no group \"contact_b\""))?;
    // Layers from each body's own contact face (the bodies share no node, so each body's
    // layers grow from its face alone).
    let seed: Vec<usize> = face_a
        .nodes
        .iter()
        .chain(&face_b.nodes)
        .map(|&n| id[n])
        .collect();
    let layers = mesh_layers(&bm, &seed);
    let mut layer_counts = [0usize; 2];
    for (e, &l) in layers.iter().enumerate() {
        let c = &mut layer_counts[bm.element_body(e)];
        *c = (*c).max(l + 1);
    }
    let node_weight = face_node_weights(mesh, &face_a.elements);
    let mut weight: Vec<f64> = gb.pairs.iter().map(|&(a, _)| node_weight[a]).collect();
    let measure: f64 = weight.iter().sum();
    if measure.is_nan() || measure <= 0.0 {
        return Err(format!(
            "{file}: the group \"contact_a\" has no faces of positive measure"
        ));
    }
    weight.iter_mut().for_each(|w| *w /= measure);
    // γ = h per row: the largest side of the Γ^a faces at its node.
    let mut size = vec![0.0f64; mesh.coords.len()];
    for face in &face_a.elements {
        let side = face_measure(mesh, face).powf(1.0 / (d - 1) as f64);
        for &n in face {
            size[n] = size[n].max(side);
        }
    }
    let lowest = gb.distance.iter().copied().fold(f64::INFINITY, f64::min);
    let (loaded, loaded_measure) = match group("loaded") {
        Some(g) => {
            let w = face_node_weights(mesh, &g.elements);
            let total: f64 = g.nodes.iter().map(|&n| w[n]).sum();
            let nodes = g.nodes.iter().map(|&n| (id[n], w[n] / total)).collect();
            (nodes, total)
        }
        None if keys.pressure != 0.0 => {
            return Err(format!(
                "{file}: pressure = {} needs the physical group \"loaded\" (A's face it acts on)",
                keys.pressure
            ));
        }
        None => (Vec::new(), 0.0),
    };
    let extent = |body: u8| mesh.extent(|n| gb.node_body[n] == body);
    let interface = pair_faces(mesh, &gb.node_body, lowest, &gb.distance);
    let mut parts = bodies_parts(
        s,
        BodiesSpec {
            layers,
            layer_counts,
            clamped,
            pairs: gb.pairs.iter().map(|&(a, b)| (id[a], id[b])).collect(),
            general: None,
            height: gb.distance.iter().map(|g| g - lowest).collect(),
            row_h: gb.pairs.iter().map(|&(a, _)| size[a]).collect(),
            weight,
            measure,
            loaded,
            loaded_measure,
            heights: [extent(0), extent(1)],
            measured_layers: true,
            density_b: keys.density_b,
            lame_b: (keys.lame_lambda_b, keys.lame_mu_b),
            velocity_b: keys.velocity_b,
            mass_side: keys.mass_side,
            pressure: keys.pressure,
            mesh: bm,
        },
    )?;
    parts.two.interface = interface;
    Ok(parts)
}

/// Γ^a's and Γ^b's faces for Nitsche ([`super::nitsche_interface`]) as cells of the joined
/// mesh ([`BodiesMesh::split`] numbers A's cells, then B's, each in the file's order); the
/// projection reaches the farthest pair's distance and a tenth of the largest cell beyond it.
fn pair_faces(
    mesh: &GmshMesh,
    node_body: &[u8],
    lowest: f64,
    distance: &[f64],
) -> Result<PairFaces, String> {
    let mut cell = vec![0usize; mesh.num_elements()];
    let mut next = 0;
    for body in 0..2u8 {
        for (e, c) in cell.iter_mut().enumerate() {
            if node_body[mesh.element_nodes(e)[0]] == body {
                *c = next;
                next += 1;
            }
        }
    }
    let side = |name: &str| -> Result<Vec<ContactFace>, String> {
        let group = mesh
            .group(name)
            .ok_or_else(|| format!("{}: no group \"{name}\"", mesh.file))?;
        let mut faces = gmsh_contact_faces(mesh, group)?;
        faces.iter_mut().for_each(|f| f.element = cell[f.element]);
        Ok(faces)
    };
    let farthest = distance.iter().copied().fold(lowest, f64::max);
    Ok(PairFaces {
        faces: [side("contact_a")?, side("contact_b")?],
        reach: farthest + 0.1 * mesh.h,
        lowest,
    })
}
