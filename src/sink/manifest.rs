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
    path: std::path::PathBuf,
    /// This session's id in the `sessions` list.
    id: String,
}

/// What a run found of DIR's manifest before its session starts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ManifestState {
    /// No manifest (a new folder, or one whose manifest was lost).
    Missing,
    /// A readable manifest, recording this sweep name (if any).
    Sweep(Option<String>),
    /// Not valid JSON: moved aside to the given path, to be rebuilt by the session.
    MovedAside {
        to: std::path::PathBuf,
        reason: String,
    },
}

impl Manifest {
    /// Inspect DIR's manifest before a session: a damaged one is moved aside to
    /// `DIR/damaged/manifest.json` (the session rebuilds it from its sweep file; the sessions
    /// it recorded are lost, the results are not).
    pub fn inspect(dir: &Path) -> Result<ManifestState, SinkError> {
        let path = dir.join("manifest.json");
        let lock_path = dir.join(".manifest.lock");
        let _lock = super::lock_exclusive(&lock_path).map_err(|source| SinkError::Io {
            path: lock_path.clone(),
            source,
        })?;
        match Self::existing_sweep(dir) {
            Ok(None) if !path.exists() => Ok(ManifestState::Missing),
            Ok(name) => Ok(ManifestState::Sweep(name)),
            Err(SinkError::Manifest { message, .. }) => {
                let to = super::damaged_dir(dir, "manifest.json");
                if let Some(parent) = to.parent() {
                    std::fs::create_dir_all(parent).map_err(|source| SinkError::Io {
                        path: parent.to_path_buf(),
                        source,
                    })?;
                }
                std::fs::rename(&path, &to).map_err(|source| SinkError::Io {
                    path: path.clone(),
                    source,
                })?;
                Ok(ManifestState::MovedAside {
                    to,
                    reason: message,
                })
            }
            Err(e) => Err(e),
        }
    }

    /// DIR's manifest as JSON (`None` without one).
    pub fn read(dir: &Path) -> Result<Option<Json>, SinkError> {
        let path = dir.join("manifest.json");
        if !path.exists() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path).map_err(|source| SinkError::Io {
            path: path.clone(),
            source,
        })?;
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| SinkError::Manifest {
                path,
                message: e.to_string(),
            })
    }

    /// Read DIR's manifest if any: the sweep name it records.
    pub fn existing_sweep(dir: &Path) -> Result<Option<String>, SinkError> {
        Ok(Manifest::read(dir)?.and_then(|doc| doc["sweep"].as_str().map(String::from)))
    }

    /// The sweep file's text of DIR's latest session that recorded one (`None` without a
    /// manifest or without such a session): where `summarize DIR` finds the `[summary]` table.
    pub fn latest_sweep_text(dir: &Path) -> Result<Option<String>, SinkError> {
        Ok(Manifest::latest_sweep(dir)?.map(|(text, _)| text))
    }

    /// The sweep file's text of DIR's latest session that recorded one, with the `--set`
    /// arguments that session applied on top of it (empty for sessions of older versions).
    pub fn latest_sweep(dir: &Path) -> Result<Option<(String, Vec<String>)>, SinkError> {
        let Some(doc) = Manifest::read(dir)? else {
            return Ok(None);
        };
        Ok(doc["sessions"].as_array().and_then(|s| {
            s.iter().rev().find_map(|x| {
                let text = x["sweep_text"].as_str()?.to_string();
                let sets = x["overrides"]
                    .as_array()
                    .map(|a| {
                        a.iter()
                            .filter_map(|v| v.as_str().map(String::from))
                            .collect()
                    })
                    .unwrap_or_default();
                Some((text, sets))
            })
        }))
    }

    /// Start a session: create or extend the manifest. `shard` is the shards it runs (`K/N`,
    /// `A-B/N`, … of a job array).
    pub fn begin(
        dir: &Path,
        plan: &Plan,
        planned: usize,
        skipped: usize,
        threads: usize,
        shard: Option<String>,
    ) -> Result<Manifest, SinkError> {
        let path = dir.join("manifest.json");
        let id = format!(
            "{}-{}",
            SystemTime::now()
                .duration_since(SystemTime::UNIX_EPOCH)
                .unwrap_or_default()
                .as_nanos(),
            std::process::id()
        );
        let commit = env!("CONTACT_SWEEP_GIT_COMMIT");
        let session = json!({
            "id": id,
            "started": now(),
            "finished": Json::Null,
            "version": env!("CARGO_PKG_VERSION"),
            "git_commit": if commit.is_empty() { Json::Null } else { Json::from(commit) },
            "machine": machine(),
            "threads": threads,
            "shard": shard,
            "sweep_file": plan.sweep.path.display().to_string(),
            "sweep_text": plan.sweep.text,
            // `--set key=value` applied on top of sweep_text, in order.
            "overrides": plan.sweep.sets,
            "runs_planned": planned,
            "runs_skipped_as_done": skipped,
            "runs_written": 0,
        });
        let m = Manifest { path, id };
        m.update(dir, |doc| {
            if doc.is_null() {
                *doc = json!({
                    "tool": "contact-sweep",
                    "sweep": plan.sweep.name,
                    "scene": plan.sweep.scene.name(),
                    "sessions": [],
                });
            }
            if !doc["sessions"].is_array() {
                doc["sessions"] = json!([]);
            }
            doc["sessions"].as_array_mut().expect("array").push(session);
        })?;
        Ok(m)
    }

    /// Read-modify-write under an exclusive lock on DIR/.manifest.lock: the shards of a job
    /// array start and finish concurrently, and none may lose another's session entry.
    fn update(&self, dir: &Path, f: impl FnOnce(&mut Json)) -> Result<(), SinkError> {
        let lock_path = dir.join(".manifest.lock");
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SinkError::Io { path, source }
        };
        let _lock = super::lock_exclusive(&lock_path).map_err(io(&lock_path))?;
        let mut doc = if self.path.exists() {
            let text = std::fs::read_to_string(&self.path).map_err(io(&self.path))?;
            serde_json::from_str(&text).map_err(|e| SinkError::Manifest {
                path: self.path.clone(),
                message: e.to_string(),
            })?
        } else {
            Json::Null
        };
        f(&mut doc);
        let text = serde_json::to_string_pretty(&doc).expect("JSON values serialize");
        write_atomic(&self.path, text.as_bytes())
        // the lock is released when `lock` drops
    }

    /// Close the session with its end time and the number of rows written.
    pub fn finish(
        &mut self,
        dir: &Path,
        written: usize,
        interrupted: bool,
    ) -> Result<(), SinkError> {
        let id = self.id.clone();
        self.update(dir, |doc| {
            if let Some(me) = doc["sessions"]
                .as_array_mut()
                .and_then(|a| a.iter_mut().find(|s| s["id"] == id.as_str()))
            {
                me["finished"] = Json::from(now());
                me["runs_written"] = Json::from(written);
                me["interrupted"] = Json::from(interrupted);
            }
        })
    }
}
