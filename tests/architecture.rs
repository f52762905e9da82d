//! The layout is the architecture (ARCHITECTURE.md):
//! - The modules form a pipeline, `space, time, contact < scene < model < run < sweep < sink <
//!   exec < summary < report < cli`, and code imports only modules below its own
//!   ([`imports_point_down_the_pipeline`]): each layer can be read, tested and changed without
//!   the ones above it, and the dependency picture of `src/` has no cycle.
//! - A scene lives in `scene/` (and its mesh, if new, in `space/fe/`); the planner, the
//!   executor, the sink and the summaries know no scene. Adding a scene is therefore a diff in
//!   those two folders only ([`planner_executor_sink_and_summaries_know_no_scene`]).

use std::path::Path;

const SCENE_WORDS: [&str; 11] = [
    "bar1d",
    "bar2d",
    "bar3d",
    "disc2d",
    "sphere3d",
    "Bar1d",
    "BarScene",
    "BarParams",
    "FeConfig",
    "FeSetup",
    "SceneSetup",
];

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn planner_executor_sink_and_summaries_know_no_scene() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    for layer in ["sweep", "exec", "sink", "summary", "report"] {
        rust_files(&root.join(layer), &mut files);
    }
    assert!(files.len() >= 10, "found only {} files", files.len());
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        // Unit tests inside a module may use a concrete scene as their example.
        let code = text.split("#[cfg(test)]").next().unwrap();
        for (i, line) in code.lines().enumerate() {
            let l = line.trim_start();
            if l.starts_with("//") {
                continue;
            }
            for w in SCENE_WORDS {
                if l.contains(w) {
                    found.push(format!("{}:{}: `{w}` in {l}", f.display(), i + 1));
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "scene-specific code outside scene/:\n{}",
        found.join("\n")
    );
}

/// The pipeline's order: a module may name (`crate::NAME`) only modules of a lower rank. The
/// bottom group (space, time, contact) names none of the others.
const LAYERS: [(&str, u32); 12] = [
    ("space", 0),
    ("time", 0),
    ("contact", 0),
    ("scene", 1),
    ("model", 2),
    ("run", 3),
    ("sweep", 4),
    ("sink", 5),
    ("exec", 6),
    ("summary", 7),
    ("report", 8),
    ("cli", 9),
];

fn rank(module: &str) -> Option<u32> {
    LAYERS.iter().find(|(m, _)| *m == module).map(|(_, r)| *r)
}

/// The top-level module names a line of code refers to through `crate::` — `crate::run::X`,
/// and each first segment of a group `use crate::{run::X, sweep::{…}}` (which may span lines:
/// `group` carries the open brace depth between lines).
fn crate_refs(line: &str, group: &mut usize, out: &mut Vec<String>) {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut rest = line;
    while *group > 0 && !rest.is_empty() {
        // Inside `use crate::{ … }`: a name at depth 1 is a top-level module.
        let t = rest.trim_start_matches([' ', ',']);
        if let Some(after) = t.strip_prefix('}') {
            *group -= 1;
            rest = after;
        } else if let Some(after) = t.strip_prefix('{') {
            *group += 1;
            rest = after;
        } else {
            let name = ident(t);
            if name.is_empty() {
                rest = &t[t.chars().next().map_or(0, char::len_utf8)..];
                continue;
            }
            if *group == 1 && !name.is_empty() && name != "self" {
                out.push(name.clone());
            }
            rest = &t[name.len()..];
            // Skip the path after the first segment up to the next separator at this depth.
            let t2 = rest.trim_start_matches(':');
            if let Some(after) = t2.strip_prefix('{') {
                *group += 1;
                rest = after;
            } else {
                let cut = t2.find([',', '{', '}']).unwrap_or(t2.len());
                let seg = &t2[..cut];
                rest = &t2[seg.len()..];
            }
        }
    }
    let mut at = 0;
    while let Some(k) = rest[at..].find("crate::") {
        let after = &rest[at + k + "crate::".len()..];
        if let Some(inner) = after.strip_prefix('{') {
            *group = 1;
            let mut sub = Vec::new();
            crate_refs(inner, group, &mut sub);
            out.extend(sub);
            return;
        }
        out.push(ident(after));
        at += k + "crate::".len();
    }
}

#[test]
fn imports_point_down_the_pipeline() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    // Every top-level module of the library has its place in the order.
    let lib = std::fs::read_to_string(root.join("lib.rs")).unwrap();
    for l in lib.lines() {
        if let Some(m) = l.strip_prefix("pub mod ").and_then(|m| m.strip_suffix(';')) {
            assert!(
                rank(m).is_some(),
                "module `{m}` has no place in the pipeline order of tests/architecture.rs"
            );
        }
    }
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut up = Vec::new();
    let mut checked = 0;
    for f in &files {
        let rel = f.strip_prefix(&root).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let top = top.trim_end_matches(".rs");
        let Some(own) = rank(top) else { continue };
        checked += 1;
        let text = std::fs::read_to_string(f).unwrap();
        // A module's unit tests may reach up (e.g. plan a sweep to get a run to test).
        let code = text.split("#[cfg(test)]").next().unwrap();
        let mut group = 0;
        for (i, line) in code.lines().enumerate() {
            let l = line.trim_start();
            if l.starts_with("//") {
                continue;
            }
            let l = l.split(" //").next().unwrap();
            let mut refs = Vec::new();
            crate_refs(l, &mut group, &mut refs);
            for r in refs {
                if let Some(theirs) = rank(&r)
                    && theirs >= own
                    && r != top
                {
                    up.push(format!(
                        "{}:{}: {top} imports {r}: {}",
                        rel.display(),
                        i + 1,
                        l.trim()
                    ));
                }
            }
        }
    }
    assert!(checked >= 60, "checked only {checked} files");
    assert!(
        up.is_empty(),
        "imports pointing up the pipeline:\n{}",
        up.join("\n")
    );
}

#[test]
fn the_import_scanner_sees_paths_and_groups() {
    let mut g = 0;
    let mut out = Vec::new();
    crate_refs("use crate::sweep::{Key, RunSpec};", &mut g, &mut out);
    assert_eq!(out, ["sweep"]);
    out.clear();
    crate_refs(
        "let x = crate::run::fe::f(crate::space::g());",
        &mut g,
        &mut out,
    );
    assert_eq!(out, ["run", "space"]);
    out.clear();
    crate_refs("use crate::{", &mut g, &mut out);
    crate_refs(
        "    exec::RunResult, model::{Key, Value},",
        &mut g,
        &mut out,
    );
    crate_refs("    summary,", &mut g, &mut out);
    crate_refs("};", &mut g, &mut out);
    assert_eq!(out, ["exec", "model", "summary"]);
    assert_eq!(g, 0);
}
