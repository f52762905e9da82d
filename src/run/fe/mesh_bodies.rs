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
use super::pairing::{GeneralRows, InterfaceKeys, Side, general_rows};
use crate::scene::{FeSetup, MeshBodies, Pairing};
use crate::space::fe::interface::{Projector, face_integrals};
use crate::space::fe::mesh::mesh_layers;
use crate::space::fe::nitsche::{ContactFace, gmsh_contact_faces};
use crate::space::fe::{BodiesMesh, GmshMesh, Mesh, file_interface};

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
    // γ = h per row: the largest side of the Γ^a faces at its node.
    let mut size = vec![0.0f64; mesh.coords.len()];
    for face in &face_a.elements {
        let side = face_measure(mesh, face).powf(1.0 / (d - 1) as f64);
        for &n in face {
            size[n] = size[n].max(side);
        }
    }
    let rows = if gb.unmatched.is_none() && keys.pairing == Pairing::NodeToNode {
        matched_rows(mesh, gb, &face_a.elements, &size, &id)?
    } else {
        file_rows(mesh, keys, &id, &clamped, &size)?
    };
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
    let interface = pair_faces(mesh, &gb.node_body, rows.lowest, rows.farthest);
    let mut parts = bodies_parts(
        s,
        BodiesSpec {
            layers,
            layer_counts,
            clamped,
            pairs: rows.pairs,
            general: rows.general,
            height: rows.height,
            row_h: rows.row_h,
            weight: rows.weight,
            measure: rows.measure,
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

/// A file's contact rows (module header) with their gaps beyond the run's, weights (sum 1),
/// γ = h per row and |Γ^a|, and the closest and farthest distance of Γ^a to Γ^b in the file.
struct FileRows {
    pairs: Vec<(usize, usize)>,
    general: Option<GeneralRows>,
    height: Vec<f64>,
    weight: Vec<f64>,
    row_h: Vec<f64>,
    measure: f64,
    lowest: f64,
    farthest: f64,
}

/// The matched pairs' node-to-node rows (joined ids through `id`), weighted by the Γ^a faces'
/// `faces` measures, γ = `size` at the Γ^a node.
fn matched_rows(
    mesh: &GmshMesh,
    gb: &crate::space::fe::GmshBodies,
    faces: &[Vec<usize>],
    size: &[f64],
    id: &[usize],
) -> Result<FileRows, String> {
    let node_weight = face_node_weights(mesh, faces);
    let mut weight: Vec<f64> = gb.pairs.iter().map(|&(a, _)| node_weight[a]).collect();
    let measure = normalise(&mesh.file, &mut weight)?;
    let lowest = gb.distance.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(FileRows {
        pairs: gb.pairs.iter().map(|&(a, b)| (id[a], id[b])).collect(),
        general: None,
        height: gb.distance.iter().map(|g| g - lowest).collect(),
        weight,
        row_h: gb.pairs.iter().map(|&(a, _)| size[a]).collect(),
        measure,
        lowest,
        farthest: gb.distance.iter().copied().fold(lowest, f64::max),
    })
}

/// Weights to sum 1; returns their sum, |Γ^a|, refused where it is no positive measure.
fn normalise(file: &str, weight: &mut [f64]) -> Result<f64, String> {
    let measure: f64 = weight.iter().sum();
    if measure.is_nan() || measure <= 0.0 {
        return Err(format!(
            "{file}: the group \"contact_a\" has no faces of positive measure"
        ));
    }
    weight.iter_mut().for_each(|w| *w /= measure);
    Ok(measure)
}

/// The rows of a non-matching file, or of a pairing that projects (issue 45): the file's faces
/// as the blocks' interface ([`file_interface`], checked at plan time) through the blocks'
/// [`general_rows`] — node-to-segment or mortar, in the reference configuration, once per run.
/// Rows of clamped Γ^a nodes are left out and clamped nodes' entries dropped (their
/// displacement is 0). `nitsche` on a non-matching file (`pairing` node-to-node) takes its
/// points from the faces; its rows, for the observables only, pair each Γ^a node with the
/// nearest vertex of its Γ^b face (the blocks' nearest partner).
fn file_rows(
    mesh: &GmshMesh,
    keys: &MeshBodies,
    id: &[usize],
    clamped: &[bool],
    size: &[f64],
) -> Result<FileRows, String> {
    let fi = file_interface(mesh)?;
    let reach = fi.farthest + 0.1 * mesh.h;
    let side = |k: usize| Side {
        surface: fi.sides[k].surface.clone(),
        global: fi.sides[k].nodes.iter().map(|&n| id[n]).collect(),
    };
    let (a, b) = (side(0), side(1));
    let free = |n: &usize| !clamped[*n];
    let keep: Vec<usize> = (0..a.global.len())
        .filter(|&k| free(&a.global[k]))
        .collect();
    let row_h = keep.iter().map(|&k| size[fi.sides[0].nodes[k]]).collect();
    let (pairs, general, height, mut weight) = if keys.pairing == Pairing::NodeToNode {
        let proj = Projector::new(&b.surface, reach);
        let mut pairs = Vec::with_capacity(keep.len());
        let mut height = Vec::with_capacity(keep.len());
        for &k in &keep {
            let x = a.surface.coords[k];
            let p = proj.project(x).map_err(|e| format!("{}: {e}", mesh.file))?;
            let n = b.surface.kind.shape(p.xi);
            let face = b.surface.face(p.face);
            let j = (0..face.len())
                .filter(|&j| free(&b.global[face[j]]))
                .max_by(|&i, &j| n[i].total_cmp(&n[j]))
                .ok_or_else(|| format!("{}: a face of \"contact_b\" is clamped", mesh.file))?;
            pairs.push((a.global[k], b.global[face[j]]));
            height.push(p.distance - fi.lowest);
        }
        let node_weight = face_integrals(&a.surface);
        let weight = keep.iter().map(|&k| node_weight[k]).collect();
        (pairs, None, height, weight)
    } else {
        let ik = InterfaceKeys {
            pairing: keys.pairing,
            basis: keys.mortar_basis,
            quadrature: keys.interface_quadrature,
        };
        let mut g = general_rows(ik, &a, &b, reach).map_err(|e| format!("{}: {e}", mesh.file))?;
        let drop = |e: &mut Vec<(usize, f64)>| e.retain(|(n, _)| free(n));
        let take = |v: &[f64]| keep.iter().map(|&k| v[k]).collect::<Vec<f64>>();
        let mut rows: Vec<_> = keep.iter().map(|&k| g.rows[k].clone()).collect();
        rows.iter_mut().for_each(|(ra, rb)| {
            drop(ra);
            drop(rb);
        });
        let height = take(&g.height).iter().map(|h| h - fi.lowest).collect();
        let weight = take(&g.weight);
        g.a_node = keep.iter().map(|&k| g.a_node[k]).collect();
        g.b_nodes.retain(free);
        g.rows = rows;
        (Vec::new(), Some(g), height, weight)
    };
    let measure = normalise(&mesh.file, &mut weight)?;
    Ok(FileRows {
        pairs,
        general,
        height,
        weight,
        row_h,
        measure,
        lowest: fi.lowest,
        farthest: fi.farthest,
    })
}

/// Γ^a's and Γ^b's faces for Nitsche ([`super::nitsche_interface`]) as cells of the joined
/// mesh ([`BodiesMesh::split`] numbers A's cells, then B's, each in the file's order); the
/// projection reaches the farthest distance and a tenth of the largest cell beyond it.
fn pair_faces(
    mesh: &GmshMesh,
    node_body: &[u8],
    lowest: f64,
    farthest: f64,
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
    Ok(PairFaces {
        faces: [side("contact_a")?, side("contact_b")?],
        reach: farthest + 0.1 * mesh.h,
        lowest,
    })
}
