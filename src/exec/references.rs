//! Reference runs (contract §1.2, §7 `reference = {…}`): each distinct reference of a plan is
//! computed once per output folder and stored in `DIR/references/<run_id>.ref`, then reused on
//! resume, by every shard, and by every run measured against it.
//!
//! Shards that need the same reference at the same time do not compute it twice: the first
//! takes an exclusive lock on `DIR/references/<run_id>.lock`, the others wait for it and read
//! the stored file. A stored file that cannot be read is reported and computed again.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use crate::run::reference::ReferenceData;
use crate::run::{RunContext, RunOptions, Status, simulate_with};
use crate::sweep::{Plan, RunSpec};

/// Why a reference could not be provided.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceRunError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// The stored references of the runs in `runs`, computing the missing ones. A reference run
/// that fails is reported on stderr and left out: its runs go on without errors against it.
pub fn ensure(
    dir: &Path,
    plan: &Plan,
    runs: &[&RunSpec],
    opts: &RunOptions,
) -> Result<HashMap<String, Arc<ReferenceData>>, ReferenceRunError> {
    let mut out = HashMap::new();
    let needed: Vec<&str> = {
        let mut v: Vec<&str> = runs.iter().filter_map(|r| r.reference.as_deref()).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    if needed.is_empty() {
        return Ok(out);
    }
    let folder = dir.join("references");
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ReferenceRunError::Io { path, source }
    };
    std::fs::create_dir_all(&folder).map_err(io(&folder))?;
    for rp in plan
        .references
        .iter()
        .filter(|p| needed.contains(&p.spec.run_id.as_str()))
    {
        let id = &rp.spec.run_id;
        let path = folder.join(format!("{id}.ref"));
        let lock_path = folder.join(format!("{id}.lock"));
        // Held until the reference is stored: a concurrent shard waits, then reads it.
        let _lock = crate::sink::lock_exclusive(&lock_path).map_err(io(&lock_path))?;
        if path.exists() {
            match ReferenceData::load(&path) {
                Ok(d) if d.space_stride == rp.space_stride && d.time_stride == rp.time_stride => {
                    eprintln!("reference {id} ({}): stored, reused", rp.spec.label);
                    out.insert(id.clone(), Arc::new(d));
                    continue;
                }
                Ok(_) => eprintln!(
                    "reference {id}: stored on another lattice than this plan needs; computing it again"
                ),
                Err(e) => eprintln!("warning: {e}; computing it again"),
            }
        }
        eprintln!(
            "reference {id} ({}): computing ({:.2e} steps × unknowns)…",
            rp.spec.label,
            rp.spec.config.work() as f64
        );
        let started = Instant::now();
        let ctx = RunContext {
            reference: None,
            record_reference: Some((rp.space_stride, rp.time_stride)),
        };
        // A reference is no ordinary run: `--run-timeout` does not apply to it (an interrupt
        // does).
        let run_opts = RunOptions {
            series_every: 0,
            timeout: None,
            ..*opts
        };
        let outcome = simulate_with(&rp.spec.config, &run_opts, &ctx);
        match (outcome.status, outcome.reference) {
            (Status::Ok, Some(data)) => {
                data.save(&path).map_err(|e| ReferenceRunError::Io {
                    path: path.clone(),
                    source: std::io::Error::other(e.to_string()),
                })?;
                eprintln!(
                    "reference {id}: done in {:.1} s, stored in {}",
                    started.elapsed().as_secs_f64(),
                    path.display()
                );
                out.insert(id.clone(), Arc::new(data));
            }
            (status, _) => eprintln!(
                "warning: reference {id} ({}) ended {}: {}; its runs have no error columns",
                rp.spec.label,
                status.as_str(),
                outcome.message.unwrap_or_default()
            ),
        }
    }
    Ok(out)
}
