//! `DIR/manifest.json`: what produced the folder — the sweep file's text, the tool version, the
//! git commit it was built from (if known), the machine, and one entry per session (start and
//! end times, runs planned, skipped as already done, and written).

use std::path::Path;
use std::time::SystemTime;

use serde_json::{Value as Json, json};

use super::{SinkError, write_atomic};
use crate::sweep::Plan;

fn now() -> String {
    humantime::format_rfc3339_seconds(SystemTime::now()).to_string()
}

fn machine() -> Json {
    let hostname = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .or_else(|_| std::env::var("HOSTNAME"))
        .unwrap_or_default();
    json!({
        "hostname": hostname,
        "os": std::env::consts::OS,
        "arch": std::env::consts::ARCH,
        "cpus": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
    })
}

/// The manifest of a results folder.
pub struct Manifest {
    doc: Json,
    path: std::path::PathBuf,
}

impl Manifest {
    /// Read DIR's manifest if any: the sweep name it records.
    pub fn existing_sweep(dir: &Path) -> Result<Option<String>, SinkError> {
        let path = dir.join("manifest.json");
        if !path.exists() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path).map_err(|source| SinkError::Io {
            path: path.clone(),
            source,
        })?;
        let doc: Json = serde_json::from_str(&text).map_err(|e| SinkError::Manifest {
            path: path.clone(),
            message: e.to_string(),
        })?;
        Ok(doc["sweep"].as_str().map(String::from))
    }

    /// Start a session: create or extend the manifest.
    pub fn begin(
        dir: &Path,
        plan: &Plan,
        planned: usize,
        skipped: usize,
        threads: usize,
    ) -> Result<Manifest, SinkError> {
        let path = dir.join("manifest.json");
        let mut doc = if path.exists() {
            let text = std::fs::read_to_string(&path).map_err(|source| SinkError::Io {
                path: path.clone(),
                source,
            })?;
            serde_json::from_str(&text).map_err(|e| SinkError::Manifest {
                path: path.clone(),
                message: e.to_string(),
            })?
        } else {
            json!({
                "tool": "contact-sweep",
                "sweep": plan.sweep.name,
                "scene": plan.sweep.scene.name(),
                "sessions": [],
            })
        };
        let commit = env!("CONTACT_SWEEP_GIT_COMMIT");
        let session = json!({
            "started": now(),
            "finished": Json::Null,
            "version": env!("CARGO_PKG_VERSION"),
            "git_commit": if commit.is_empty() { Json::Null } else { Json::from(commit) },
            "machine": machine(),
            "threads": threads,
            "sweep_file": plan.sweep.path.display().to_string(),
            "sweep_text": plan.sweep.text,
            "runs_planned": planned,
            "runs_skipped_as_done": skipped,
            "runs_written": 0,
        });
        if !doc["sessions"].is_array() {
            doc["sessions"] = json!([]);
        }
        doc["sessions"].as_array_mut().expect("array").push(session);
        let m = Manifest { doc, path };
        m.save()?;
        Ok(m)
    }

    fn save(&self) -> Result<(), SinkError> {
        let text = serde_json::to_string_pretty(&self.doc).expect("JSON values serialize");
        write_atomic(&self.path, text.as_bytes())
    }

    /// Close the session with its end time and the number of rows written.
    pub fn finish(&mut self, written: usize, interrupted: bool) -> Result<(), SinkError> {
        if let Some(last) = self.doc["sessions"]
            .as_array_mut()
            .and_then(|a| a.last_mut())
        {
            last["finished"] = Json::from(now());
            last["runs_written"] = Json::from(written);
            last["interrupted"] = Json::from(interrupted);
        }
        self.save()
    }
}
