//! Bad Gmsh meshes are refused before anything runs (issue 22, "done when" 4): one test per
//! reason, each asserting the typed error, the element/node/group it names, and that the message
//! names the file. The meshes are hand-written MSH 4.1 (ASCII) variations of one good file: the
//! unit square as two counter-clockwise triangles, `contact` = the bottom line.

use std::path::PathBuf;

use contact_sweep::space::fe::{GmshError, GmshMesh};

/// The good file; each test edits one thing in it.
const GOOD: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 \"contact\"
2 2 \"body\"
$EndPhysicalNames
$Entities
0 1 1 0
1 0 0 0 1 0 0 1 1 0
1 0 0 0 1 1 0 1 2 1 1
$EndEntities
$Nodes
2 4 1 4
1 1 0 2
1
2
0 0 0
1 0 0
2 1 0 2
3
4
1 1 0
0 1 0
$EndNodes
$Elements
2 3 1 3
1 1 1 1
1 1 2
2 1 2 2
2 1 2 3
3 1 3 4
$EndElements
";

/// Write `text` to a fresh file and read it; keeps the directory alive for the message check.
fn read(text: &str) -> (Result<GmshMesh, GmshError>, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("body.msh");
    std::fs::write(&path, text).unwrap();
    (GmshMesh::read(&path), path, dir)
}

/// The error of `text`, checking that its message names the file.
fn refused(text: &str) -> GmshError {
    let (r, path, _dir) = read(text);
    let e = r.expect_err("the mesh must be refused");
    let msg = e.to_string();
    assert!(
        msg.contains(&path.display().to_string()),
        "message does not name the file: {msg}"
    );
    e
}

fn edit(from: &str, to: &str) -> String {
    assert!(
        GOOD.contains(from),
        "edit target {from:?} not in the good file"
    );
    GOOD.replacen(from, to, 1)
}

#[test]
fn the_good_file_is_read() {
    // The baseline the edits start from must itself pass, else the tests below prove nothing.
    let (r, _, _dir) = read(GOOD);
    let m = r.unwrap();
    assert_eq!((m.coords.len(), m.element_tags.len()), (4, 2));
    assert_eq!(m.group("contact").unwrap().nodes, vec![0, 1]);
    // Two right triangles of area 1/2: exact in binary floating point.
    assert_eq!(m.measure(), 1.0);
}

#[test]
fn missing_contact_group() {
    let e = refused(&edit("\"contact\"", "\"bottom\""));
    match e {
        GmshError::MissingGroup { group, found, .. } => {
            assert_eq!(group, "contact");
            assert!(
                found.contains("\"bottom\"") && found.contains("\"body\""),
                "{found}"
            );
        }
        other => panic!("expected MissingGroup, got {other:?}"),
    }
}

#[test]
fn contact_group_of_the_wrong_dimension() {
    // `contact` tagging the surface instead of a boundary line.
    let text = edit(
        "1 1 \"contact\"\n2 2 \"body\"",
        "1 1 \"bottom\"\n2 2 \"contact\"",
    );
    match refused(&text) {
        GmshError::GroupDimension {
            group,
            found,
            expected,
            ..
        } => assert_eq!((group.as_str(), found, expected), ("contact", 2, 1)),
        other => panic!("expected GroupDimension, got {other:?}"),
    }
}

#[test]
fn unsupported_element_type() {
    // Element 1 becomes a 4-node (cubic) line, Gmsh type 26.
    let e = refused(&edit("1 1 1 1\n1 1 2\n", "1 1 26 1\n1 1 2 3 4\n"));
    match e {
        GmshError::UnsupportedElement {
            element, type_id, ..
        } => assert_eq!((element, type_id), (1, 26)),
        other => panic!("expected UnsupportedElement, got {other:?}"),
    }
}

#[test]
fn two_dimensional_mesh_not_in_a_plane() {
    let e = refused(&edit("0 1 0\n$EndNodes", "0 1 0.5\n$EndNodes"));
    match e {
        GmshError::NotPlanar { node, z, z0, .. } => {
            assert_eq!(node, 4);
            // The values as written in the file.
            assert_eq!((z, z0), (0.5, 0.0));
        }
        other => panic!("expected NotPlanar, got {other:?}"),
    }
}

#[test]
fn inverted_element() {
    // Element 3 listed clockwise: det J = −2 (twice its area, negative) everywhere.
    let e = refused(&edit("3 1 3 4\n", "3 1 4 3\n"));
    match e {
        GmshError::Inverted { element, det, .. } => {
            assert_eq!(element, 3);
            // Affine triangle: det J = ±2·area = −1 exactly (integer coordinates).
            assert_eq!(det, -1.0);
        }
        other => panic!("expected Inverted, got {other:?}"),
    }
}

#[test]
fn inverted_quadratic_element_positive_at_its_centre() {
    // A 6-node triangle with corners (0,0), (1,0), (0,1) whose midpoint of edge 12 is pulled
    // inwards to (0.22, 0.22): x = ξ + 4ξη δ with δ = −0.28 (1, 1), det J = 1 − 1.12 (ξ + η),
    // positive at vertex 0 and at the centre (the cell is counter-clockwise) but −0.12 at
    // vertices 1 and 2 — only a check beyond the centre (nodes, quadrature points) sees it.
    let text = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
1 1 \"contact\"
$EndPhysicalNames
$Entities
0 1 1 0
1 0 0 0 1 0 0 1 1 0
1 0 0 0 1 1 0 0 1 1
$EndEntities
$Nodes
1 6 1 6
2 1 0 6
1
2
3
4
5
6
0 0 0
1 0 0
0 1 0
0.5 0 0
0.22 0.22 0
0 0.5 0
$EndNodes
$Elements
2 2 1 2
1 1 8 1
1 1 2 4
2 1 9 1
2 1 2 3 4 5 6
$EndElements
";
    match refused(text) {
        GmshError::Inverted { element, det, .. } => {
            assert_eq!(element, 2);
            // det J = 1 − 1.12 at vertex 1, the first node checked after vertex 0; round-off of
            // the P2 gradients is ~1e-15.
            assert!((det + 0.12).abs() < 1e-12, "det J = {det}");
        }
        other => panic!("expected Inverted, got {other:?}"),
    }
}

#[test]
fn degenerate_element() {
    // Node 4 moved to (2, 2): element 3 = (0,0), (1,1), (2,2) is flat, det J = 0 exactly.
    let e = refused(&edit("0 1 0\n$EndNodes", "2 2 0\n$EndNodes"));
    match e {
        GmshError::Degenerate { element, det, .. } => {
            assert_eq!(element, 3);
            assert_eq!(det, 0.0);
        }
        other => panic!("expected Degenerate, got {other:?}"),
    }
}

#[test]
fn unreferenced_node() {
    let text = edit("2 4 1 4\n", "2 5 1 5\n").replacen(
        "2 1 0 2\n3\n4\n1 1 0\n0 1 0\n",
        "2 1 0 3\n3\n4\n5\n1 1 0\n0 1 0\n0.5 0.5 0\n",
        1,
    );
    match refused(&text) {
        GmshError::UnreferencedNode { node, .. } => assert_eq!(node, 5),
        other => panic!("expected UnreferencedNode, got {other:?}"),
    }
}

#[test]
fn not_msh_41() {
    // An MSH 2.2 header, and a file that is not MSH at all (a .geo script).
    match refused(&edit("4.1 0 8", "2.2 0 8")) {
        GmshError::NotMsh41 { reason, .. } => assert!(reason.contains("2.2"), "{reason}"),
        other => panic!("expected NotMsh41, got {other:?}"),
    }
    match refused("Point(1) = {0, 0, 0};\n") {
        GmshError::NotMsh41 { reason, .. } => assert!(reason.contains("$MeshFormat"), "{reason}"),
        other => panic!("expected NotMsh41, got {other:?}"),
    }
}

#[test]
fn no_cells() {
    // Only the contact line saved (the body's Physical Surface forgotten).
    let text = edit("2 3 1 3\n", "1 1 1 1\n")
        .replacen("2 1 2 2\n2 1 2 3\n3 1 3 4\n", "", 1)
        .replacen("2 4 1 4\n", "1 2 1 2\n", 1)
        .replacen("2 1 0 2\n3\n4\n1 1 0\n0 1 0\n", "", 1);
    match refused(&text) {
        GmshError::NoCells { .. } => {}
        other => panic!("expected NoCells, got {other:?}"),
    }
}

#[test]
fn missing_file() {
    let e = refused_path("/nonexistent/dir/body.msh");
    assert!(matches!(e, GmshError::Io { .. }), "{e:?}");
}

fn refused_path(p: &str) -> GmshError {
    let e = GmshMesh::read(std::path::Path::new(p)).expect_err("must be refused");
    assert!(e.to_string().contains(p), "{e}");
    e
}

#[test]
fn clockwise_surface_is_reoriented_not_refused() {
    // Both triangles clockwise (a surface oriented towards −z): a valid mesh, mirrored on
    // reading so that det J > 0; the measure stays 1 (exact: two triangles of area 1/2).
    let text = edit("2 1 2 3\n3 1 3 4\n", "2 1 3 2\n3 1 4 3\n");
    let (r, _, _dir) = read(&text);
    let m = r.unwrap_or_else(|e| panic!("{e}"));
    assert!(m.reoriented);
    assert_eq!(m.measure(), 1.0);
}

// ---------------------------------------------------------------------------------------------
// Sweeps of the `mesh2d`/`mesh3d` scenes (SPEC §1.6) with a bad mesh or bad mesh keys: refused
// by `plan` and by `run` with exit status 2, the message naming the sweep file, the key and the
// reason (and the mesh file where it is at fault), no panic, nothing run (no output folder).

/// (sweep body after the header, key the message must name, phrases of the reason)
const SWEEP_CASES: &[(&str, &str, &[&str])] = &[
    // The file does not exist (relative to the sweep file's folder).
    (
        "[fixed]\ndt = 0.1\nmesh = \"nope.msh\"\n",
        "fixed.mesh",
        &["nope.msh", "cannot read the mesh file"],
    ),
    // No `contact` group.
    (
        "[fixed]\ndt = 0.1\nmesh = \"no_contact.msh\"\n",
        "fixed.mesh",
        &["no_contact.msh", "no physical group named \"contact\""],
    ),
    // One bad file of a list: the axis names its item.
    (
        "[fixed]\ndt = 0.1\n[grid]\nmesh = [\"body.msh\", \"no_contact.msh\"]\n",
        "grid.mesh[1]",
        &["no_contact.msh", "\"contact\""],
    ),
    // A 3D mesh for the 2D scene.
    (
        "[fixed]\ndt = 0.1\nmesh = \"cube.msh\"\n",
        "fixed.mesh",
        &["cube.msh", "a 3D mesh, scene mesh2d needs a 2D one"],
    ),
    // The mesh fixes h.
    (
        "[fixed]\ndt = 0.1\nh = 0.5\nmesh = \"body.msh\"\n",
        "fixed.h",
        &["takes its mesh from the `mesh` key"],
    ),
    // No mesh at all.
    ("[fixed]\ndt = 0.1\n", "mesh", &["required", "mesh2d"]),
    // The hybrid scheme needs a contact potential (Nitsche or the penalty, which the mesh
    // scenes take on the `contact` group's faces): refused with mixed, and said so.
    (
        "[fixed]\ndt = 0.1\nmesh = \"body.msh\"\nscheme = \"hybrid\"\n",
        "fixed.scheme",
        &[
            "not available for scene mesh2d with space = mixed",
            "hybrid with nitsche or penalty",
        ],
    ),
    // `obstacle` and `gap` are two names of one plane (SPEC §1.6): both given is refused,
    // naming both keys.
    (
        "[fixed]\ndt = 0.1\nmesh = \"body.msh\"\ngap = 0.1\nobstacle = -0.1\n",
        "fixed.obstacle",
        &["`gap`", "`obstacle`", "not both", "fixed.gap"],
    ),
    // A plane above the lowest contact node (here y = 0): the body would start inside it.
    (
        "[fixed]\ndt = 0.1\nmesh = \"body.msh\"\nobstacle = 0.05\n",
        "fixed.obstacle",
        &[
            "obstacle = 0.05 lies above the lowest contact node",
            "body.msh",
            "inside the obstacle",
        ],
    ),
    // A reference on another mesh file is located node by node (SPEC §1.6), but it must be
    // at least as fine as the run's: this one's largest cell is larger (a node moved up).
    (
        "reference = { dt = 0.05, mesh = \"fine.msh\" }\n[fixed]\ndt = 0.1\nmesh = \"body.msh\"\n",
        "reference.mesh",
        &["is coarser than the run's"],
    ),
];

#[test]
fn bad_mesh_sweeps_are_refused_with_the_file_key_and_exit_2() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("body.msh"), GOOD).unwrap();
    std::fs::write(
        dir.join("no_contact.msh"),
        edit("\"contact\"", "\"bottom\""),
    )
    .unwrap();
    // A finer-looking copy: another file (its bytes differ by a comment-free edit of a
    // coordinate that keeps it valid), so its content hash differs.
    std::fs::write(
        dir.join("fine.msh"),
        edit("1 1 0\n0 1 0\n", "1 1.5 0\n0 1 0\n"),
    )
    .unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(
        root.join("sweeps/meshes/cube_tet.msh"),
        dir.join("cube.msh"),
    )
    .unwrap();
    for (i, (body, key, reasons)) in SWEEP_CASES.iter().enumerate() {
        let file = format!("bad{i}.toml");
        let text = format!("name = \"x\"\nscene = \"mesh2d\"\n{body}");
        std::fs::write(dir.join(&file), text).unwrap();
        let out_dir = format!("out{i}");
        for cmd in ["plan", "run"] {
            let mut args = vec![cmd, file.as_str()];
            if cmd == "run" {
                args.extend(["--out", out_dir.as_str()]);
            }
            let o = std::process::Command::new(env!("CARGO_BIN_EXE_contact-sweep"))
                .args(&args)
                .current_dir(dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "case {i} ({cmd}):\n{err}");
            assert!(!err.contains("panicked"), "case {i}: panic\n{err}");
            assert!(err.contains(&file), "case {i}: sweep file not named\n{err}");
            assert!(
                err.contains(&format!("`{key}`")),
                "case {i}: key `{key}` not named\n{err}"
            );
            for r in *reasons {
                assert!(err.contains(r), "case {i}: `{r}` missing\n{err}");
            }
            assert!(!dir.join(&out_dir).exists(), "case {i}: output written");
        }
    }
    // The baseline of the cases is itself a valid sweep: `plan` accepts it, so each case above
    // is refused for its own edit.
    std::fs::write(
        dir.join("good.toml"),
        "name = \"x\"\nscene = \"mesh2d\"\n[fixed]\ndt = 0.1\nmesh = \"body.msh\"\n",
    )
    .unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_contact-sweep"))
        .args(["plan", "good.toml"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}
