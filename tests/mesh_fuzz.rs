//! Issue 36's fuzz test: a seeded generator of the mutation classes over the project's
//! Gmsh meshes (`sweeps/meshes/*.msh`, ASCII and binary, 2D and 3D, P1/Q1 and P2/Q2), each case
//! read by the library and, for a subset, planned by the binary.
//!
//! Each case is one of
//! - a valid rewrite — nodes listed in another order (blocks reversed: the bottom row last;
//!   nodes shuffled within their blocks), tag gaps, the other encoding (binary ↔ ASCII), CRLF
//!   line ends, `$Comments` sections, or several of these at once: it must read as the same mesh
//!   as the unmutated file (every field but the content hash, and the node tags after a tag
//!   change), so every run on it gives the same numbers (`rewrites_run_to_the_same_numbers`
//!   checks that on runs);
//! - a damaged file that must be refused: cut short, counts that lie (±1, 10⁹, 10¹⁸, 2⁶⁴ − 1),
//!   a bad `$MeshFormat` line, a cell listed twice, a cell inverted, a node moved onto another,
//!   a non-finite coordinate, a node tag given twice, an undefined node, a `contact` element
//!   that is an interior face or of the wrong type;
//! - random damage (a few bytes changed): refused or read, either is allowed.
//!
//! Never: a panic (caught, with the case's seed), a case over 10 s (a hang), a refusal on more
//! than one line or of 300 characters or more, or one that does not name the file. Every 20th
//! case is also planned by the binary (exit 0 or 2 as the library said, under a 60 s timeout,
//! no panic, no output).
//!
//! 300 cases per run (under a minute in release here); `CONTACT_SWEEP_MESH_FUZZ_CASES=100000`
//! raises the count (the campaign of CONTRIBUTING.md), `CONTACT_SWEEP_MESH_FUZZ_SEED` changes
//! the seed; the counts per class are printed (`--nocapture`).

mod common;
mod msh_io;

use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use contact_sweep::run::RunRecord;
use contact_sweep::space::fe::msh::{self, MshFile};
use contact_sweep::space::fe::{GmshError, GmshMesh};
use msh_io::{Lie, Style};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The committed meshes (top level of `sweeps/meshes/`), sorted by name.
fn bases() -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(root().join("sweeps/meshes"))
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "msh"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// What a case must give.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    /// The same mesh as the base; `tags_changed`: node tags differ (tag gaps).
    Same {
        tags_changed: bool,
    },
    Refused,
    Either,
}

/// A mutated file and what it must give.
struct Case {
    class: &'static str,
    bytes: Vec<u8>,
    expect: Expect,
}

fn rewrite(m: &MshFile, binary: bool, comments: bool) -> Vec<u8> {
    msh_io::write(
        m,
        &Style {
            binary,
            comments,
            lie: Lie::default(),
        },
    )
}

/// Gmsh's local index pairs that mirror a cell (swap to invert it), by type.
fn mirror(element_type: i32) -> &'static [(usize, usize)] {
    match element_type {
        2 => &[(1, 2)],
        9 => &[(1, 2), (3, 5)],
        3 => &[(1, 3)],
        10 => &[(1, 3), (4, 7), (5, 6)],
        4 => &[(0, 1)],
        11 => &[(0, 1), (5, 6), (7, 9)],
        5 => &[(0, 4), (1, 5), (2, 6), (3, 7)],
        _ => &[],
    }
}

/// The interior faces of the cells (as Gmsh face elements: type and nodes in Gmsh's order) of
/// simplex meshes: edges of triangles, faces of tetrahedra (P1 and P2).
fn interior_face(m: &MshFile) -> Option<(i32, Vec<u64>)> {
    let cells = m
        .element_blocks
        .iter()
        .filter(|b| matches!(b.element_type, 2 | 9 | 4 | 11));
    let mut seen: BTreeMap<Vec<u64>, (i32, Vec<u64>)> = BTreeMap::new();
    for b in cells {
        for i in 0..b.tags.len() {
            let c = b.element(i);
            // (face vertices, face element type, its nodes in Gmsh order).
            let faces: Vec<(i32, Vec<u64>)> = match b.element_type {
                2 => [(0, 1), (1, 2), (2, 0)]
                    .iter()
                    .map(|&(p, q)| (1, vec![c[p], c[q]]))
                    .collect(),
                9 => [(0, 1, 3), (1, 2, 4), (2, 0, 5)]
                    .iter()
                    .map(|&(p, q, r)| (8, vec![c[p], c[q], c[r]]))
                    .collect(),
                4 => [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
                    .iter()
                    .map(|f| (2, f.iter().map(|&k| c[k]).collect()))
                    .collect(),
                _ => {
                    // Tet10 edges (Gmsh): 01→4, 12→5, 20→6, 30→7, 32→8, 31→9.
                    let mid = |p: usize, q: usize| {
                        let e = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
                        let k = e
                            .iter()
                            .position(|&(a, b)| (a, b) == (p, q) || (a, b) == (q, p))
                            .unwrap();
                        c[4 + k]
                    };
                    [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]
                        .iter()
                        .map(|f| {
                            let mut n: Vec<u64> = f.iter().map(|&k| c[k]).collect();
                            n.extend([mid(f[0], f[1]), mid(f[1], f[2]), mid(f[2], f[0])]);
                            (9, n)
                        })
                        .collect()
                }
            };
            for (t, nodes) in faces {
                let nv = if t == 1 || t == 8 { 2 } else { 3 };
                let mut key = nodes[..nv].to_vec();
                key.sort_unstable();
                if seen.insert(key, (t, nodes.clone())).is_some() {
                    return Some((t, nodes));
                }
            }
        }
    }
    None
}

/// The index of the `contact` group's first element block, if any.
fn contact_block(m: &MshFile) -> Option<usize> {
    let (d, tag, _) = m.names.iter().find(|n| n.2 == "contact")?;
    let ents = m.entities.as_ref()?;
    let e: Vec<i32> = ents[*d]
        .iter()
        .filter(|e| e.physical_tags.iter().any(|t| t.abs() == *tag))
        .map(|e| e.tag)
        .collect();
    m.element_blocks
        .iter()
        .position(|b| b.entity_dim as usize == *d && e.contains(&b.entity_tag))
}

/// The cell blocks (highest dimension).
fn cell_blocks(m: &MshFile) -> Vec<usize> {
    let d = m
        .element_blocks
        .iter()
        .map(|b| b.entity_dim)
        .max()
        .unwrap_or(0);
    (0..m.element_blocks.len())
        .filter(|&i| m.element_blocks[i].entity_dim == d)
        .collect()
}

fn max_element_tag(m: &MshFile) -> u64 {
    m.element_blocks
        .iter()
        .flat_map(|b| b.tags.iter().copied())
        .max()
        .unwrap_or(0)
}

/// One case from `rng` on the base file `bytes` (parsed: `m`).
fn generate(rng: &mut fastrand::Rng, bytes: &[u8], m: &MshFile) -> Case {
    let bin = m.binary;
    let valid = |class, bytes, tags_changed| Case {
        class,
        bytes,
        expect: Expect::Same { tags_changed },
    };
    let bad = |class, bytes| Case {
        class,
        bytes,
        expect: Expect::Refused,
    };
    match rng.usize(0..20) {
        0 => {
            // The bottom row (the first blocks) last: blocks reversed, header as it was.
            let mut m = m.clone();
            m.node_blocks.reverse();
            valid(
                "rewrite: node blocks reversed",
                rewrite(&m, bin, false),
                false,
            )
        }
        1 => {
            let mut m = m.clone();
            for b in &mut m.node_blocks {
                let mut idx: Vec<usize> = (0..b.tags.len()).collect();
                rng.shuffle(&mut idx);
                b.tags = idx.iter().map(|&i| b.tags[i]).collect();
                b.coords = idx.iter().map(|&i| b.coords[i]).collect();
            }
            rng.shuffle(&mut m.node_blocks);
            valid("rewrite: nodes shuffled", rewrite(&m, bin, false), false)
        }
        2 => {
            // Tag gaps: t → k t + c, increasing, so the numbering is kept.
            let (k, c) = (rng.u64(2..10), rng.u64(0..1000));
            let mut m = m.clone();
            for b in &mut m.node_blocks {
                b.tags.iter_mut().for_each(|t| *t = k * *t + c);
            }
            for b in &mut m.element_blocks {
                b.nodes.iter_mut().for_each(|t| *t = k * *t + c);
            }
            valid("rewrite: tag gaps", rewrite(&m, bin, false), true)
        }
        3 => valid("rewrite: other encoding", rewrite(m, !bin, false), false),
        4 => {
            let ascii = if bin {
                rewrite(m, false, false)
            } else {
                bytes.to_vec()
            };
            let mut out = Vec::with_capacity(ascii.len() * 21 / 20);
            for &b in &ascii {
                if b == b'\n' {
                    out.push(b'\r');
                }
                out.push(b);
            }
            valid("rewrite: CRLF", out, false)
        }
        5 => valid("rewrite: comments", rewrite(m, rng.bool(), true), false),
        6 => {
            let mut m = m.clone();
            m.node_blocks.reverse();
            let mut out = rewrite(&m, false, true);
            if rng.bool() {
                out = String::from_utf8(out)
                    .unwrap()
                    .replace('\n', "\r\n")
                    .into_bytes();
            }
            valid("rewrite: combined", out, false)
        }
        7 => {
            // Cut short inside the data (the last section's end line is always lost).
            let at = rng.usize(8..bytes.len() - 16);
            bad("cut short", bytes[..at].to_vec())
        }
        8 => {
            let huge = [1_000_000_000, 1_000_000_000_000_000_000, u64::MAX];
            let pick = |rng: &mut fastrand::Rng, true_count: u64| {
                if rng.bool() {
                    huge[rng.usize(0..3)]
                } else if rng.bool() || true_count == 0 {
                    true_count + 1
                } else {
                    true_count - 1
                }
            };
            let mut lie = Lie::default();
            let n_nodes: u64 = m.node_blocks.iter().map(|b| b.tags.len() as u64).sum();
            let n_el: u64 = m.element_blocks.iter().map(|b| b.tags.len() as u64).sum();
            match rng.usize(0..7) {
                0 => lie.names = Some(pick(rng, m.names.len() as u64)),
                1 => lie.node_blocks = Some(pick(rng, m.node_blocks.len() as u64)),
                2 => lie.nodes = Some(pick(rng, n_nodes)),
                3 => lie.first_node_block = Some(pick(rng, m.node_blocks[0].tags.len() as u64)),
                4 => lie.element_blocks = Some(pick(rng, m.element_blocks.len() as u64)),
                5 => lie.elements = Some(pick(rng, n_el)),
                _ => {
                    lie.first_element_block = Some(pick(rng, m.element_blocks[0].tags.len() as u64))
                }
            }
            let style = Style {
                binary: rng.bool(),
                comments: false,
                lie,
            };
            bad("count lies", msh_io::write(m, &style))
        }
        9 => {
            let lines = [
                "4.0 0 8",
                "2.2 0 8",
                "4.1 2 8",
                "4.1 1 0",
                "4.1 1 3",
                "4.1 1 ",
                "4.1 1 1234567890123456789012345",
                "4.1",
                "",
                "4.1 0 8 extra $",
            ];
            let line = lines[rng.usize(0..lines.len())];
            let head = if bin {
                "$MeshFormat\n4.1 1 8\n"
            } else {
                "$MeshFormat\n4.1 0 8\n"
            };
            let mut out = format!("$MeshFormat\n{line}\n").into_bytes();
            out.extend_from_slice(&bytes[head.len()..]);
            Case {
                class: "bad $MeshFormat",
                bytes: out,
                // "4.1 0 8 extra $" on an ASCII file: a trailing word the format does not have.
                expect: Expect::Refused,
            }
        }
        10 => {
            let mut m = m.clone();
            let cb = cell_blocks(&m);
            let b = &mut m.element_blocks[cb[rng.usize(0..cb.len())]];
            let i = rng.usize(0..b.tags.len());
            let nodes = b.element(i).to_vec();
            let tag = b.tags.iter().max().unwrap() + 1_000_000;
            b.tags.push(tag);
            b.nodes.extend(nodes);
            bad("cell listed twice", rewrite(&m, rng.bool(), false))
        }
        11 => {
            let mut m = m.clone();
            let cb = cell_blocks(&m);
            let b = &mut m.element_blocks[cb[rng.usize(0..cb.len())]];
            let pairs = mirror(b.element_type);
            if pairs.is_empty() || b.tags.len() < 3 {
                return generate(rng, bytes, &m);
            }
            let i = rng.usize(0..b.tags.len());
            let k = b.nodes_per_element();
            for &(p, q) in pairs {
                b.nodes.swap(i * k + p, i * k + q);
            }
            bad("cell inverted", rewrite(&m, rng.bool(), false))
        }
        12 => {
            // A node moved onto another: a degenerate cell, inverted neighbours or a crack.
            let mut m = m.clone();
            let total: usize = m.node_blocks.iter().map(|b| b.tags.len()).sum();
            let (a, b) = (rng.usize(0..total), rng.usize(0..total));
            if a == b {
                return generate(rng, bytes, &m);
            }
            let at = |m: &MshFile, mut i: usize| {
                for (k, blk) in m.node_blocks.iter().enumerate() {
                    if i < blk.tags.len() {
                        return (k, i);
                    }
                    i -= blk.tags.len();
                }
                unreachable!()
            };
            let (kb, ib) = at(&m, b);
            let target = m.node_blocks[kb].coords[ib];
            let (ka, ia) = at(&m, a);
            m.node_blocks[ka].coords[ia] = target;
            bad("node moved onto another", rewrite(&m, rng.bool(), false))
        }
        13 => {
            let mut m = m.clone();
            let k = rng.usize(0..m.node_blocks.len());
            let blk = &mut m.node_blocks[k];
            let i = rng.usize(0..blk.coords.len());
            let v = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][rng.usize(0..3)];
            blk.coords[i][rng.usize(0..3)] = v;
            bad("non-finite coordinate", rewrite(&m, rng.bool(), false))
        }
        14 => {
            let mut m = m.clone();
            let all: Vec<u64> = m.node_blocks.iter().flat_map(|b| b.tags.clone()).collect();
            let (a, b) = (rng.usize(0..all.len()), rng.usize(0..all.len()));
            if a == b {
                return generate(rng, bytes, &m);
            }
            let mut i = a;
            for blk in &mut m.node_blocks {
                if i < blk.tags.len() {
                    blk.tags[i] = all[b];
                    break;
                }
                i -= blk.tags.len();
            }
            bad("node tag given twice", rewrite(&m, rng.bool(), false))
        }
        15 => {
            let mut m = m.clone();
            let b = rng.usize(0..m.element_blocks.len());
            let blk = &mut m.element_blocks[b];
            let i = rng.usize(0..blk.nodes.len());
            blk.nodes[i] = 1 << 40;
            bad("undefined node", rewrite(&m, rng.bool(), false))
        }
        16 => {
            // A `contact` element on an interior face (simplex meshes), else of the wrong type.
            let mut m = m.clone();
            let Some(cb) = contact_block(&m) else {
                return generate(rng, bytes, &m);
            };
            let tag = max_element_tag(&m) + 1;
            match interior_face(&m) {
                Some((t, nodes)) if m.element_blocks[cb].element_type == t => {
                    let blk = &mut m.element_blocks[cb];
                    blk.tags.push(tag);
                    blk.nodes.extend(nodes);
                    bad(
                        "contact on an interior face",
                        rewrite(&m, rng.bool(), false),
                    )
                }
                _ => {
                    // Lines ↔ 3-node lines, triangles ↔ 6-node ones, quadrilaterals ↔ 9-node.
                    let blk = &mut m.element_blocks[cb];
                    let k = blk.nodes_per_element();
                    let (t, k2) = match blk.element_type {
                        1 => (8, 3),
                        8 => (1, 2),
                        2 => (9, 6),
                        9 => (2, 3),
                        3 => (10, 9),
                        _ => (3, 4),
                    };
                    let first = blk.nodes[0];
                    let mut nodes = Vec::new();
                    for i in 0..blk.tags.len() {
                        for j in 0..k2 {
                            nodes.push(if j < k { blk.nodes[i * k + j] } else { first });
                        }
                    }
                    blk.element_type = t;
                    blk.nodes = nodes;
                    bad("contact of the wrong type", rewrite(&m, rng.bool(), false))
                }
            }
        }
        _ => {
            // Random damage: 1 to 4 bytes changed past the header.
            let mut out = bytes.to_vec();
            for _ in 0..rng.usize(1..5) {
                let i = rng.usize(24..out.len());
                out[i] = b" 0123456789.-e$\n\rx\0\xff"[rng.usize(0..20)];
            }
            Case {
                class: "random bytes",
                bytes: out,
                expect: Expect::Either,
            }
        }
    }
}

/// Equal in every field but the file, the hash and (tag gaps) the node tags.
fn same_mesh(a: &GmshMesh, b: &GmshMesh, tags_changed: bool) -> Result<(), String> {
    let eq = |what: &str, ok: bool| {
        if ok {
            Ok(())
        } else {
            Err(format!("{what} differ"))
        }
    };
    eq("dims/kinds", (a.dim, a.kind) == (b.dim, b.kind))?;
    eq("coordinates", a.coords == b.coords)?;
    eq("cells", a.elements == b.elements)?;
    eq("cell tags", a.element_tags == b.element_tags)?;
    eq("groups", a.groups == b.groups)?;
    eq("h", a.h == b.h)?;
    eq("orientation", a.reoriented == b.reoriented)?;
    if !tags_changed {
        eq("node tags", a.node_tags == b.node_tags)?;
    }
    Ok(())
}

/// Plan a sweep on `mesh` with the binary under a timeout: its exit status and stderr.
fn plan_with_the_binary(dir: &Path, mesh: &[u8], scene: &str) -> (Option<i32>, String) {
    std::fs::write(dir.join("case.msh"), mesh).unwrap();
    std::fs::write(
        dir.join("case.toml"),
        format!("name = \"f\"\nscene = \"{scene}\"\n[fixed]\ndt = 0.1\nmesh = \"case.msh\"\n"),
    )
    .unwrap();
    let mut child = Command::new(common::bin())
        .args(["plan", "case.toml"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read as _;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status.code(), err);
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("plan hangs (over 60 s)");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn mutated_meshes_are_read_the_same_or_refused_on_one_line() {
    let cases: usize = std::env::var("CONTACT_SWEEP_MESH_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300);
    let seed: u64 = std::env::var("CONTACT_SWEEP_MESH_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(36);
    let bases = bases();
    let parsed: Vec<(MshFile, GmshMesh)> = bases
        .iter()
        .map(|(name, b)| {
            (
                msh::parse(b).unwrap_or_else(|e| panic!("{name}: {e}")),
                GmshMesh::from_bytes(name, b).unwrap_or_else(|e| panic!("{e}")),
            )
        })
        .collect();
    // Parser panics are failures: silence the default hook's print, report the case instead.
    std::panic::set_hook(Box::new(|_| {}));
    let tmp = tempfile::tempdir().unwrap();
    let mut tally: BTreeMap<&'static str, (usize, usize)> = BTreeMap::new();
    let mut failures = Vec::new();
    for i in 0..cases {
        let case_seed = seed.wrapping_mul(1_000_003).wrapping_add(i as u64);
        let mut rng = fastrand::Rng::with_seed(case_seed);
        let k = rng.usize(0..bases.len());
        let (name, bytes) = &bases[k];
        let (m, base) = &parsed[k];
        let case = generate(&mut rng, bytes, m);
        let file = format!("{}/case{i}_{name}", tmp.path().display());
        let start = Instant::now();
        let got = catch_unwind(AssertUnwindSafe(|| {
            GmshMesh::from_bytes(&file, &case.bytes)
        }));
        let took = start.elapsed();
        let what = format!("case {i} (seed {case_seed}, {name}, {})", case.class);
        let verdict: Result<bool, String> = match got {
            Err(_) => Err("panicked".into()),
            Ok(_) if took > Duration::from_secs(10) => Err(format!("took {took:?}")),
            Ok(Ok(mesh)) => match case.expect {
                Expect::Same { tags_changed } => {
                    same_mesh(base, &mesh, tags_changed).map(|()| true)
                }
                Expect::Refused => Err("accepted".into()),
                Expect::Either => Ok(true),
            },
            Ok(Err(e)) => {
                let msg = e.to_string();
                if matches!(case.expect, Expect::Same { .. }) {
                    Err(format!("refused: {msg}"))
                } else if msg.contains('\n') || msg.chars().count() >= 300 || !msg.contains(&file) {
                    Err(format!("message: {msg}"))
                } else if matches!(e, GmshError::Io { .. }) {
                    Err(format!("io: {msg}"))
                } else {
                    Ok(false)
                }
            }
        };
        match verdict {
            Err(why) => failures.push(format!("{what}: {why}")),
            Ok(accepted) => {
                let t = tally.entry(case.class).or_default();
                if accepted {
                    t.0 += 1;
                } else {
                    t.1 += 1;
                }
                // The binary plans every 20th case: the same verdict, no panic, nothing run.
                if i % 20 == 0 {
                    let scene = if base.dim == 2 { "mesh2d" } else { "mesh3d" };
                    let (code, err) = plan_with_the_binary(tmp.path(), &case.bytes, scene);
                    let want = if accepted { 0 } else { 2 };
                    if code != Some(want) || err.contains("panicked") {
                        failures.push(format!("{what}: binary exit {code:?}, want {want}: {err}"));
                    }
                }
            }
        }
    }
    let _ = std::panic::take_hook();
    println!("{cases} cases (seed {seed}): class → (read, refused)");
    for (class, (a, r)) in &tally {
        println!("  {class}: {a} read, {r} refused");
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // Every class was drawn (the generator reaches each of them in a few hundred cases).
    if cases >= 300 {
        assert!(tally.len() >= 17, "classes drawn: {:?}", tally.keys());
    }
}

/// The runs' error and energy columns of a run, by name.
fn columns(r: &RunRecord) -> Vec<(&'static str, Option<f64>)> {
    vec![
        ("err_u_l2l2", r.err_u_l2l2),
        ("err_u_l2h1", r.err_u_l2h1),
        ("err_energy_l2", r.err_energy_l2),
        ("err_u_contact_max", r.err_u_contact_max),
        ("energy_initial", r.energy_initial),
        ("energy_final", r.energy_final),
        ("energy_drift", r.energy_drift),
        ("mass_total", r.mass_total),
        ("max_penetration", r.max_penetration),
        ("first_contact_time", r.first_contact_time),
    ]
}

#[test]
fn rewrites_run_to_the_same_numbers() {
    // Each valid rewrite class of the fuzz test on three meshes (P1 triangles with `clamped`, Q2
    // quadrilaterals, binary P1): a short sweep (mixed + CN and Nitsche + CN, against a reference
    // on the same file) on the rewrite gives the unmutated file's error and energy columns to
    // the bit.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for name in [
        "square_tri_p1.msh",
        "square_quad_q2.msh",
        "square_tri_p1_bin.msh",
    ] {
        let bytes = std::fs::read(root().join("sweeps/meshes").join(name)).unwrap();
        let m = msh::parse(&bytes).unwrap();
        let mut reversed = m.clone();
        reversed.node_blocks.reverse();
        let mut gaps = m.clone();
        for b in &mut gaps.node_blocks {
            b.tags.iter_mut().for_each(|t| *t = 3 * *t + 11);
        }
        for b in &mut gaps.element_blocks {
            b.nodes.iter_mut().for_each(|t| *t = 3 * *t + 11);
        }
        let ascii = rewrite(&m, false, false);
        let crlf = String::from_utf8(ascii.clone())
            .unwrap()
            .replace('\n', "\r\n");
        let rewrites: Vec<(&str, Vec<u8>)> = vec![
            ("bottom row last", rewrite(&reversed, m.binary, false)),
            ("tag gaps", rewrite(&gaps, m.binary, false)),
            ("other encoding", rewrite(&m, !m.binary, false)),
            ("CRLF", crlf.into_bytes()),
            ("comments", rewrite(&m, m.binary, true)),
        ];
        let sweep = |mesh: &str| {
            format!(
                "name = \"r\"\nscene = \"mesh2d\"\nreference = {{ dt = 0.0125 }}\n\
                 [fixed]\nmesh = \"{mesh}\"\ndt = 0.025\nT = 0.3\nvelocity = -0.5\ngap = 0.05\n\
                 scheme = \"crank-nicolson\"\n[grid]\nmethod = [{{ space = \"mixed\" }}, \
                 {{ space = \"nitsche\", nitsche_theta = 1.0, nitsche_gamma0 = 0.01 }}]\n"
            )
        };
        std::fs::write(dir.join("base.msh"), &bytes).unwrap();
        let want = common::run_sweep_text_at(&dir.join("s.toml"), &sweep("base.msh"));
        assert_eq!(want.len(), 2);
        for r in &want {
            assert!(r.err_u_l2l2.is_some_and(|e| e.is_finite()), "{name}: {r:?}");
        }
        for (what, b) in rewrites {
            let file = format!("{what}.msh").replace(' ', "_");
            std::fs::write(dir.join(&file), &b).unwrap();
            let got = common::run_sweep_text_at(&dir.join("s.toml"), &sweep(&file));
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(&want) {
                assert_eq!(columns(g), columns(w), "{name}, {what}");
                // Another file, so another run id (the id holds the file's SHA-256).
                assert_ne!(g.run_id, w.run_id);
            }
        }
    }
}
