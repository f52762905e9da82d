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

/// Source text with comments, string and char literals blanked (newlines kept, so line numbers
/// hold) and every `#[cfg(test)]` item removed: what the house rules below read is code only.
fn code_only(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied().unwrap_or('\0');
        if c == '/' && next == '/' {
            while i < b.len() && b[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c == '/' && next == '*' {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if c == 'r'
            && (next == '"' || next == '#')
            && !b[..i]
                .last()
                .is_some_and(|p| p.is_alphanumeric() || *p == '_')
        {
            // Raw string r"…", r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while j < b.len() && b[j] == '#' {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            out.push('"');
            j += 1;
            while j < b.len() {
                if b[j] == '"' && (0..hashes).all(|h| b.get(j + 1 + h) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                out.push(blank(b[j]));
                j += 1;
            }
            out.push('"');
            i = j;
        } else if c == '"' {
            out.push('"');
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < b.len() {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
            out.push('"');
            i += 1;
        } else if c == '\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            let close = if next == '\\' {
                (i + 2..b.len().min(i + 12)).find(|&j| b[j] == '\'')
            } else if b.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(j) => {
                    out.push_str("' '");
                    out.extend(std::iter::repeat_n(' ', j - i - 2));
                    i = j + 1;
                }
                None => {
                    out.push(c);
                    i += 1;
                }
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    strip_test_items(&out)
}

/// Blank each item that follows `#[cfg(test)]` (a `mod tests { … }`, a test-only fn or use).
fn strip_test_items(code: &str) -> String {
    let mut b: Vec<char> = code.chars().collect();
    let pat: Vec<char> = "#[cfg(test)]".chars().collect();
    let mut i = 0;
    while i + pat.len() <= b.len() {
        if b[i..i + pat.len()] != pat[..] {
            i += 1;
            continue;
        }
        let start = i;
        let mut j = i + pat.len();
        let mut depth = 0usize;
        while j < b.len() {
            match b[j] {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                ';' if depth == 0 => break,
                _ => {}
            }
            j += 1;
        }
        let stop = (j + 1).min(b.len());
        for c in &mut b[start..stop] {
            if *c != '\n' {
                *c = ' ';
            }
        }
        i = j + 1;
    }
    b.into_iter().collect()
}

/// (name, first line, length in lines) of every function with a body in `code`.
fn functions(code: &str) -> Vec<(String, usize, usize)> {
    let b: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    let line_at = |k: usize| b[..k].iter().filter(|&&c| c == '\n').count() + 1;
    for i in 0..b.len().saturating_sub(3) {
        if b[i..i + 3] != ['f', 'n', ' '] || (i > 0 && is_ident(b[i - 1])) {
            continue;
        }
        let name: String = b[i + 3..].iter().take_while(|c| is_ident(**c)).collect();
        if name.is_empty() {
            continue;
        }
        // The body's brace, or the `;` of a declaration — outside the signature's brackets,
        // where `[f64; 3]` holds a `;` too.
        let mut nest = 0i32;
        let Some(open) = (i..b.len()).find(|&k| {
            match b[k] {
                '(' | '[' => nest += 1,
                ')' | ']' => nest -= 1,
                _ => {}
            }
            nest == 0 && (b[k] == '{' || b[k] == ';')
        }) else {
            continue;
        };
        if b[open] == ';' {
            continue;
        }
        let mut depth = 0;
        let mut end = open;
        for (k, &c) in b.iter().enumerate().skip(open) {
            if c == '{' {
                depth += 1;
            } else if c == '}' {
                depth -= 1;
                if depth == 0 {
                    end = k;
                    break;
                }
            }
        }
        let first = line_at(i);
        out.push((name, first, line_at(end) - first + 1));
    }
    out
}

/// The house rule: a function fits in one reading. Tests (`#[cfg(test)]` items) are exempt.
const MAX_FN_LINES: usize = 150;

#[test]
fn no_function_in_src_is_longer_than_150_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let mut long = Vec::new();
    let mut seen = 0;
    for f in &files {
        let code = code_only(&std::fs::read_to_string(f).unwrap());
        for (name, line, len) in functions(&code) {
            seen += 1;
            if len > MAX_FN_LINES {
                long.push(format!("{}:{line}: fn {name} has {len} lines", f.display()));
            }
        }
    }
    assert!(seen > 1000, "found only {seen} functions");
    assert!(
        long.is_empty(),
        "functions over {MAX_FN_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn the_function_scanner_measures_bodies_not_strings_or_tests() {
    let src = "fn a() {\n    let s = \"}\";\n    let c = '}';\n}\n// fn b() {\n#[cfg(test)]\nmod tests {\n    fn t() {\n    }\n}\nfn c<'a>(x: &'a str) -> usize where 'a: 'a {\n  1\n}\ntrait T { fn d(&self); }\nfn e(x: [f64; 3]) -> f64 {\n  x[0]\n}\n";
    let f = functions(&code_only(src));
    let got: Vec<_> = f.iter().map(|(n, l, k)| (n.as_str(), *l, *k)).collect();
    assert_eq!(got, [("a", 1, 4), ("c", 11, 3), ("e", 15, 3)]);
}

/// The modules (files and subfolders) of one folder, and who of them names whom.
struct Folder {
    nodes: Vec<String>,
    edges: Vec<(usize, usize, String)>,
}

/// Child module names declared by a `mod.rs` (or `lib.rs`), and the names it re-exports from
/// each (`pub use child::{A, B}`): an item reached through `super::A` lives in that child.
fn declared(mod_code: &str) -> (Vec<String>, Vec<(String, String)>) {
    let mut children = Vec::new();
    let mut reexports = Vec::new();
    for l in mod_code.lines() {
        let t = l.trim();
        let t = t
            .strip_prefix("pub(crate) ")
            .or_else(|| t.strip_prefix("pub(super) "))
            .or_else(|| t.strip_prefix("pub "))
            .unwrap_or(t);
        if let Some(m) = t.strip_prefix("mod ").and_then(|m| m.strip_suffix(';')) {
            children.push(m.trim().to_string());
        }
    }
    // `pub use` statements may span lines.
    let flat = mod_code.replace('\n', " ");
    for stmt in flat.split(';') {
        let s = stmt.trim();
        let Some(path) = s
            .strip_prefix("pub use ")
            .or_else(|| s.strip_prefix("pub(crate) use "))
            .or_else(|| s.strip_prefix("pub(super) use "))
        else {
            continue;
        };
        let path = path.trim().trim_start_matches("self::");
        let child: String = path
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !children.contains(&child) {
            continue;
        }
        for name in path.split(|c: char| !(c.is_alphanumeric() || c == '_')) {
            if !name.is_empty() && name != child {
                reexports.push((name.to_string(), child.clone()));
            }
        }
    }
    (children, reexports)
}

fn is_reexport_or_decl(line: &str) -> bool {
    let t = line.trim();
    let t = t
        .strip_prefix("pub(crate) ")
        .or_else(|| t.strip_prefix("pub(super) "))
        .or_else(|| t.strip_prefix("pub "))
        .unwrap_or(t);
    t.starts_with("mod ")
        || line.trim_start().starts_with("pub use ")
        || line.trim_start().starts_with("pub(crate) use ")
        || line.trim_start().starts_with("pub(super) use ")
}

/// The sibling modules a path names: `prefix` is how this file reaches its folder
/// (`super::` from a child file, `super::super::` from a grandchild, `crate::a::b::` anywhere).
fn sibling_refs(
    code: &str,
    prefixes: &[String],
    children: &[String],
    reexports: &[(String, String)],
    own_is_mod: bool,
    out: &mut Vec<(String, String)>,
) {
    let flat: Vec<(usize, String)> = code
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.to_string()))
        .collect();
    let mut in_pub_use = false;
    for (n, line) in &flat {
        // A multi-line `pub use … ;` in mod.rs is a re-export throughout.
        if own_is_mod && (is_reexport_or_decl(line) || in_pub_use) {
            in_pub_use = !line.contains(';');
            continue;
        }
        let mut targets: Vec<String> = Vec::new();
        for p in prefixes {
            let mut at = 0;
            while let Some(k) = line[at..].find(p.as_str()) {
                let abs = at + k;
                let before_ok = abs == 0
                    || !line[..abs]
                        .ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':');
                let after = &line[abs + p.len()..];
                at = abs + p.len();
                if !before_ok {
                    continue;
                }
                if let Some(group) = after.strip_prefix('{') {
                    // super::{a::X, B}: first segments at depth 1 (one line is enough here).
                    let mut depth = 1;
                    let mut seg = String::new();
                    let mut firsts = vec![];
                    let mut take = true;
                    for c in group.chars() {
                        match c {
                            '{' => depth += 1,
                            '}' => {
                                depth -= 1;
                                if depth == 0 {
                                    break;
                                }
                            }
                            ',' if depth == 1 => {
                                take = true;
                                continue;
                            }
                            _ => {}
                        }
                        if depth == 1 && take {
                            if c.is_alphanumeric() || c == '_' {
                                seg.push(c);
                            } else if !seg.is_empty() {
                                firsts.push(std::mem::take(&mut seg));
                                take = false;
                            }
                        }
                    }
                    if !seg.is_empty() {
                        firsts.push(seg);
                    }
                    targets.extend(firsts);
                } else {
                    let name: String = after
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    targets.push(name);
                }
            }
        }
        if own_is_mod {
            // Children are in scope in mod.rs without a prefix: `child::f(…)`, `use child::X;`.
            for c in children {
                let pat = format!("{c}::");
                let mut at = 0;
                while let Some(k) = line[at..].find(&pat) {
                    let abs = at + k;
                    at = abs + pat.len();
                    if abs == 0
                        || !line[..abs]
                            .ends_with(|ch: char| ch.is_alphanumeric() || ch == '_' || ch == ':')
                    {
                        targets.push(c.clone());
                    }
                }
            }
        }
        for t in targets {
            if t.is_empty() || t == "self" || t == "super" || t == "crate" {
                continue;
            }
            let node = if children.contains(&t) {
                t.clone()
            } else if let Some((_, c)) = reexports.iter().find(|(name, _)| *name == t) {
                c.clone()
            } else {
                "mod".to_string()
            };
            out.push((node, format!("line {n}: {}", line.trim())));
        }
    }
}

/// Every folder of `src/` with its module graph.
fn folders(root: &Path) -> Vec<(std::path::PathBuf, Folder)> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let face = if dir == root {
            dir.join("lib.rs")
        } else {
            dir.join("mod.rs")
        };
        let Ok(face_text) = std::fs::read_to_string(&face) else {
            continue;
        };
        let face_code = code_only(&face_text);
        let (children, reexports) = declared(&face_code);
        let mut nodes = vec!["mod".to_string()];
        nodes.extend(children.iter().cloned());
        let rel: Vec<String> = dir
            .strip_prefix(root)
            .unwrap()
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        let crate_prefix = if rel.is_empty() {
            "crate::".to_string()
        } else {
            format!("crate::{}::", rel.join("::"))
        };
        let mut edges = Vec::new();
        // The face itself.
        let mut refs = Vec::new();
        let self_prefixes = if rel.is_empty() {
            vec!["crate::".to_string(), "self::".to_string()]
        } else {
            vec![crate_prefix.clone(), "self::".to_string()]
        };
        sibling_refs(
            &face_code,
            &self_prefixes,
            &children,
            &reexports,
            true,
            &mut refs,
        );
        for (to, why) in refs {
            if to != "mod" {
                let j = nodes.iter().position(|n| *n == to).unwrap();
                edges.push((0, j, format!("{}: {why}", face.display())));
            }
        }
        // Each child: a file, or a subfolder whose files all speak for it.
        for (ci, c) in children.iter().enumerate() {
            let file = dir.join(format!("{c}.rs"));
            let sub = dir.join(c);
            let mut files = Vec::new();
            if file.is_file() {
                files.push((file, 1usize));
            }
            if sub.is_dir() {
                stack.push(sub.clone());
                let mut fs = Vec::new();
                rust_files(&sub, &mut fs);
                for f in fs {
                    let depth = f.strip_prefix(&sub).unwrap().components().count();
                    let is_face = f.file_name().is_some_and(|n| n == "mod.rs");
                    // super:: from sub/mod.rs reaches this folder; from sub/x.rs, super::super::.
                    let d = if is_face { depth } else { depth + 1 };
                    files.push((f, d.saturating_sub(1).max(1)));
                }
            }
            for (f, d) in files {
                let code = code_only(&std::fs::read_to_string(&f).unwrap());
                let sup = "super::".repeat(d);
                let mut prefixes = vec![crate_prefix.clone()];
                if !rel.is_empty() || d > 1 || !crate_prefix.is_empty() {
                    prefixes.push(sup);
                }
                if rel.is_empty() {
                    // At the crate root, siblings are reached as crate::x only (super:: from a
                    // top-level file also lands at the root).
                    prefixes = vec!["crate::".to_string(), "super::".repeat(d)];
                }
                let mut refs = Vec::new();
                sibling_refs(&code, &prefixes, &children, &reexports, false, &mut refs);
                for (to, why) in refs {
                    let j = nodes.iter().position(|n| *n == to).unwrap();
                    if j != ci + 1 {
                        edges.push((ci + 1, j, format!("{}: {why}", f.display())));
                    }
                }
            }
        }
        out.push((dir, Folder { nodes, edges }));
    }
    out
}

/// The strongly connected groups of a folder's module graph with more than one member (a
/// cycle runs through each), each with the edges inside it and the line that makes each edge.
fn cycles(f: &Folder) -> Vec<Vec<String>> {
    let n = f.nodes.len();
    let reach = |from: usize| {
        let mut seen = vec![false; n];
        let mut stack = vec![from];
        while let Some(u) = stack.pop() {
            for (a, b, _) in &f.edges {
                if *a == u && !seen[*b] {
                    seen[*b] = true;
                    stack.push(*b);
                }
            }
        }
        seen
    };
    let reaches: Vec<Vec<bool>> = (0..n).map(reach).collect();
    let mut done = vec![false; n];
    let mut out = Vec::new();
    for u in 0..n {
        if done[u] {
            continue;
        }
        let group: Vec<usize> = (0..n).filter(|&v| reaches[u][v] && reaches[v][u]).collect();
        for &v in &group {
            done[v] = true;
        }
        if group.len() < 2 {
            continue;
        }
        let mut lines = Vec::new();
        let mut pairs = Vec::new();
        for (a, b, why) in &f.edges {
            if group.contains(a) && group.contains(b) && !pairs.contains(&(*a, *b)) {
                pairs.push((*a, *b));
                lines.push(format!("{} -> {}  ({why})", f.nodes[*a], f.nodes[*b]));
            }
        }
        out.push(lines);
    }
    out
}

/// Inside a folder too, imports go one way: no two files name each other, and more generally
/// the files of a folder (its `mod.rs` counted as one, minus its `mod` and `pub use` lines,
/// which only declare the folder's face) form no cycle — so each folder has an order, bottom
/// to top, that a reader can follow.
#[test]
fn files_of_a_folder_import_one_way() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let all = folders(&root);
    assert!(all.len() >= 12, "found only {} folders", all.len());
    let mut bad = Vec::new();
    for (dir, f) in &all {
        for c in cycles(f) {
            bad.push(format!("{}:\n    {}", dir.display(), c.join("\n    ")));
        }
    }
    assert!(
        bad.is_empty(),
        "import cycles inside a folder:\n{}",
        bad.join("\n")
    );
}
