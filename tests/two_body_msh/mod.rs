//! Two-body Gmsh files for the tests (contract §1.10 "Two bodies from Gmsh"; issues 44, 45),
//! written without Gmsh: two boxes A on B with their own lattices (`across` and `across_b`
//! cells across: a non-matching interface when they differ), Q1 or cut into P1 triangles and
//! tetrahedra, as MSH 4.1 ASCII with the coordinates of the library's own boxes (so they are
//! the blocks' doubles, printed as the shortest decimal that reads back to them); and the
//! comparison of two runs over every metric and series value.
#![allow(dead_code)]

use std::fmt::Write as _;

use contact_sweep::run::Outcome;
use contact_sweep::space::fe::{BoxMesh, Mesh};
use contact_sweep::sweep::{SweepFile, expand};

/// A sweep over the two-body file `msh` (scene mesh{dim}d, `fixed` after its mesh and dt)
/// refused at plan time: its message.
pub fn refused(msh: &str, dim: usize, fixed: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("two.msh"), msh).unwrap();
    let text = format!(
        "name = \"x\"\nscene = \"mesh{dim}d\"\n[fixed]\nmesh = \"two.msh\"\ndt = 0.01\n{fixed}"
    );
    let path = dir.path().join("s.toml");
    match SweepFile::parse(&path, &text).map(|s| expand(&s)) {
        Err(e) => e.to_string(),
        Ok(Err(e)) => e.to_string(),
        Ok(Ok(_)) => panic!("accepted:\n{text}"),
    }
}

/// Two boxes: width W, heights H_a, H_b, cells across A and B and up each.
#[derive(Clone, Copy, Debug)]
pub struct Boxes {
    pub dim: usize,
    pub width: f64,
    pub height_a: f64,
    pub height_b: f64,
    pub across: usize,
    pub across_b: usize,
    pub cells_a: usize,
    pub cells_b: usize,
}

/// A box's cell in Gmsh's order from the box's tensor order (local node a has bit k of a
/// along axis k).
fn gmsh_order(t: &[usize]) -> Vec<usize> {
    match t.len() {
        4 => vec![t[0], t[1], t[3], t[2]],
        _ => vec![t[0], t[1], t[3], t[2], t[4], t[5], t[7], t[6]],
    }
}

/// A hexahedron (tensor order) as Kuhn's six tetrahedra around its diagonal 0–7: the paths
/// 0 → e_i → e_i + e_j → 7. Every face of the cube is cut along its diagonal from its lowest
/// to its highest corner, so neighbours' faces match and [`plane_faces`]'s triangles are faces
/// of these tetrahedra.
fn kuhn(t: &[usize]) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    for (i, j) in [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)] {
        let (a, b) = (1usize << i, (1usize << i) | (1 << j));
        out.push(vec![t[0], t[a], t[b], t[7]]);
    }
    out
}

/// The faces of a box on its plane x_d = `layer` (in cells), Gmsh's order; `tri` cuts each
/// square along its lowest–highest diagonal (the tetrahedra's faces).
fn plane_faces(m: &BoxMesh, layer: usize, tri: bool) -> Vec<Vec<usize>> {
    let (d, cells) = (m.dim, &m.cells);
    let mut out = Vec::new();
    if d == 2 {
        for i in 0..cells[0] {
            out.push(vec![m.node_id([i, layer, 0]), m.node_id([i + 1, layer, 0])]);
        }
    } else {
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                let n = |a: usize, b: usize| m.node_id([i + a, j + b, layer]);
                if tri {
                    out.push(vec![n(0, 0), n(1, 0), n(1, 1)]);
                    out.push(vec![n(0, 0), n(1, 1), n(0, 1)]);
                } else {
                    out.push(vec![n(0, 0), n(1, 0), n(1, 1), n(0, 1)]);
                }
            }
        }
    }
    out
}

/// A box's cells in Gmsh's order, Q1 or cut into simplices (a square into two triangles along
/// its first diagonal, a cube into Kuhn's tetrahedra, each positively oriented).
fn cells(m: &BoxMesh, simplex: bool) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    for e in 0..m.num_elements() {
        let t = m.element_nodes(e);
        match (simplex, m.dim) {
            (false, _) => out.push(gmsh_order(t)),
            (true, 2) => {
                let q = gmsh_order(t);
                out.push(vec![q[0], q[1], q[2]]);
                out.push(vec![q[0], q[2], q[3]]);
            }
            (true, _) => {
                for mut tet in kuhn(t) {
                    let x = |k: usize| m.coords[tet[k]];
                    let v = |k: usize| [0, 1, 2].map(|c| x(k)[c] - x(0)[c]);
                    let (a, b, c) = (v(1), v(2), v(3));
                    let det = a[0] * (b[1] * c[2] - b[2] * c[1])
                        - a[1] * (b[0] * c[2] - b[2] * c[0])
                        + a[2] * (b[0] * c[1] - b[1] * c[0]);
                    if det < 0.0 {
                        tet.swap(1, 2);
                    }
                    out.push(tet);
                }
            }
        }
    }
    out
}

/// The two boxes as one MSH 4.1 file: A of height H_a on B's top, drawn `lift` above it (0:
/// touching), A's nodes first in the box's order, then B's; groups body_a, body_b, contact_a
/// (A's bottom), contact_b (B's top), loaded (A's top) and, if `clamped`, clamped (B's base).
/// `simplex`: P1 triangles or tetrahedra instead of Q1 cells.
pub fn boxes_msh(b: Boxes, clamped: bool, simplex: bool, lift: f64) -> String {
    let d = b.dim;
    let mut ext = vec![b.width; d];
    let mut cells_a = vec![b.across; d];
    ext[d - 1] = b.height_a;
    cells_a[d - 1] = b.cells_a;
    let mut a = BoxMesh::new(&ext, &cells_a);
    a.coords
        .iter_mut()
        .for_each(|c| c[d - 1] += b.height_b + lift);
    ext[d - 1] = b.height_b;
    let mut cells_b = vec![b.across_b; d];
    cells_b[d - 1] = b.cells_b;
    let bm = BoxMesh::new(&ext, &cells_b);
    let off = a.num_nodes();
    let shift = |faces: Vec<Vec<usize>>| -> Vec<Vec<usize>> {
        faces
            .into_iter()
            .map(|f| f.into_iter().map(|n| n + off).collect())
            .collect()
    };
    let tri = simplex && d == 3;
    let mut groups = vec![
        (d, "body_a", cells(&a, simplex)),
        (d, "body_b", shift(cells(&bm, simplex))),
        (d - 1, "contact_a", plane_faces(&a, 0, tri)),
        (d - 1, "contact_b", shift(plane_faces(&bm, b.cells_b, tri))),
        (d - 1, "loaded", plane_faces(&a, b.cells_a, tri)),
    ];
    if clamped {
        groups.push((d - 1, "clamped", shift(plane_faces(&bm, 0, tri))));
    }
    let coords: Vec<[f64; 3]> = a.coords.iter().chain(&bm.coords).copied().collect();
    write_msh(d, &coords, &groups)
}

/// [`boxes_msh`] in 2D with Q2 cells (9-node quadrilaterals, 3-node boundary lines): each box
/// on a lattice of twice its cells, cell (i, j) the lattice's nodes 2i…2i + 2 × 2j…2j + 2 —
/// degree-2 faces, straight.
pub fn boxes_msh_q2(b: Boxes) -> String {
    let fine = |across: usize, up: usize, h: f64, lift: f64| {
        let mut m = BoxMesh::new(&[b.width, h], &[2 * across, 2 * up]);
        m.coords.iter_mut().for_each(|c| c[1] += lift);
        m
    };
    let a = fine(b.across, b.cells_a, b.height_a, b.height_b);
    let bm = fine(b.across_b, b.cells_b, b.height_b, 0.0);
    let off = a.num_nodes();
    let quads = |m: &BoxMesh, o: usize| -> Vec<Vec<usize>> {
        let n = |i: usize, j: usize| m.node_id([i, j, 0]) + o;
        let mut out = Vec::new();
        for j in (0..m.cells[1]).step_by(2) {
            for i in (0..m.cells[0]).step_by(2) {
                out.push(vec![
                    n(i, j),
                    n(i + 2, j),
                    n(i + 2, j + 2),
                    n(i, j + 2),
                    n(i + 1, j),
                    n(i + 2, j + 1),
                    n(i + 1, j + 2),
                    n(i, j + 1),
                    n(i + 1, j + 1),
                ]);
            }
        }
        out
    };
    let lines = |m: &BoxMesh, o: usize, j: usize| -> Vec<Vec<usize>> {
        let n = |i: usize| m.node_id([i, j, 0]) + o;
        (0..m.cells[0])
            .step_by(2)
            .map(|i| vec![n(i), n(i + 2), n(i + 1)])
            .collect()
    };
    let groups = vec![
        (2, "body_a", quads(&a, 0)),
        (2, "body_b", quads(&bm, off)),
        (1, "contact_a", lines(&a, 0, 0)),
        (1, "contact_b", lines(&bm, off, bm.cells[1])),
        (1, "loaded", lines(&a, 0, a.cells[1])),
    ];
    let coords: Vec<[f64; 3]> = a.coords.iter().chain(&bm.coords).copied().collect();
    write_msh(2, &coords, &groups)
}

/// One MSH 4.1 ASCII file of `coords` (nodes 1…) and `groups` (physical dimension, name,
/// elements as 0-based node ids), one entity per group tagged as its group.
pub fn write_msh(
    d: usize,
    coords: &[[f64; 3]],
    groups: &[(usize, &str, Vec<Vec<usize>>)],
) -> String {
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    let _ = writeln!(s, "{}", groups.len());
    for (k, (gd, name, _)) in groups.iter().enumerate() {
        let _ = writeln!(s, "{gd} {} \"{name}\"", k + 1);
    }
    s.push_str("$EndPhysicalNames\n$Entities\n");
    let mut counts = [0usize; 4];
    for g in groups {
        counts[g.0] += 1;
    }
    let _ = writeln!(s, "{} {} {} {}", counts[0], counts[1], counts[2], counts[3]);
    for dd in 1..=3 {
        for (k, _) in groups.iter().enumerate().filter(|(_, g)| g.0 == dd) {
            let _ = writeln!(s, "{} 0 0 0 1 1 1 1 {} 0", k + 1, k + 1);
        }
    }
    s.push_str("$EndEntities\n$Nodes\n");
    let total = coords.len();
    let _ = writeln!(s, "1 {total} 1 {total}");
    let _ = writeln!(s, "{d} 1 0 {total}");
    for n in 0..total {
        let _ = writeln!(s, "{}", n + 1);
    }
    for c in coords {
        let z = if d == 3 { c[2] } else { 0.0 };
        let _ = writeln!(s, "{:?} {:?} {:?}", c[0], c[1], z);
    }
    s.push_str("$EndNodes\n$Elements\n");
    let n_el: usize = groups.iter().map(|g| g.2.len()).sum();
    let _ = writeln!(s, "{} {n_el} 1 {n_el}", groups.len());
    let mut tag = 0;
    for (k, (gd, _, els)) in groups.iter().enumerate() {
        let ty = match (*gd, els[0].len()) {
            (1, 2) => 1,
            (1, 3) => 8,
            (2, 9) => 10,
            (2, 3) => 2,
            (2, 4) => 3,
            (3, 4) => 4,
            (3, 8) => 5,
            other => panic!("no element type for {other:?}"),
        };
        let _ = writeln!(s, "{gd} {} {ty} {}", k + 1, els.len());
        for e in els {
            tag += 1;
            let nodes: Vec<String> = e.iter().map(|n| (n + 1).to_string()).collect();
            let _ = writeln!(s, "{tag} {}", nodes.join(" "));
        }
    }
    s.push_str("$EndElements\n");
    s
}

/// Every number of a run's metrics by name, in order (from its Debug form `name: value, …`,
/// nested values included), the wall-clock times and the cache counters left out.
pub fn metric_values(o: &Outcome) -> Vec<(String, Option<f64>)> {
    let text = format!("{:?}", o.metrics)
        .replace("Some(", "")
        .replace(')', "");
    text.split([',', '{', '}', '['])
        .filter_map(|piece| {
            let (name, v) = piece.trim().split_once(": ")?;
            if name.ends_with("_time_s") || name == "factor_cache_hits" {
                return None;
            }
            match v.trim() {
                "None" => Some((name.to_string(), None)),
                v => v.parse::<f64>().ok().map(|x| (name.to_string(), Some(x))),
            }
        })
        .collect()
}

/// The largest relative difference of two runs over every metric and every series value
/// (each against the larger of its own column's scale and `floor`), with the name where it
/// is.
pub fn difference(k: &Outcome, g: &Outcome, floor: f64) -> (f64, String) {
    let mut worst = (0.0f64, String::from("none"));
    let mut see = |name: &str, d: f64| {
        if d > worst.0 || d.is_nan() {
            worst = (d, name.to_string());
        }
    };
    let (mk, mg) = (metric_values(k), metric_values(g));
    assert_eq!(mk.len(), mg.len());
    // The two-body columns are among them: the momentum, the bodies' velocities, the masses.
    let given = mk.iter().filter(|(_, v)| v.is_some()).count();
    assert!(given >= 20, "{mk:?}");
    for ((n, a), (m, b)) in mk.iter().zip(mg) {
        assert_eq!(*n, m);
        assert_eq!(a.is_some(), b.is_some(), "{n}: {a:?} and {b:?}");
        if let (Some(a), Some(b)) = (a, b) {
            see(n, (a - b).abs() / a.abs().max(b.abs()).max(floor));
        }
    }
    let (sk, sg) = (&k.series, &g.series);
    assert_eq!(sk.step, sg.step);
    let cols: [(&str, &[f64], &[f64]); 5] = [
        ("t", &sk.t, &sg.t),
        ("u_contact", &sk.u_contact, &sg.u_contact),
        ("v_contact", &sk.v_contact, &sg.v_contact),
        ("sigma_contact", &sk.sigma_contact, &sg.sigma_contact),
        ("energy", &sk.energy, &sg.energy),
    ];
    let optional = sk.optional.iter().zip(&sg.optional).enumerate();
    let opt: Vec<(String, &[f64], &[f64])> = optional
        .map(|(i, (a, b))| (format!("series optional {i}"), &a[..], &b[..]))
        .collect();
    for (i, (a, b)) in sk.valid.iter().zip(&sg.valid).enumerate() {
        assert_eq!(a, b, "series optional {i}: the same steps given");
    }
    let all = cols
        .iter()
        .map(|(n, a, b)| (n.to_string(), *a, *b))
        .chain(opt);
    for (name, a, b) in all {
        assert_eq!(a.len(), b.len(), "{name}");
        let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(floor);
        for (x, y) in a.iter().zip(b) {
            see(&name, (x - y).abs() / scale);
        }
    }
    worst
}
