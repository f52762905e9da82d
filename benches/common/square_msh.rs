//! The unit square as a Gmsh MSH 4.1 ASCII file, written by the mesh benchmarks
//! (`benches/mesh_read.rs`, `benches/mesh_overlap.rs`) at set-up so that no large mesh is
//! committed.

use std::fmt::Write as _;

/// The MSH 4.1 text of the unit square as `n` × `n` squares, two triangles each, of degree
/// `p` (1: 3-node triangles, Gmsh type 2; 2: 6-node, type 9, with 3-node lines, type 8). Nodes
/// are the (pn + 1)² lattice, tag 1 + i + (pn + 1) j; every node is written in the surface's
/// block (Gmsh would put the boundary ones in the curves' blocks: the reader takes the tags
/// wherever they are).
pub fn square_msh(n: usize, p: usize) -> String {
    let m = p * n + 1;
    let tag = |i: usize, j: usize| 1 + i + m * j;
    let mut s = String::new();
    s.push_str("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    s.push_str(
        "$PhysicalNames\n3\n1 1 \"contact\"\n1 2 \"clamped\"\n2 3 \"body\"\n$EndPhysicalNames\n",
    );
    // Two curves (bottom: tag 1, physical 1; top: tag 2, physical 2), one surface (physical 3).
    s.push_str("$Entities\n0 2 1 0\n");
    s.push_str("1 0 0 0 1 0 0 1 1 0\n2 0 1 0 1 1 0 1 2 0\n");
    s.push_str("1 0 0 0 1 1 0 1 3 2 1 2\n$EndEntities\n");
    let nn = m * m;
    writeln!(s, "$Nodes\n1 {nn} 1 {nn}\n2 1 0 {nn}").unwrap();
    for t in 1..=nn {
        writeln!(s, "{t}").unwrap();
    }
    let h = 1.0 / (m - 1) as f64;
    for j in 0..m {
        for i in 0..m {
            writeln!(s, "{} {} 0", i as f64 * h, j as f64 * h).unwrap();
        }
    }
    s.push_str("$EndNodes\n");
    let (line_type, tri_type) = if p == 1 { (1, 2) } else { (8, 9) };
    let tris = 2 * n * n;
    let total = 2 * n + tris;
    writeln!(s, "$Elements\n3 {total} 1 {total}").unwrap();
    let mut e = 1;
    // A line of the boundary row j from lattice column a: its ends, then (P2) its midpoint.
    let line = |s: &mut String, e: &mut usize, j: usize, a: usize| {
        write!(s, "{e} {} {}", tag(a, j), tag(a + p, j)).unwrap();
        if p == 2 {
            write!(s, " {}", tag(a + 1, j)).unwrap();
        }
        s.push('\n');
        *e += 1;
    };
    writeln!(s, "1 1 {line_type} {n}").unwrap();
    for c in 0..n {
        line(&mut s, &mut e, 0, c * p);
    }
    writeln!(s, "1 2 {line_type} {n}").unwrap();
    for c in 0..n {
        line(&mut s, &mut e, m - 1, c * p);
    }
    writeln!(s, "2 1 {tri_type} {tris}").unwrap();
    for b in 0..n {
        for a in 0..n {
            let (i, j) = (a * p, b * p);
            // Counter-clockwise: (00, 10, 11) and (00, 11, 01); P2 adds the edge midpoints in
            // Gmsh's order (edge 0–1, 1–2, 2–0).
            let q = p / 2;
            let lower = [
                tag(i, j),
                tag(i + p, j),
                tag(i + p, j + p),
                tag(i + q, j),
                tag(i + p, j + q),
                tag(i + q, j + q),
            ];
            let upper = [
                tag(i, j),
                tag(i + p, j + p),
                tag(i, j + p),
                tag(i + q, j + q),
                tag(i + q, j + p),
                tag(i, j + q),
            ];
            for t in [lower, upper] {
                write!(s, "{e}").unwrap();
                for v in &t[..3 * p] {
                    write!(s, " {v}").unwrap();
                }
                s.push('\n');
                e += 1;
            }
        }
    }
    s.push_str("$EndElements\n");
    s
}
