//! Bad Gmsh meshes are refused before anything runs (issue 22, "done when" 4): one test per
//! reason, each asserting the typed error, the element/node/group it names, and that the message
//! names the file. The meshes are hand-written MSH 4.1 (ASCII) variations of one good file: the
//! unit square as two counter-clockwise triangles, `contact` = the bottom line.

mod msh_io;

use std::path::{Path, PathBuf};

use contact_sweep::space::fe::{ElementKind, GmshError, GmshMesh};

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
    // Element 1 becomes a 4-node (cubic) line, Gmsh type 26: refused by the parser, naming the
    // section, the block and the element.
    let e = refused(&edit("1 1 1 1\n1 1 2\n", "1 1 26 1\n1 1 2 3 4\n"));
    match e {
        GmshError::Parse { error, .. } => {
            assert_eq!(error.section, "$Elements");
            assert!(error.at.contains("block 1 of 2"), "{error}");
            assert!(
                error
                    .reason
                    .contains("element 1 has Gmsh type 26 (4-node line)"),
                "{error}"
            );
        }
        other => panic!("expected Parse, got {other:?}"),
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
// Sweeps of the `mesh2d`/`mesh3d` scenes (contract §1.6) with a bad mesh or bad mesh keys: refused
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
    // `obstacle` and `gap` are two names of one plane (contract §1.6): both given is refused,
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
    // A reference on another mesh file is located node by node (contract §1.6), but it must be
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

// ---------------------------------------------------------------------------------------------
// Issue 36: the user's mesh under fire. Each class the issue found is refused at read time (so
// at plan time: the planner reads every mesh file) with one line naming the file and the
// reason, or — for valid rewrites — read as the same mesh.

/// Every refusal's message: one line, under 300 characters, naming the file.
fn one_line(e: &GmshError, path: &Path) {
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "more than one line: {msg}");
    assert!(msg.chars().count() < 300, "{} chars: {msg}", msg.len());
    assert!(msg.contains(&path.display().to_string()), "{msg}");
}

/// The error of `bytes`, checked by [`one_line`].
fn refused_bytes(bytes: &[u8]) -> GmshError {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("body.msh");
    std::fs::write(&path, bytes).unwrap();
    let e = GmshMesh::read(&path).expect_err("the mesh must be refused");
    one_line(&e, &path);
    e
}

/// `plan` and `run` of a mesh2d sweep on `mesh`: exit 2, no panic, no output folder, and the
/// stderr line naming the mesh file under 300 characters and holding `reason`.
fn refused_by_the_binary(mesh: &[u8], scene: &str, reason: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("body.msh"), mesh).unwrap();
    std::fs::write(
        dir.join("s.toml"),
        format!(
            "name = \"x\"\nscene = \"{scene}\"\n[fixed]\ndt = 0.1\nT = 0.2\nmesh = \"body.msh\"\n"
        ),
    )
    .unwrap();
    for cmd in ["plan", "run"] {
        let mut args = vec![cmd, "s.toml"];
        if cmd == "run" {
            args.extend(["--out", "out"]);
        }
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_contact-sweep"))
            .args(&args)
            .current_dir(dir)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{cmd}:\n{err}");
        assert!(!err.contains("panicked"), "{cmd}: panic\n{err}");
        let line = err
            .lines()
            .find(|l| l.contains("body.msh"))
            .unwrap_or_else(|| panic!("{cmd}: the mesh file is not named\n{err}"));
        assert!(
            line.chars().count() < 300,
            "{cmd}: {} chars: {line}",
            line.len()
        );
        assert!(line.contains(reason), "{cmd}: `{reason}` missing: {line}");
        assert!(!dir.join("out").exists(), "{cmd}: output written");
    }
}

fn committed(name: &str) -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("sweeps/meshes")
            .join(name),
    )
    .unwrap()
}

#[test]
fn nodes_listed_out_of_tag_order_are_read_by_tag() {
    // Issue 36's misread: the bottom row listed last under a `$Nodes` header whose tag range is
    // contiguous (1..4 for 4 nodes). mshio numbered the nodes by position, so the square was
    // read mirrored (contact on top) or refused as inverted. Read by tag, it is the same mesh.
    let swapped = edit(
        "1 1 0 2\n1\n2\n0 0 0\n1 0 0\n2 1 0 2\n3\n4\n1 1 0\n0 1 0\n",
        "2 1 0 2\n3\n4\n1 1 0\n0 1 0\n1 1 0 2\n1\n2\n0 0 0\n1 0 0\n",
    );
    let (a, _, _d1) = read(GOOD);
    let (b, _, _d2) = read(&swapped);
    let (a, b) = (a.unwrap(), b.unwrap_or_else(|e| panic!("{e}")));
    // Equal in everything but the bytes' hash: coordinates, numbering, cells, groups, h.
    assert_eq!(a.coords, b.coords);
    assert_eq!(a.node_tags, b.node_tags);
    assert_eq!(a.elements, b.elements);
    assert_eq!(a.groups, b.groups);
    assert_eq!((a.h, a.reoriented), (b.h, b.reoriented));
    // Γ_C is the bottom y = 0, not the top.
    for &n in &b.group("contact").unwrap().nodes {
        assert_eq!(b.coords[n][1], 0.0);
    }
}

#[test]
fn physical_names_count_of_1e9_and_1e18_is_refused_not_aborted() {
    // 10⁹ aborted the process (40 GB asked of the allocator), 10¹⁸ panicked ("capacity
    // overflow"): the count is checked against the bytes left first.
    for count in ["1000000000", "1000000000000000000", "18446744073709551615"] {
        let text = edit("$PhysicalNames\n2\n", &format!("$PhysicalNames\n{count}\n"));
        match refused_bytes(text.as_bytes()) {
            GmshError::Parse { error, .. } => {
                assert_eq!(error.section, "$PhysicalNames");
                assert!(
                    error
                        .reason
                        .contains(&format!("{count} physical names announced")),
                    "{error}"
                );
            }
            other => panic!("expected Parse, got {other:?}"),
        }
        refused_by_the_binary(text.as_bytes(), "mesh2d", "$PhysicalNames");
    }
    // A count past u64 is no integer.
    let text = edit(
        "$PhysicalNames\n2\n",
        "$PhysicalNames\n99999999999999999999999\n",
    );
    assert!(matches!(
        refused_bytes(text.as_bytes()),
        GmshError::Parse { .. }
    ));
}

#[test]
fn binary_data_size_of_0_3_or_25_digits_is_refused() {
    // mshio panicked on these (`not implemented`, an unwrap on PosOverflow).
    let good = committed("square_tri_p1_bin.msh");
    let head = b"$MeshFormat\n4.1 1 8\n";
    assert!(good.starts_with(head));
    for size in ["", "3", "1234567890123456789012345"] {
        let mut bytes = format!("$MeshFormat\n4.1 1 {size}\n").into_bytes();
        bytes.extend_from_slice(&good[head.len()..]);
        match refused_bytes(&bytes) {
            GmshError::Parse { error, .. } => {
                assert_eq!(error.section, "$MeshFormat", "{error}");
                assert!(error.reason.contains("data size"), "{error}");
            }
            other => panic!("expected Parse, got {other:?}"),
        }
        refused_by_the_binary(&bytes, "mesh2d", "data size");
    }
}

#[test]
fn point_element_in_a_contact_curve_is_refused_at_read() {
    // A point (Gmsh type 15) in the contact curve's block panicked inside every run
    // (src/run/fe/, an index out of bounds on the face's second node).
    let text = edit("1 1 1 1\n1 1 2\n", "1 1 15 1\n1 1\n");
    match refused(&text) {
        GmshError::Parse { error, .. } => {
            assert_eq!(error.section, "$Elements");
            assert!(
                error
                    .reason
                    .contains("points (dimension 0) in a block of an entity of dimension 1"),
                "{error}"
            );
        }
        other => panic!("expected Parse, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "point");
}

#[test]
fn cell_listed_twice_is_refused() {
    // E(T)/E⁰ went from 1.326 to 1.366 on a mesh with a cell listed twice.
    let text = edit("2 3 1 3\n", "2 4 1 4\n")
        .replacen("2 1 2 2\n", "2 1 2 3\n", 1)
        .replacen("3 1 3 4\n", "3 1 3 4\n4 3 4 1\n", 1);
    match refused(&text) {
        GmshError::DuplicateCell { element, first, .. } => assert_eq!((element, first), (4, 3)),
        other => panic!("expected DuplicateCell, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "a cell listed twice");
}

#[test]
fn overlapping_cells_are_refused() {
    // A third triangle (1, 2, 4) over the square: it shares edge 1–2 with element 2 on the same
    // side (both traverse it 1 → 2).
    let text = edit("2 3 1 3\n", "2 4 1 4\n")
        .replacen("2 1 2 2\n", "2 1 2 3\n", 1)
        .replacen("3 1 3 4\n", "3 1 3 4\n4 1 2 4\n", 1);
    match refused(&text) {
        GmshError::SameSide { a, b, nodes, .. } => {
            assert_eq!((a, b, nodes), (2, 4, vec![1, 2]));
        }
        other => panic!("expected SameSide, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "overlap");
    // Both diagonals' triangles: the square covered twice, every side shared on one side.
    let text = edit("2 3 1 3\n", "2 5 1 5\n")
        .replacen("2 1 2 2\n", "2 1 2 4\n", 1)
        .replacen("3 1 3 4\n", "3 1 3 4\n4 1 2 4\n5 2 3 4\n", 1);
    assert!(matches!(refused(&text), GmshError::SameSide { .. }));
}

#[test]
fn crack_of_coincident_nodes_is_refused() {
    // Element 3 uses node 5, a copy of node 1 at (0, 0): the two triangles share only node 3, so
    // the diagonal is a crack (two boundary edges on one line).
    let text = edit("2 4 1 4\n", "2 5 1 5\n")
        .replacen(
            "2 1 0 2\n3\n4\n1 1 0\n0 1 0\n",
            "2 1 0 3\n3\n4\n5\n1 1 0\n0 1 0\n0 0 0\n",
            1,
        )
        .replacen("3 1 3 4\n", "3 5 3 4\n", 1);
    match refused(&text) {
        GmshError::CoincidentNodes { a, b, distance, .. } => {
            assert_eq!((a, b, distance), (1, 5, 0.0));
        }
        other => panic!("expected CoincidentNodes, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "coincide");
}

#[test]
fn contact_on_an_interior_face_is_refused() {
    // The diagonal 1–3 is shared by both triangles: the plane inside the body.
    let text = edit("1 1 1 1\n1 1 2\n", "1 1 1 1\n1 1 3\n");
    match refused(&text) {
        GmshError::GroupElement {
            group,
            element,
            reason,
            ..
        } => {
            assert_eq!((group.as_str(), element), ("contact", 1));
            assert!(
                reason.contains("interior face (between elements 2 and 3)"),
                "{reason}"
            );
        }
        other => panic!("expected GroupElement, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "interior face");
}

#[test]
fn contact_elements_of_the_wrong_type_or_no_face_are_refused() {
    // A 3-node line on P1 triangles.
    let text = edit("1 1 1 1\n1 1 2\n", "1 1 8 1\n1 1 2 3\n");
    match refused(&text) {
        GmshError::GroupElement { reason, .. } => assert!(
            reason.contains(
                "a 3-node line, but the faces of the mesh's 3-node triangles are 2-node lines"
            ),
            "{reason}"
        ),
        other => panic!("expected GroupElement, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "3-node line");
    // The line 2–4 crosses the square: no cell has it as an edge ("no face of any cell" failed
    // inside every Nitsche run, after planning accepted the file).
    let text = edit("1 1 1 1\n1 1 2\n", "1 1 1 1\n1 2 4\n");
    match refused(&text) {
        GmshError::GroupElement { reason, .. } => {
            assert!(
                reason.contains("vertices [2, 4] are no face of any cell"),
                "{reason}"
            )
        }
        other => panic!("expected GroupElement, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "no face of any cell");
}

/// One 6-node triangle, corners (0,0), (1,0), (0,1), midside nodes as given (Gmsh order: edges
/// 01, 12, 20), `contact` = edge 01.
fn p2_triangle(m: [[f64; 2]; 3]) -> String {
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 1 \"contact\"\n$EndPhysicalNames\n\
         $Entities\n0 1 1 0\n1 0 0 0 1 0 0 1 1 0\n1 0 0 0 1 1 0 0 1 1\n$EndEntities\n\
         $Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n0 0 0\n1 0 0\n0 1 0\n{} {} 0\n{} {} 0\n{} {} 0\n$EndNodes\n\
         $Elements\n2 2 1 2\n1 1 8 1\n1 1 2 4\n2 1 9 1\n2 1 2 3 4 5 6\n$EndElements\n",
        m[0][0], m[0][1], m[1][0], m[1][1], m[2][0], m[2][1]
    )
}

#[test]
fn folded_p2_triangle_positive_at_the_points_checked_is_refused() {
    // Midside nodes (0.82, 0.07), (0.8, 0.25), (0.08, 0.54): det J (a degree-2 polynomial) is
    // positive at the 9 points the reader sampled (vertices, edge midpoints, the 3 quadrature
    // points; smallest 0.056 at vertex 1) but negative on about 7 % of the cell (a 400 × 400
    // grid), e.g. −0.058 at (0.772, 0.206). Its Bernstein coefficients are not all positive, and
    // subdivision finds a negative value.
    let m = [[0.82, 0.07], [0.8, 0.25], [0.08, 0.54]];
    let mut x = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    x.extend(m.iter().map(|p| [p[0], p[1], 0.0]));
    let det = |xi: [f64; 3]| {
        let g = ElementKind::Tri6.shape_gradients(xi);
        let mut j = [[0.0; 2]; 2];
        for (xa, ga) in x.iter().zip(&g) {
            for r in 0..2 {
                for c in 0..2 {
                    j[r][c] += xa[r] * ga[c];
                }
            }
        }
        j[0][0] * j[1][1] - j[0][1] * j[1][0]
    };
    // The premise: positive where the old check looked, negative inside.
    let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
    for p in [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [0.5, 0.5],
        [0.0, 0.5],
        [a, a],
        [b, a],
        [a, b],
    ] {
        assert!(det([p[0], p[1], 0.0]) > 0.05, "{p:?}");
    }
    assert!(det([0.772, 0.2055, 0.0]) < -0.05);
    let text = p2_triangle(m);
    match refused(&text) {
        GmshError::Inverted {
            element,
            det: d,
            xi,
            ..
        } => {
            assert_eq!(element, 2);
            // A value of det J itself, at the reported point.
            assert!(d < 0.0 && (d - det(xi)).abs() < 1e-12, "{d} at {xi:?}");
        }
        other => panic!("expected Inverted, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "inverted");
    // The straight cell and a gently curved one are certified (det J = 1, and 1 − 0.4 η … > 0).
    let (r, _, _d) = read(&p2_triangle([[0.5, 0.0], [0.5, 0.5], [0.0, 0.5]]));
    r.unwrap_or_else(|e| panic!("{e}"));
    let (r, _, _d) = read(&p2_triangle([[0.5, 0.0], [0.55, 0.55], [0.0, 0.5]]));
    r.unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn p2_midside_node_not_shared_is_refused() {
    // Two 6-node triangles on the unit square sharing the diagonal 1–3, each with its own
    // midside node on it (7 at (0.5, 0.5), 10 at (0.45, 0.55)): the field is cut along it.
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 1 \"contact\"\n$EndPhysicalNames\n\
         $Entities\n0 1 1 0\n1 0 0 0 1 0 0 1 1 0\n1 0 0 0 1 1 0 0 1 1\n$EndEntities\n\
         $Nodes\n1 10 1 10\n2 1 0 10\n1\n2\n3\n4\n5\n6\n7\n8\n9\n10\n\
         0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0 0\n1 0.5 0\n0.5 0.5 0\n0.5 1 0\n0 0.5 0\n0.45 0.55 0\n$EndNodes\n\
         $Elements\n2 3 1 3\n1 1 8 1\n1 1 2 5\n2 1 9 2\n2 1 2 3 5 6 7\n3 1 3 4 10 8 9\n$EndElements\n";
    match refused(text) {
        GmshError::NotConforming {
            a,
            b,
            vertices,
            na,
            nb,
            ..
        } => {
            assert_eq!((a, b, vertices), (2, 3, vec![1, 3]));
            let mut both = [na, nb].concat();
            both.sort_unstable();
            assert_eq!(both, vec![7, 10]);
        }
        other => panic!("expected NotConforming, got {other:?}"),
    }
    refused_by_the_binary(text.as_bytes(), "mesh2d", "not conforming");
}

#[test]
fn nan_z_in_a_2d_mesh_is_refused() {
    for v in ["nan", "NaN", "inf", "-inf"] {
        let text = edit("0 1 0\n$EndNodes", &format!("0 1 {v}\n$EndNodes"));
        match refused(&text) {
            GmshError::NonFinite { node, axis, .. } => assert_eq!((node, axis), (4, "z")),
            other => panic!("expected NonFinite, got {other:?}"),
        }
    }
    let text = edit("0 1 0\n$EndNodes", "0 1 nan\n$EndNodes");
    refused_by_the_binary(text.as_bytes(), "mesh2d", "every coordinate must be finite");
}

#[test]
fn node_tag_given_twice_is_refused() {
    let text = edit("2 1 0 2\n3\n4\n", "2 1 0 2\n3\n2\n");
    match refused(&text) {
        GmshError::DuplicateNodeTag { node, .. } => assert_eq!(node, 2),
        other => panic!("expected DuplicateNodeTag, got {other:?}"),
    }
}

#[test]
fn messages_are_one_line_without_dumps() {
    // mshio answered "Unknown error occurred" with a hex dump of the rest of the file (450 KB
    // for the Hertz mesh). Truncated, damaged and lying files, ASCII and binary: one line each.
    let hertz = committed("hertz_halfdisc.msh");
    let bin = committed("square_tri_p1_bin.msh");
    let mut cases: Vec<Vec<u8>> = vec![
        hertz[..hertz.len() / 2].to_vec(),
        bin[..bin.len() / 2].to_vec(),
        bin[..bin.len() - 12].to_vec(),
    ];
    let mut flipped = hertz.clone();
    let at = flipped.windows(6).position(|w| w == b"$Nodes").unwrap() + 9;
    flipped[at] = b'x';
    cases.push(flipped);
    let mut lying = bin.clone();
    let at = lying.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
    lying[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    cases.push(lying);
    for c in &cases {
        match refused_bytes(c) {
            GmshError::Parse { error, .. } => {
                assert!(
                    error.section.starts_with('$') || error.section == "file",
                    "{error}"
                )
            }
            other => panic!("expected Parse, got {other:?}"),
        }
    }
    // The section is named right after the file.
    refused_by_the_binary(&cases[0], "mesh2d", "body.msh: $");
}

// ---------------------------------------------------------------------------------------------
// Issue 42: the geometric check. A cell laid over others without sharing a face with them
// passed every topological check and ran, its region counted twice. Refused naming both cells;
// shared vertices do not excuse an overlap, and cells merely touching along a boundary pass.

/// The two cells an [`GmshError::Overlap`] names, and its depth.
fn overlap_of(e: GmshError) -> (u64, u64, f64) {
    match e {
        GmshError::Overlap { a, b, depth, .. } => (a, b, depth),
        other => panic!("expected Overlap, got {other:?}"),
    }
}

#[test]
fn p1_triangle_laid_inside_another_is_refused() {
    // A fourth triangle (0.6, 0.1), (0.9, 0.1), (0.9, 0.4) of its own nodes, inside element 2
    // (the lower right half of the square, x ≥ y) and away from element 3.
    let text = edit("2 4 1 4\n", "2 7 1 7\n")
        .replacen(
            "2 1 0 2\n3\n4\n1 1 0\n0 1 0\n",
            "2 1 0 5\n3\n4\n5\n6\n7\n1 1 0\n0 1 0\n0.6 0.1 0\n0.9 0.1 0\n0.9 0.4 0\n",
            1,
        )
        .replacen("2 3 1 3\n", "2 4 1 4\n", 1)
        .replacen("2 1 2 2\n", "2 1 2 3\n", 1)
        .replacen("3 1 3 4\n", "3 1 3 4\n4 5 6 7\n", 1);
    let (a, b, depth) = overlap_of(refused(&text));
    assert_eq!((a, b), (2, 4));
    // The inner triangle is contained: its projections overlap element 2's by its own widths,
    // 0.3 along x and y and 0.3/√2 along the common hypotenuse normal (1, −1)/√2 — the depth.
    // Round-off: a few ulps (5.6e-17) of the coordinates' differences (0.1 is not a double).
    assert!((depth - 0.3 / 2f64.sqrt()).abs() < 1e-15, "{depth}");
    refused_by_the_binary(text.as_bytes(), "mesh2d", "elements 2 and 4 overlap");
}

/// A P2 triangle `A` (corners (0,0), (1,0), (0,1), straight; nodes 1–6) and a second one `B`
/// (nodes 7–12: `corners`, then the midside nodes of edges 01, 12, 20, straight except edge 01's
/// at `m01`); `contact` = A's bottom edge.
fn two_p2_triangles(corners: [[f64; 2]; 3], m01: [f64; 2]) -> String {
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let c = corners;
    let b_nodes = [c[0], c[1], c[2], m01, mid(c[1], c[2]), mid(c[2], c[0])];
    let mut nodes = String::from("0 0 0\n1 0 0\n0 1 0\n0.5 0 0\n0.5 0.5 0\n0 0.5 0\n");
    for p in b_nodes {
        nodes.push_str(&format!("{:?} {:?} 0\n", p[0], p[1]));
    }
    let tags: String = (1..=12).map(|t| format!("{t}\n")).collect();
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n1 1 \"contact\"\n$EndPhysicalNames\n\
         $Entities\n0 1 1 0\n1 0 0 0 1 0 0 1 1 0\n1 -1 -1 0 2 2 0 0 1 1\n$EndEntities\n\
         $Nodes\n1 12 1 12\n2 1 0 12\n{tags}{nodes}$EndNodes\n\
         $Elements\n2 3 1 3\n1 1 8 1\n1 1 2 4\n2 1 9 2\n2 1 2 3 4 5 6\n3 7 8 9 10 11 12\n$EndElements\n"
    )
}

#[test]
fn curved_p2_edge_reaching_into_another_cell_is_refused() {
    // B's corners (0.1, 1.1), (1.1, 0.1), (1.1, 1.1): its edge 01 runs along x + y = 1.2, a gap
    // of 0.2/√2 from A's hypotenuse x + y = 1 — the straight-sided cells are apart. Its midside
    // node at (0.45, 0.45) bends the edge into A (x + y = 0.9 at its middle; B's det J stays
    // positive, the bulge is outwards from B). Only a test of the curved cell sees it.
    let corners = [[0.1, 1.1], [1.1, 0.1], [1.1, 1.1]];
    let text = two_p2_triangles(corners, [0.45, 0.45]);
    let (a, b, depth) = overlap_of(refused(&text));
    assert_eq!((a, b), (2, 3));
    // The node is 0.1/√2 = 0.0707 inside A; the pieces through it reach no deeper, and a
    // penetration below 10⁻⁶ of a cell would not have been refused.
    assert!(
        depth > 1e-3 && depth <= 0.1 / 2f64.sqrt() + 1e-12,
        "{depth}"
    );
    refused_by_the_binary(text.as_bytes(), "mesh2d", "elements 2 and 3 overlap");
    // The same B straight (midside node at the edge's middle, (0.6, 0.6)) is 0.14 away: read.
    let (r, _, _d) = read(&two_p2_triangles(corners, [0.6, 0.6]));
    r.unwrap_or_else(|e| panic!("{e}"));
    // B touching A along A's whole hypotenuse (B's edge 01 on x + y = 1 from (−0.3, 1.3) to
    // (1.5, −0.5), A's corners on it, no node shared): merely touching, read.
    let touching = [[-0.3, 1.3], [1.5, -0.5], [1.5, 1.3]];
    let (r, _, _d) = read(&two_p2_triangles(touching, [0.6, 0.4]));
    r.unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn p1_tetrahedron_inside_another_sharing_a_vertex_is_refused() {
    // Element 2 = the unit corner tetrahedron; element 3 shares its vertex 1 (the origin) and
    // lies inside it ((0.6, 0.2, 0.1), (0.2, 0.6, 0.1), (0.2, 0.2, 0.5): x + y + z = 0.9 < 1),
    // positively oriented (det = 0.144): no face shared, no topological check sees it.
    let text = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"contact\"\n$EndPhysicalNames\n\
         $Entities\n0 0 1 1\n1 0 0 0 1 1 0 1 1 0\n1 0 0 0 1 1 1 0 1 1\n$EndEntities\n\
         $Nodes\n1 7 1 7\n3 1 0 7\n1\n2\n3\n4\n5\n6\n7\n\
         0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.6 0.2 0.1\n0.2 0.6 0.1\n0.2 0.2 0.5\n$EndNodes\n\
         $Elements\n2 3 1 3\n2 1 2 1\n1 1 3 2\n3 1 4 2\n2 1 2 3 4\n3 1 5 6 7\n$EndElements\n";
    let (a, b, depth) = overlap_of(refused(text));
    assert_eq!((a, b), (2, 3));
    // Contained: the depth is element 3's smallest width over the separating axes, positive and
    // below its longest side (0.4 + round-off).
    assert!(depth > 0.01 && depth < 0.4 + 1e-12, "{depth}");
    refused_by_the_binary(text.as_bytes(), "mesh3d", "elements 2 and 3 overlap");
}

/// A committed mesh with a copy of its cell nearest the corner (1, 1[, 1]) shifted by 0.4 of
/// the cell's extent along each axis (new nodes, a new element): the copy sticks out of the
/// body and overlaps that cell alone on a structured mesh. Returns the file, the corner cell's
/// tag and the copy's.
fn shifted_corner_copy(name: &str) -> (Vec<u8>, u64, u64) {
    use contact_sweep::space::fe::msh;
    let mut m = msh::parse(&committed(name)).unwrap();
    let coord: std::collections::HashMap<u64, [f64; 3]> = m
        .node_blocks
        .iter()
        .flat_map(|b| b.tags.iter().copied().zip(b.coords.iter().copied()))
        .collect();
    let d = m.element_blocks.iter().map(|b| b.entity_dim).max().unwrap();
    let bi = m
        .element_blocks
        .iter()
        .position(|b| b.entity_dim == d)
        .unwrap();
    let blk = &m.element_blocks[bi];
    let score = |i: usize| -> f64 {
        let e = blk.element(i);
        e.iter().map(|t| coord[t].iter().sum::<f64>()).sum::<f64>() / e.len() as f64
    };
    let corner = (0..blk.tags.len())
        .max_by(|&i, &j| score(i).total_cmp(&score(j)))
        .unwrap();
    let nodes = blk.element(corner).to_vec();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for t in &nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(coord[t][k]);
            hi[k] = hi[k].max(coord[t][k]);
        }
    }
    let next_node = coord.keys().max().unwrap() + 1;
    let new_nodes: Vec<u64> = (0..nodes.len() as u64).map(|k| next_node + k).collect();
    let corner_tag = blk.tags[corner];
    let new_tag = m
        .element_blocks
        .iter()
        .flat_map(|b| b.tags.iter().copied())
        .max()
        .unwrap()
        + 1;
    let (dim, entity) = (blk.entity_dim, blk.entity_tag);
    m.node_blocks.push(msh::NodeBlock {
        entity_dim: dim,
        entity_tag: entity,
        tags: new_nodes.clone(),
        coords: nodes
            .iter()
            .map(|t| std::array::from_fn(|k| coord[t][k] + 0.4 * (hi[k] - lo[k])))
            .collect(),
    });
    let blk = &mut m.element_blocks[bi];
    blk.tags.push(new_tag);
    blk.nodes.extend(new_nodes);
    let bytes = msh_io::write(&m, &msh_io::Style::default());
    (bytes, corner_tag, new_tag)
}

#[test]
fn shifted_copies_of_quadrilaterals_and_hexahedra_are_refused() {
    // Q1 and Q2 quadrilaterals (2D), Q1 and Q2 hexahedra (3D): the copy of the corner cell,
    // shifted by 0.4 of its extent, overlaps it over 0.6 of its extent along each axis. The
    // unmodified meshes are read (the committed files; `the_committed_meshes_are_read` of
    // gmsh_meshes.rs covers them all).
    for name in [
        "square_quad_q1.msh",
        "square_quad_q2.msh",
        "cube_hex_q1.msh",
        "cube_hex_q2.msh",
    ] {
        let (bytes, corner, copy) = shifted_corner_copy(name);
        let (a, b, depth) = overlap_of(refused_bytes(&bytes));
        let mut named = [a, b];
        named.sort_unstable();
        assert_eq!(named, [corner, copy], "{name}");
        // Boxes overlapping by 0.6 of the cell's sides (0.25 × 0.5 rectangles, cubes of side
        // 0.5): two pieces of them (triangles, tetrahedra) overlap by at most the boxes'
        // overlap along x, 0.15 or 0.3 (a penetration depth is at most the overlap of the
        // projections on any axis); the 1e-12 is round-off.
        let bound = if name.starts_with("square") {
            0.15
        } else {
            0.3
        };
        assert!(depth > 0.0 && depth <= bound + 1e-12, "{name}: {depth}");
    }
    let (bytes, _, _) = shifted_corner_copy("cube_hex_q2.msh");
    refused_by_the_binary(&bytes, "mesh3d", "overlap");
}

#[test]
fn shifted_copies_of_p2_tetrahedra_and_triangles_are_refused() {
    // On unstructured simplex meshes the copy may reach more than the corner cell: the error
    // names the copy and one existing cell it overlaps.
    for (name, scene) in [
        ("cube_tet_p2.msh", "mesh3d"),
        ("cube_tet.msh", "mesh3d"),
        ("square_tri_p2.msh", "mesh2d"),
    ] {
        let (bytes, _, copy) = shifted_corner_copy(name);
        let (a, b, depth) = overlap_of(refused_bytes(&bytes));
        assert!(a != b && (a == copy || b == copy), "{name}: {a}, {b}");
        assert!(depth > 0.0, "{name}: {depth}");
        refused_by_the_binary(&bytes, scene, "overlap");
    }
}
