//! The layout is the architecture (ARCHITECTURE.md): a scene lives in `scene/` (and its mesh,
//! if new, in `space/fe/`); the planner, the executor, the sink and the summaries know no scene.
//! Adding a scene is therefore a diff in those two folders only. This test fails when code in
//! `sweep/`, `exec/`, `sink/`, `summary/` or `report/` names a concrete scene or its configuration
//! type.

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
