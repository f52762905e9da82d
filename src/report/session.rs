//! The facts the report states about how the folder was made — the sweep's name and scene,
//! the sweep file as run with its `--set` overrides, the version and commit, when it finished
//! — read from `DIR/manifest.json`'s latest session that recorded its sweep file. A folder
//! without a manifest (runs copied by hand) still gets a report, without these facts.

use std::path::Path;

use anyhow::Context as _;

/// The manifest's facts about the latest session (absent fields: None).
#[derive(Default)]
pub(super) struct Session {
    pub sweep: Option<String>,
    pub scene: Option<String>,
    pub file: Option<String>,
    pub text: Option<String>,
    pub sets: Vec<String>,
    pub version: Option<String>,
    pub commit: Option<String>,
    pub finished: Option<String>,
}

/// The manifest of `dir`, if any: its sweep and the latest session that recorded its file.
pub(super) fn session(dir: &Path) -> anyhow::Result<Session> {
    let path = dir.join("manifest.json");
    if !path.exists() {
        return Ok(Session::default());
    }
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a manifest (invalid JSON)", path.display()))?;
    let s = |v: &serde_json::Value| v.as_str().map(String::from);
    let last = doc["sessions"]
        .as_array()
        .and_then(|a| a.iter().rev().find(|x| x["sweep_text"].is_string()))
        .cloned()
        .unwrap_or_default();
    Ok(Session {
        sweep: s(&doc["sweep"]),
        scene: s(&doc["scene"]),
        file: s(&last["sweep_file"]),
        text: s(&last["sweep_text"]),
        sets: last["overrides"]
            .as_array()
            .map(|a| a.iter().filter_map(s).collect())
            .unwrap_or_default(),
        version: s(&last["version"]),
        commit: s(&last["git_commit"]),
        finished: s(&last["finished"]),
    })
}
