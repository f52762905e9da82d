//! `contact-sweep status DIR`: what a results folder holds against what its sweep plans.
//!
//! The plan is the sweep file the manifest records (or the frozen copy of a Slurm submission,
//! or `--sweep`); a run is *done* when its row is in a readable runs part — whatever its status,
//! which is counted (`ok`, `diverged`, `timeout`, …: a failed run is a result, not a gap) — and
//! *missing* otherwise. Shards are those of the folder's sessions (`--shard …/N` in the
//! manifest; one shard without), cut as [`super::shard::assign`] cuts them, so "shard k misses
//! runs" is exactly what `run --shard k/N` would compute. Damaged files are the parts that
//! cannot be read and those already moved aside (under `damaged/`, or `.damaged-*` beside the
//! parts in folders written before `damaged/` existed). The report ends with the one
//! command that completes only what is missing: locally `run` on the same folder (it skips what
//! is done), on a cluster `slurm … --only-shards K,…/N --submit` (an array over the shards that
//! miss runs).

use std::collections::{BTreeMap, HashMap};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value as Json;

use super::shard::{self, compact};
use crate::sink::{self, Manifest, SinkError};
use crate::sweep::{Plan, SweepError, SweepFile, expand};

/// Why a folder's status cannot be told.
#[derive(Debug, thiserror::Error)]
pub enum StatusError {
    #[error(transparent)]
    Sink(#[from] SinkError),
    #[error(transparent)]
    Sweep(#[from] SweepError),
    #[error(
        "{dir}: no sweep file recorded (no manifest.json session and no slurm/sweep.toml); pass --sweep FILE"
    )]
    NoSweep { dir: PathBuf },
    #[error("{dir}: parquet: {message}")]
    Read { dir: PathBuf, message: String },
}

/// One shard's counts.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ShardCounts {
    pub planned: usize,
    pub done: usize,
    /// Done runs by status other than `ok`.
    pub failed: usize,
    pub missing: usize,
}

/// The state of a results folder.
#[derive(Debug, Clone)]
pub struct FolderStatus {
    pub dir: PathBuf,
    /// The sweep file the commands name.
    pub sweep_file: PathBuf,
    pub sweep_name: String,
    pub planned: usize,
    /// Done runs by status.
    pub by_status: BTreeMap<String, usize>,
    pub missing: usize,
    /// Rows whose run_id the plan does not hold (another sweep added with --resume).
    pub foreign_rows: usize,
    /// Rows beyond the first of a run_id (0 unless something went wrong).
    pub duplicate_rows: usize,
    /// Shard count of the folder's sessions (1 without shards).
    pub shards: usize,
    pub per_shard: Vec<ShardCounts>,
    /// Unreadable parts still in place, and files already moved aside.
    pub unreadable: Vec<sink::Damaged>,
    pub moved_aside: Vec<PathBuf>,
    /// (id, started, finished, shard, written, interrupted) of each session.
    pub sessions: Vec<SessionInfo>,
    /// Whether DIR/slurm/ holds a Slurm submission.
    pub slurm: bool,
}

#[derive(Debug, Clone)]
pub struct SessionInfo {
    pub started: String,
    pub finished: Option<String>,
    pub shard: Option<String>,
    pub written: u64,
    pub interrupted: bool,
    pub host: String,
}

impl FolderStatus {
    pub fn done(&self) -> usize {
        self.by_status.values().sum()
    }

    /// Shards with at least one missing run.
    pub fn missing_shards(&self) -> Vec<usize> {
        self.per_shard
            .iter()
            .enumerate()
            .filter(|(_, c)| c.missing > 0)
            .map(|(k, _)| k)
            .collect()
    }

    /// The command that completes only what is missing on this machine.
    pub fn local_command(&self) -> String {
        format!(
            "contact-sweep run {} --out {}",
            quote(&self.sweep_file),
            quote(&self.dir)
        )
    }

    /// The Slurm submission of an array over the shards that miss runs.
    pub fn slurm_command(&self) -> String {
        format!(
            "contact-sweep slurm {} --out {} --only-shards {}/{} --submit",
            quote(&self.sweep_file),
            quote(&self.dir),
            compact(&self.missing_shards()),
            self.shards
        )
    }
}

fn quote(p: &Path) -> String {
    let s = p.display().to_string();
    if s.chars()
        .all(|c| c.is_ascii_alphanumeric() || "/._-+".contains(c))
    {
        s
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// The sweep file to plan from: `--sweep`, else the text of the manifest's latest session —
/// named by the file it was read from if that still holds the same text, else by
/// `DIR/slurm/sweep.toml` (a Slurm submission's frozen copy), else frozen now into
/// `DIR/sweep.toml` so that the printed commands work.
fn sweep_of(
    dir: &Path,
    given: Option<&Path>,
    manifest: Option<&Json>,
) -> Result<SweepFile, StatusError> {
    if let Some(p) = given {
        return Ok(SweepFile::load(p)?);
    }
    let latest = manifest.and_then(|m| {
        m["sessions"].as_array().and_then(|s| {
            s.iter().rev().find_map(|x| {
                Some((
                    x["sweep_text"].as_str()?.to_string(),
                    x["sweep_file"].as_str().map(PathBuf::from),
                    // `--set key=value` applied on top of the text (issue 11)
                    x["overrides"]
                        .as_array()
                        .map(|a| {
                            a.iter()
                                .filter_map(|v| v.as_str().map(String::from))
                                .collect::<Vec<_>>()
                        })
                        .unwrap_or_default(),
                ))
            })
        })
    });
    let frozen = dir.join("slurm/sweep.toml");
    let Some((text, file, sets)) = latest else {
        if frozen.exists() {
            return Ok(SweepFile::load(&frozen)?);
        }
        return Err(StatusError::NoSweep {
            dir: dir.to_path_buf(),
        });
    };
    let same = |p: &Path| std::fs::read_to_string(p).is_ok_and(|t| t == text);
    let path = match file {
        Some(f) if same(&f) => f,
        _ if same(&frozen) => frozen,
        _ => {
            let copy = dir.join("sweep.toml");
            if !same(&copy) {
                sink::write_atomic(&copy, text.as_bytes())?;
            }
            copy
        }
    };
    Ok(SweepFile::parse_with(&path, &text, &sets)?)
}

/// Tell the state of DIR.
pub fn status(dir: &Path, sweep: Option<&Path>) -> Result<FolderStatus, StatusError> {
    let (manifest, manifest_damaged) = match Manifest::read(dir) {
        Ok(m) => (m, None),
        Err(SinkError::Manifest { path, .. }) => (None, Some(path)),
        Err(e) => return Err(e.into()),
    };
    let sweep = sweep_of(dir, sweep, manifest.as_ref())?;
    let plan: Plan = expand(&sweep)?;

    let sessions: Vec<SessionInfo> = manifest
        .as_ref()
        .and_then(|m| m["sessions"].as_array().cloned())
        .unwrap_or_default()
        .iter()
        .map(|s| SessionInfo {
            started: s["started"].as_str().unwrap_or("?").to_string(),
            finished: s["finished"].as_str().map(String::from),
            shard: s["shard"].as_str().map(String::from),
            written: s["runs_written"].as_u64().unwrap_or(0),
            interrupted: s["interrupted"].as_bool().unwrap_or(false),
            host: s["machine"]["hostname"].as_str().unwrap_or("").to_string(),
        })
        .collect();
    // The shard count of the latest sharded session (a folder is normally cut one way).
    let shards = sessions
        .iter()
        .rev()
        .find_map(|s| s.shard.as_deref()?.split_once('/')?.1.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or(1);

    let df = sink::read_runs(dir)?;
    let mut rows: HashMap<String, String> = HashMap::new();
    let (mut foreign_rows, mut duplicate_rows) = (0, 0);
    if df.height() > 0 {
        let read = |e: polars::prelude::PolarsError| StatusError::Read {
            dir: dir.join("runs"),
            message: e.to_string(),
        };
        let ids = df
            .column("run_id")
            .and_then(|c| c.str().cloned())
            .map_err(read)?;
        let status = df.column("status").and_then(|c| c.str().cloned()).ok();
        let planned: HashMap<&str, ()> =
            plan.runs.iter().map(|r| (r.run_id.as_str(), ())).collect();
        for (i, id) in ids.iter().enumerate() {
            let Some(id) = id else { continue };
            if !planned.contains_key(id) {
                foreign_rows += 1;
                continue;
            }
            let st = status
                .as_ref()
                .and_then(|s| s.get(i))
                .unwrap_or("ok")
                .to_string();
            if rows.insert(id.to_string(), st).is_some() {
                duplicate_rows += 1;
            }
        }
    }
    let assignment = shard::assign(&plan.runs, shards);
    let mut per_shard = vec![ShardCounts::default(); shards];
    let mut by_status: BTreeMap<String, usize> = BTreeMap::new();
    let mut missing = 0;
    for (r, &s) in plan.runs.iter().zip(&assignment) {
        let c = &mut per_shard[s];
        c.planned += 1;
        match rows.get(&r.run_id) {
            Some(st) => {
                c.done += 1;
                if st != "ok" {
                    c.failed += 1;
                }
                *by_status.entry(st.clone()).or_default() += 1;
            }
            None => {
                c.missing += 1;
                missing += 1;
            }
        }
    }
    // Moved aside: everything under damaged/, and the dot-files of the older layout.
    let mut moved_aside = Vec::new();
    let mut pending = vec![dir.join("damaged")];
    while let Some(d) = pending.pop() {
        if let Ok(entries) = std::fs::read_dir(&d) {
            for e in entries.flatten() {
                let p = e.path();
                if p.is_dir() {
                    pending.push(p);
                } else {
                    moved_aside.push(p);
                }
            }
        }
    }
    for sub in ["runs", "series", "references"] {
        moved_aside.extend(sink::legacy_damaged(&dir.join(sub))?);
    }
    let aside = dir.join(".damaged-manifest.json");
    if aside.exists() {
        moved_aside.push(aside);
    }
    moved_aside.sort();
    let mut unreadable = sink::unreadable_parts(dir)?;
    if let Some(path) = manifest_damaged {
        unreadable.push(sink::Damaged {
            path,
            reason: "not valid JSON".into(),
            moved_to: None,
        });
    }
    Ok(FolderStatus {
        dir: dir.to_path_buf(),
        sweep_file: sweep.path.clone(),
        sweep_name: plan.sweep.name.clone(),
        planned: plan.runs.len(),
        by_status,
        missing,
        foreign_rows,
        duplicate_rows,
        shards,
        per_shard,
        unreadable,
        moved_aside,
        sessions,
        slurm: dir.join("slurm/array.sh").exists(),
    })
}

/// Most sessions listed one by one (a large array has thousands: the rest is counted).
const SESSIONS_LISTED: usize = 20;

impl std::fmt::Display for FolderStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{}: sweep `{}` ({}), {} runs planned",
            self.dir.display(),
            self.sweep_name,
            self.sweep_file.display(),
            self.planned
        );
        let statuses = self
            .by_status
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ");
        let failed: usize = self
            .by_status
            .iter()
            .filter(|(k, _)| *k != "ok")
            .map(|(_, v)| v)
            .sum();
        let _ = writeln!(
            s,
            "done {} ({}), failed {failed}, missing {}",
            self.done(),
            if statuses.is_empty() {
                "none".into()
            } else {
                statuses
            },
            self.missing
        );
        if self.foreign_rows > 0 {
            let _ = writeln!(
                s,
                "{} rows of runs not in this plan (another sweep)",
                self.foreign_rows
            );
        }
        if self.duplicate_rows > 0 {
            let _ = writeln!(
                s,
                "{} duplicate rows (summaries keep the first)",
                self.duplicate_rows
            );
        }
        let _ = writeln!(s, "\nshard  runs  done  failed  missing");
        for (k, c) in self.per_shard.iter().enumerate() {
            let _ = writeln!(
                s,
                "{:<5}  {:>4}  {:>4}  {:>6}  {:>7}",
                format!("{k}/{}", self.shards),
                c.planned,
                c.done,
                c.failed,
                c.missing
            );
        }
        if self.unreadable.is_empty() && self.moved_aside.is_empty() {
            let _ = writeln!(s, "\ndamaged files: none");
        } else {
            let _ = writeln!(s, "\ndamaged files:");
            for d in &self.unreadable {
                let _ = writeln!(s, "  {}", d.warning());
            }
            for p in &self.moved_aside {
                let _ = writeln!(
                    s,
                    "  {} (moved aside; its runs count as missing)",
                    p.display()
                );
            }
        }
        let unfinished = self
            .sessions
            .iter()
            .filter(|x| x.finished.is_none())
            .count();
        let interrupted = self.sessions.iter().filter(|x| x.interrupted).count();
        let _ = writeln!(
            s,
            "\nsessions: {} ({} finished, {interrupted} of them interrupted; {unfinished} without an end: killed, or still running)",
            self.sessions.len(),
            self.sessions.len() - unfinished
        );
        let listed: Vec<&SessionInfo> = if self.sessions.len() <= SESSIONS_LISTED {
            self.sessions.iter().collect()
        } else {
            // The unfinished ones first: they are what a user looks for.
            let mut v: Vec<&SessionInfo> = self
                .sessions
                .iter()
                .filter(|x| x.finished.is_none())
                .collect();
            v.truncate(SESSIONS_LISTED);
            v
        };
        for x in &listed {
            let _ = writeln!(
                s,
                "  {} → {}  shard {}  {} runs written{}{}",
                x.started,
                x.finished.as_deref().unwrap_or("(no end)"),
                x.shard.as_deref().unwrap_or("—"),
                x.written,
                if x.interrupted { ", interrupted" } else { "" },
                if x.host.is_empty() {
                    String::new()
                } else {
                    format!(" on {}", x.host)
                }
            );
        }
        if listed.len() < self.sessions.len() {
            let _ = writeln!(s, "  … {} more", self.sessions.len() - listed.len());
        }
        if self.missing == 0 {
            let _ = writeln!(s, "\ncomplete: nothing to resubmit");
        } else {
            let _ = writeln!(
                s,
                "\nto complete the {} missing runs (only those; done runs are skipped):",
                self.missing
            );
            let _ = writeln!(s, "  here:  {}", self.local_command());
            let _ = writeln!(
                s,
                "  Slurm: {}   ({} task(s): the shards {} of {})",
                self.slurm_command(),
                self.missing_shards().len(),
                compact(&self.missing_shards()),
                self.shards
            );
        }
        f.write_str(&s)
    }
}
