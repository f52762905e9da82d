//! Crash-safe Parquet output (contract §8).
//!
//! Layout of DIR:
//! - `runs/part-*.parquet` — rows of [`RunRecord`], one file per batch;
//! - `series/part-*.parquet` — the time series of the same batch, same file name;
//! - `manifest.json` — the sweep file's text, tool version, git commit, machine, sessions;
//! - `.tmp/` — parts being written (never a complete part);
//! - `damaged/runs/`, `damaged/series/` — parts found unreadable, moved out of the way.
//!
//! `runs/` and `series/` hold complete parts only, at every moment, so every reader's glob
//! (`runs/*.parquet`, a directory read) sees committed data only: current polars expands
//! `*.parquet` to dot-files too, so a temporary or a damaged part must not even sit beside the
//! parts under another dot-name. A batch is encoded, by the thread
//! whose run filled it (a worker), into `.tmp/NAME.series` and `.tmp/NAME.runs`; one committer
//! thread then commits it by an atomic sequence: fsync `.tmp/NAME.series`, rename it to
//! `series/NAME`; then the same for `runs/NAME`; then fsync the folders (`.tmp/` is on the
//! same file system, so the rename is atomic). The runs
//! part is the commit record: a run counts as done iff its row is in a runs part. After a
//! SIGKILL at any moment the folder holds only complete Parquet files plus perhaps temporaries
//! in `.tmp/` and a series part whose runs part never landed; [`Sink::open`] removes both, so
//! `--resume` loses only the runs in flight and never duplicates a row. Batches are flushed
//! every `batch_runs` runs or `batch_seconds`, whichever comes first, so a long sweep never
//! holds much unsaved work. The parts' encoding is [`parquet`]'s. It runs on the workers, not
//! on one writer thread, so the output's CPU grows with them: the serial part left is the
//! committer's, a few system calls a batch ([`SinkStats::commit_cpu_seconds`]).
//!
//! Several sessions may write into one DIR at once (the shards of a job array): each holds a
//! shared lock on `DIR/.lock` while it writes, and the clean-up above takes the exclusive lock
//! — so it runs only when no other session is writing, and never removes a temporary or a
//! series part that another session is about to commit.
//!
//! Damage from outside (a part truncated or overwritten by hand, a disk error): a runs part that
//! cannot be read whole, or a series part whose footer cannot be read, is moved with its
//! partner to `damaged/runs/NAME` and `damaged/series/NAME` ([`quarantine`], called by
//! [`Sink::open`]); its runs are then missing and a resume computes them again, so every run is
//! present exactly once. Renaming is safe while other shards write (their parts are complete
//! files, never rewritten). Folders written before this layout kept temporaries and damaged
//! parts as dot-files beside the parts (`runs/.tmp-NAME`, `runs/.damaged-NAME`): the clean-up
//! removes the former and moves the latter to `damaged/`, and runs parts with another column
//! set than the current [`RunRecord`] are rewritten with it ([`conform_runs_parts`]: a glob
//! reader takes the first part's columns as the folder's). Readers ([`read_runs`], the
//! summaries) skip unreadable parts, with the same warning ([`Damaged::warning`]).

use std::collections::HashSet;
use std::fs::{self, File};
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, mpsc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use polars::prelude::*;

pub mod manifest;
pub mod parquet;

pub use manifest::{Manifest, ManifestState};

use crate::run::{RunRecord, RunResult, Series};

/// Failures of the output folder.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    #[error("{path}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: parquet")]
    Parquet { path: PathBuf, source: PolarsError },
    #[error("{path}: parquet")]
    Format {
        path: PathBuf,
        source: ::parquet::errors::ParquetError,
    },
    #[error(
        "{path}: holds results of sweep `{found}`, not `{expected}`; choose another --out, or pass --resume to add this sweep's runs to it"
    )]
    ForeignSweep {
        path: PathBuf,
        found: String,
        expected: String,
    },
    #[error(
        "{path}: holds {count} row(s) of this sweep's runs computed before a change of definition moved their numbers (the body load of contract §1.3 and exact quadrature on curved cells, issue 34; e.g. run {example}, now {now}); resuming would put both numbers in one folder's tables — run into a new --out"
    )]
    Superseded {
        path: PathBuf,
        count: usize,
        example: String,
        now: String,
    },
    #[error("{path}: manifest is not valid JSON: {message}")]
    Manifest { path: PathBuf, message: String },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> SinkError + '_ {
    move |source| SinkError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Where a file being written atomically in place of `dst` lives until it is complete: beside
/// it, dot-named and with a suffix no reader's glob matches (`*.parquet`, `*.csv`).
fn temp_beside(dst: &Path) -> PathBuf {
    let name = dst.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    dst.with_file_name(format!(".tmp-{name}.partial"))
}

/// Whether a file must survive a power cut once written. Results (runs and series parts, the
/// manifest) are synced before they count as committed; what is derived from them (summary
/// tables, the report) is only renamed into place — never seen half-written, and rebuilt by
/// `contact-sweep summarize` if a power cut took it. fsync costs 5–10 ms a file here, and the
/// summary writes ~20 files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Durability {
    Synced,
    Derived,
}

/// Write `bytes` produced by `encode` to `tmp`, then rename it to `dst`; returns the size.
fn write_then_rename(
    tmp: &Path,
    dst: &Path,
    durability: Durability,
    encode: impl FnOnce(&mut BufWriter<&File>) -> Result<(), SinkError>,
) -> Result<u64, SinkError> {
    let bytes = write_file(tmp, durability, encode)?;
    fs::rename(tmp, dst).map_err(io(dst))?;
    Ok(bytes)
}

/// Write the bytes produced by `encode` to `path` (synced if `durability` says so); returns
/// the size.
fn write_file(
    path: &Path,
    durability: Durability,
    encode: impl FnOnce(&mut BufWriter<&File>) -> Result<(), SinkError>,
) -> Result<u64, SinkError> {
    let file = File::create(path).map_err(io(path))?;
    // Buffered: encoders write page by page (≈ 40 000 write calls for the summary's tables
    // and series parts of one sweep without the buffer).
    let mut buf = BufWriter::with_capacity(1 << 20, &file);
    encode(&mut buf)?;
    buf.flush().map_err(io(path))?;
    drop(buf);
    if durability == Durability::Synced {
        file.sync_all().map_err(io(path))?;
    }
    file.metadata().map(|m| m.len()).map_err(io(path))
}

/// Write a DataFrame to `dir/name` atomically and synced (see [`write_frame_atomic`]).
pub fn write_parquet_atomic(dir: &Path, name: &str, df: &mut DataFrame) -> Result<u64, SinkError> {
    write_frame_atomic(dir, name, df, Durability::Synced)
}

/// Write a DataFrame (a summary table) to `dir/name` atomically with polars' own writer
/// (zstd at its default level, statistics); returns the file's size in bytes.
pub fn write_frame_atomic(
    dir: &Path,
    name: &str,
    df: &mut DataFrame,
    durability: Durability,
) -> Result<u64, SinkError> {
    let dst = dir.join(name);
    let tmp = temp_beside(&dst);
    write_then_rename(&tmp, &dst, durability, |out| {
        ParquetWriter::new(out)
            .with_compression(ParquetCompression::Zstd(None))
            .with_statistics(StatisticsOptions::default())
            .finish(df)
            .map(|_| ())
            .map_err(|source| SinkError::Parquet {
                path: tmp.clone(),
                source,
            })
    })
}

/// Write a sink part: encoded into `tmp_dir/NAME.SUFFIX` (outside the parts' folder), synced,
/// renamed to `dir/NAME`. Returns the part's size in bytes.
fn write_part_atomic(
    tmp_dir: &Path,
    dir: &Path,
    name: &str,
    suffix: &str,
    encode: impl FnOnce(&mut BufWriter<&File>) -> Result<(), ::parquet::errors::ParquetError>,
) -> Result<u64, SinkError> {
    let dst = dir.join(name);
    let tmp = tmp_dir.join(format!("{name}.{suffix}"));
    write_then_rename(&tmp, &dst, Durability::Synced, |out| {
        encode(out).map_err(|source| SinkError::Format {
            path: tmp.clone(),
            source,
        })
    })
}

fn sync_dir(dir: &Path) -> Result<(), SinkError> {
    File::open(dir).and_then(|f| f.sync_all()).map_err(io(dir))
}

/// Open (creating it) and lock `path` exclusively, waiting for other holders: a lock file
/// that serialises processes sharing an output folder. Released when the file drops.
pub fn lock_exclusive(path: &Path) -> std::io::Result<File> {
    let f = File::options()
        .create(true)
        .truncate(false)
        .write(true)
        .open(path)?;
    f.lock()?;
    Ok(f)
}

/// Write bytes atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), SinkError> {
    write_text_atomic(path, bytes, Durability::Synced)
}

/// Write a derived file (a summary table, the report): atomically, without fsync
/// (see [`Durability`]).
pub fn write_derived(path: &Path, bytes: &[u8]) -> Result<(), SinkError> {
    write_text_atomic(path, bytes, Durability::Derived)
}

fn write_text_atomic(path: &Path, bytes: &[u8], durability: Durability) -> Result<(), SinkError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let tmp = temp_beside(path);
    let mut f = File::create(&tmp).map_err(io(&tmp))?;
    f.write_all(bytes).map_err(io(&tmp))?;
    if durability == Durability::Synced {
        f.sync_all().map_err(io(&tmp))?;
    }
    drop(f);
    fs::rename(&tmp, path).map_err(io(path))?;
    match durability {
        Durability::Synced => sync_dir(dir),
        Durability::Derived => Ok(()),
    }
}

/// A part file that cannot be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Damaged {
    pub path: PathBuf,
    pub reason: String,
    /// Where it was moved (None: left in place by a reader).
    pub moved_to: Option<PathBuf>,
}

impl Damaged {
    /// One line for the user: the file, why, and what was done about it.
    pub fn warning(&self) -> String {
        let what = match &self.moved_to {
            Some(to) => format!(
                "moved aside to {}; its runs are computed again",
                to.display()
            ),
            None => "skipped (`contact-sweep run` on this folder moves it aside and computes its runs again)".into(),
        };
        format!(
            "{} cannot be read ({}): {what}",
            self.path.display(),
            self.reason
        )
    }
}

/// Why a part cannot be read, if it cannot: a runs part is read whole (it is small, and a
/// damaged page fails only when decoded); of a series part, which may be large, the footer.
pub fn part_problem(path: &Path, whole: bool) -> Option<String> {
    parquet::problem(path, whole)
}

/// The folder damaged parts are moved to: `DIR/damaged/runs` or `DIR/damaged/series`, out of
/// every reader's glob.
pub fn damaged_dir(dir: &Path, sub: &str) -> PathBuf {
    dir.join("damaged").join(sub)
}

/// Unreadable parts of DIR, without touching them: runs parts read whole, series parts by
/// their footer.
pub fn unreadable_parts(dir: &Path) -> Result<Vec<Damaged>, SinkError> {
    unreadable_parts_except(dir, &HashSet::new())
}

/// [`unreadable_parts`], taking the runs parts named in `read` as readable: a reader that has
/// just read them whole (the summary's loader) need not have them read a second time.
pub fn unreadable_parts_except(
    dir: &Path,
    read: &HashSet<String>,
) -> Result<Vec<Damaged>, SinkError> {
    let mut out = Vec::new();
    for (sub, whole) in [("runs", true), ("series", false)] {
        for part in parquet_parts(&dir.join(sub))? {
            let name = part.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if whole && read.contains(name) {
                continue;
            }
            if let Some(reason) = part_problem(&part, whole) {
                out.push(Damaged {
                    path: part,
                    reason,
                    moved_to: None,
                });
            }
        }
    }
    Ok(out)
}

/// Move `from` to `to` (creating `to`'s folder); a `from` already gone (another session moved
/// it first, or a batch without that partner) is not an error.
fn move_aside(from: &Path, to: &Path) -> Result<bool, SinkError> {
    if let Some(parent) = to.parent() {
        fs::create_dir_all(parent).map_err(io(parent))?;
    }
    match fs::rename(from, to) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(false),
        Err(e) => Err(io(from)(e)),
    }
}

/// Move every unreadable part of DIR to `DIR/damaged/`, with its partner in the other folder
/// (a batch is a runs part and a series part of one name: a batch with either damaged is
/// computed again).
pub fn quarantine(dir: &Path) -> Result<Vec<Damaged>, SinkError> {
    let mut out = Vec::new();
    for mut d in unreadable_parts(dir)? {
        let name = d.path.file_name().expect("a part file").to_owned();
        for sub in ["runs", "series"] {
            let p = dir.join(sub).join(&name);
            let to = damaged_dir(dir, sub).join(&name);
            move_aside(&p, &to)?;
            if p == d.path {
                d.moved_to = Some(to);
            }
        }
        if !out
            .iter()
            .any(|o: &Damaged| o.path.file_name() == d.path.file_name())
        {
            out.push(d);
        }
    }
    Ok(out)
}

/// Move the damaged parts a folder written before `damaged/` existed keeps beside its parts
/// (`runs/.damaged-NAME`, `series/.damaged-NAME`) to `damaged/`: polars' glob reads them.
/// Returns where each went.
pub fn migrate_legacy_damaged(dir: &Path) -> Result<Vec<PathBuf>, SinkError> {
    let mut moved = Vec::new();
    for sub in ["runs", "series"] {
        for p in legacy_damaged(&dir.join(sub))? {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let to = damaged_dir(dir, sub).join(name.trim_start_matches(".damaged-"));
            if move_aside(&p, &to)? {
                moved.push(to);
            }
        }
    }
    Ok(moved)
}

/// `.damaged-*` files of a folder (the layout before `damaged/`).
pub fn legacy_damaged(folder: &Path) -> Result<Vec<PathBuf>, SinkError> {
    let mut out = Vec::new();
    if !folder.exists() {
        return Ok(out);
    }
    for entry in fs::read_dir(folder).map_err(io(folder))? {
        let p = entry.map_err(io(folder))?.path();
        if p.file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.starts_with(".damaged-"))
        {
            out.push(p);
        }
    }
    out.sort();
    Ok(out)
}

/// Give every readable runs part of `runs_dir` the columns of the current [`RunRecord`]
/// (written into `tmp_dir`, synced, renamed over the part: a reader sees the old part or the
/// new one, never a mix; a crash leaves some parts converted and the next session converts the
/// rest). Returns the parts rewritten. Unreadable parts are left to [`quarantine`]. Only
/// called under the exclusive lock, before any session writes.
pub fn conform_runs_parts(tmp_dir: &Path, runs_dir: &Path) -> Result<Vec<PathBuf>, SinkError> {
    let current = parquet::record_batch(RunRecord::to_columns(&[]))
        .map_err(|source| SinkError::Format {
            path: runs_dir.to_path_buf(),
            source,
        })?
        .schema();
    conform_parts(
        tmp_dir,
        runs_dir,
        &current,
        ::parquet::basic::Compression::UNCOMPRESSED,
    )
}

/// [`conform_runs_parts`] for the series parts: the columns of [`parquet::series_schema`]
/// (a folder resumed by a version with new series columns — issue 32's friction series —
/// must hold one schema there too, or polars' glob refuses the folder's series).
pub fn conform_series_parts(tmp_dir: &Path, series_dir: &Path) -> Result<Vec<PathBuf>, SinkError> {
    conform_parts(
        tmp_dir,
        series_dir,
        &parquet::series_schema(),
        parquet::codec(),
    )
}

fn conform_parts(
    tmp_dir: &Path,
    runs_dir: &Path,
    current: &arrow_schema::Schema,
    compression: ::parquet::basic::Compression,
) -> Result<Vec<PathBuf>, SinkError> {
    let mut rewritten = Vec::new();
    for part in parquet_parts(runs_dir)? {
        match parquet::part_is_current(&part, current) {
            Ok(true) | Err(_) => continue,
            Ok(false) => {}
        }
        let name = part
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("part")
            .to_string();
        match write_part_atomic(tmp_dir, runs_dir, &name, "conform", |out| {
            parquet::conform_part(&part, current, compression, out)
        }) {
            Ok(_) => rewritten.push(part),
            // A page that cannot be decoded: the part stays as it is, for `quarantine`.
            Err(SinkError::Format { .. }) => {
                let _ = fs::remove_file(tmp_dir.join(format!("{name}.conform")));
            }
            Err(e) => return Err(e),
        }
    }
    if !rewritten.is_empty() {
        sync_dir(runs_dir)?;
    }
    Ok(rewritten)
}

/// Read the run_id column of every committed runs part.
pub fn committed_run_ids(runs_dir: &Path) -> Result<HashSet<String>, SinkError> {
    let mut ids = HashSet::new();
    for part in parquet_parts(runs_dir)? {
        let col = parquet::run_ids(&part).map_err(|source| SinkError::Format {
            path: part.clone(),
            source,
        })?;
        ids.extend(col.into_iter().flatten());
    }
    Ok(ids)
}

/// Committed `*.parquet` files of a folder (dot-files excluded), sorted.
pub fn parquet_parts(dir: &Path) -> Result<Vec<PathBuf>, SinkError> {
    let mut parts = Vec::new();
    if !dir.exists() {
        return Ok(parts);
    }
    for entry in fs::read_dir(dir).map_err(io(dir))? {
        let p = entry.map_err(io(dir))?.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if !name.starts_with('.') && name.ends_with(".parquet") {
            parts.push(p);
        }
    }
    parts.sort();
    Ok(parts)
}

/// Batching policy.
#[derive(Debug, Clone, Copy)]
pub struct BatchPolicy {
    pub runs: usize,
    pub seconds: f64,
}

impl Default for BatchPolicy {
    fn default() -> Self {
        Self {
            runs: 16,
            seconds: 2.0,
        }
    }
}

/// What the session has committed so far.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SinkStats {
    /// Runs committed (rows in runs parts).
    pub written: usize,
    /// Time-series rows (stored steps) committed.
    pub series_rows: u64,
    /// Bytes of the committed series parts.
    pub series_bytes: u64,
    /// Σ over committed runs of median wall time × repeats: the runs' own time.
    pub run_seconds: f64,
    /// Wall time spent encoding the committed batches into `.tmp/`, summed over the threads
    /// that encoded them (the workers, and the thread calling [`Sink::flush`] for the last).
    pub encode_seconds: f64,
    /// CPU time of that encoding, summed over those threads (None where the platform has no
    /// per-thread clock). It runs where the runs run, so it grows with the workers.
    pub encode_cpu_seconds: Option<f64>,
    /// Wall time the committer thread spent committing (fsync, rename, folder sync).
    pub commit_seconds: f64,
    /// CPU time of the committer thread since it started (None without a per-thread clock).
    /// The one serial part of the output: N workers cannot go faster than
    /// (runs CPU + encoding CPU) / committer CPU times one worker (Amdahl).
    pub commit_cpu_seconds: Option<f64>,
}

/// CPU time consumed so far by the calling thread.
pub fn thread_cpu_seconds() -> Option<f64> {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant of the platform.
        let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
        (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The batch being filled, shared by every thread that pushes results.
struct Pending {
    rows: Vec<RunRecord>,
    series: Vec<(String, Series)>,
    last_flush: Instant,
    seq: usize,
}

/// A batch taken out of [`Pending`], named, to be encoded by the thread that took it.
struct Batch {
    name: String,
    rows: Vec<RunRecord>,
    series: Vec<(String, Series)>,
}

impl Pending {
    /// Take the batch (None if empty) and start the clock of the next one.
    fn take(&mut self, tag: &str) -> Option<Batch> {
        self.last_flush = Instant::now();
        if self.rows.is_empty() {
            return None;
        }
        let name = format!("part-{tag}-{:05}.parquet", self.seq);
        self.seq += 1;
        Some(Batch {
            name,
            rows: std::mem::take(&mut self.rows),
            series: std::mem::take(&mut self.series),
        })
    }
}

/// A batch encoded into `.tmp/NAME.series` and `.tmp/NAME.runs` (complete, not yet synced),
/// with what its commit adds to [`SinkStats`].
struct Encoded {
    name: String,
    runs: usize,
    run_seconds: f64,
    series_rows: u64,
    series_bytes: u64,
    encode_seconds: f64,
    encode_cpu_seconds: Option<f64>,
}

/// What the committer thread is handed.
enum Job {
    Commit(Encoded),
    /// Answered once every job sent before has been handled.
    Sync(mpsc::Sender<()>),
}

/// State shared between the pushing threads and the committer.
#[derive(Default)]
struct Shared {
    stats: SinkStats,
    /// The first failure, until reported (taken by the next [`Sink::push`] or [`Sink::flush`]).
    error: Option<SinkError>,
    /// Set by the first failure: nothing is encoded or committed after it.
    failed: bool,
}

impl Shared {
    fn fail(&mut self, e: SinkError) {
        if !self.failed {
            self.error = Some(e);
            self.failed = true;
        }
    }
}

/// The writer of one session into DIR.
///
/// A full batch is encoded by the thread whose result filled it — a worker of the executor's
/// pool, or the run loop itself with `--threads 1` — into complete files in `DIR/.tmp/`, so
/// the CPU of the output grows with the workers: a single encoding thread capped a sweep at
/// about 7 workers' throughput (issue 35). One committer thread then makes each batch
/// visible in today's atomic order (fsync and rename the series part, then the runs part,
/// then sync both folders); it only waits on the disk, so its CPU — the serial part of the
/// output — is small. Batches are committed in the order they finish encoding; each is
/// independent (its runs part is its commit record). The sink is shared by reference
/// between the workers (`push` takes `&self`). A failure is reported by the next
/// [`Sink::push`] or by [`Sink::flush`]; nothing is encoded or committed after it.
pub struct Sink {
    runs_dir: PathBuf,
    dirs: Arc<PartDirs>,
    pending: Mutex<Pending>,
    policy: BatchPolicy,
    tag: String,
    /// Parts found unreadable when the folder was opened, now moved aside.
    pub damaged: Vec<Damaged>,
    /// Damaged parts of the layout before `damaged/` (dot-files beside the parts), moved to
    /// `damaged/` when the folder was opened: where each went.
    pub legacy_damaged: Vec<PathBuf>,
    /// Runs parts of an older version rewritten with the current columns when the folder was
    /// opened ([`conform_runs_parts`]).
    pub migrated: Vec<PathBuf>,
    /// Series parts rewritten likewise ([`conform_series_parts`]).
    pub migrated_series: Vec<PathBuf>,
    shared_with_others: bool,
    shared: Arc<Mutex<Shared>>,
    jobs: Option<mpsc::Sender<Job>>,
    committer: Option<JoinHandle<()>>,
    /// Shared lock on DIR/.lock, held while this session may write.
    _lock: File,
}

impl Sink {
    /// Prepare DIR: create folders, drop temporaries and uncommitted series parts, and return
    /// the run ids already committed.
    pub fn open(dir: &Path, policy: BatchPolicy) -> Result<(Sink, HashSet<String>), SinkError> {
        let runs_dir = dir.join("runs");
        let series_dir = dir.join("series");
        fs::create_dir_all(&runs_dir).map_err(io(&runs_dir))?;
        fs::create_dir_all(&series_dir).map_err(io(&series_dir))?;
        let lock_path = dir.join(".lock");
        let lock = File::options()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true)
            .open(&lock_path)
            .map_err(io(&lock_path))?;
        let alone = match lock.try_lock() {
            Ok(()) => true,
            Err(fs::TryLockError::WouldBlock) => false,
            Err(fs::TryLockError::Error(e)) => return Err(io(&lock_path)(e)),
        };
        let tmp_dir = dir.join(".tmp");
        let mut migrated = Vec::new();
        let mut migrated_series = Vec::new();
        if alone {
            Self::clean(&tmp_dir, &runs_dir, &series_dir)?;
            fs::create_dir_all(&tmp_dir).map_err(io(&tmp_dir))?;
            migrated = conform_runs_parts(&tmp_dir, &runs_dir)?;
            migrated_series = conform_series_parts(&tmp_dir, &series_dir)?;
            lock.unlock().map_err(io(&lock_path))?;
        }
        fs::create_dir_all(&tmp_dir).map_err(io(&tmp_dir))?;
        lock.lock_shared().map_err(io(&lock_path))?;
        let legacy_damaged = migrate_legacy_damaged(dir)?;
        let damaged = quarantine(dir)?;
        let done = committed_run_ids(&runs_dir)?;
        let stamp = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .unwrap_or_default()
            .as_millis();
        let dirs = Arc::new(PartDirs {
            tmp: tmp_dir,
            runs: runs_dir.clone(),
            series: series_dir,
        });
        let shared = Arc::new(Mutex::new(Shared::default()));
        // Unbounded: a job is a name, the encoded bytes wait in `.tmp/`; the memory of the
        // batches is bounded by the encoding threads themselves (one batch each).
        let (jobs, rx) = mpsc::channel::<Job>();
        let committer = {
            let (dirs, shared) = (Arc::clone(&dirs), Arc::clone(&shared));
            std::thread::Builder::new()
                .name("parquet-committer".into())
                .spawn(move || commit_loop(&dirs, &rx, &shared))
                .map_err(io(dir))?
        };
        Ok((
            Sink {
                runs_dir,
                dirs,
                pending: Mutex::new(Pending {
                    rows: Vec::new(),
                    series: Vec::new(),
                    last_flush: Instant::now(),
                    seq: 0,
                }),
                policy,
                tag: format!("{stamp}-{}", std::process::id()),
                damaged,
                legacy_damaged,
                migrated,
                migrated_series,
                shared_with_others: !alone,
                shared,
                jobs: Some(jobs),
                committer: Some(committer),
                _lock: lock,
            },
            done,
        ))
    }

    /// Remove what a killed session left: temporaries (in `.tmp/`, and the dot-named ones
    /// of the layout before it beside the parts) and series parts whose runs part never
    /// landed. Only called under the exclusive lock.
    fn clean(tmp_dir: &Path, runs_dir: &Path, series_dir: &Path) -> Result<(), SinkError> {
        if tmp_dir.exists() {
            for entry in fs::read_dir(tmp_dir).map_err(io(tmp_dir))? {
                let p = entry.map_err(io(tmp_dir))?.path();
                fs::remove_file(&p).map_err(io(&p))?;
            }
        }
        for d in [runs_dir, series_dir] {
            for entry in fs::read_dir(d).map_err(io(d))? {
                let p = entry.map_err(io(d))?.path();
                if p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(".tmp-"))
                {
                    fs::remove_file(&p).map_err(io(&p))?;
                }
            }
        }
        // A series part without its runs part belongs to a batch that never committed.
        for part in parquet_parts(series_dir)? {
            let name = part.file_name().expect("a file");
            if !runs_dir.join(name).exists() {
                fs::remove_file(&part).map_err(io(&part))?;
            }
        }
        Ok(())
    }

    /// Whether another session was writing into the folder when this one opened it.
    pub fn shared_with_others(&self) -> bool {
        self.shared_with_others
    }

    /// What has been committed so far (batches still encoding or queued are not counted).
    pub fn stats(&self) -> SinkStats {
        self.lock().stats
    }

    /// Runs committed so far.
    pub fn written(&self) -> usize {
        self.stats().written
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Shared> {
        // A poisoned lock means a thread panicked while holding it; its stats are still valid.
        self.shared.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The first failure, if not yet reported (taken: reported once).
    fn take_error(&self) -> Result<(), SinkError> {
        match self.lock().error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Add a finished run; if the batch is now full or old, encode it in the calling thread
    /// and hand it to the committer. Called from any thread (the executor's workers).
    pub fn push(&self, result: RunResult) -> Result<(), SinkError> {
        self.take_error()?;
        let full = {
            let mut p = self.pending.lock().unwrap_or_else(|p| p.into_inner());
            if !result.series.is_empty() {
                p.series.push((result.record.run_id.clone(), result.series));
            }
            p.rows.push(result.record);
            let old = p.last_flush.elapsed() >= Duration::from_secs_f64(self.policy.seconds);
            if p.rows.len() >= self.policy.runs || old {
                p.take(&self.tag)
            } else {
                None
            }
        };
        match full {
            Some(batch) => self.encode_and_send(batch),
            None => Ok(()),
        }
    }

    /// Encode `batch` into `.tmp/` in this thread and queue it for the committer.
    fn encode_and_send(&self, batch: Batch) -> Result<(), SinkError> {
        if self.lock().failed {
            return self.take_error(); // nothing is encoded after a failure
        }
        match encode_batch(&self.dirs, batch) {
            Ok(encoded) => {
                let sent = self
                    .jobs
                    .as_ref()
                    .is_some_and(|tx| tx.send(Job::Commit(encoded)).is_ok());
                if sent { Ok(()) } else { self.stopped() }
            }
            Err(e) => {
                self.lock().fail(e);
                self.take_error()
            }
        }
    }

    /// The committer thread is gone (it panicked): its failure, or one saying so.
    fn stopped(&self) -> Result<(), SinkError> {
        self.take_error()?;
        Err(io(&self.runs_dir)(std::io::Error::other(
            "the Parquet committer thread stopped",
        )))
    }

    /// Encode the pending batch in the calling thread and wait until every batch handed over
    /// is committed.
    pub fn flush(&self) -> Result<(), SinkError> {
        let last = self
            .pending
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .take(&self.tag);
        if let Some(batch) = last {
            self.encode_and_send(batch)?;
        }
        let (ack, done) = mpsc::channel();
        let sent = self
            .jobs
            .as_ref()
            .is_some_and(|tx| tx.send(Job::Sync(ack)).is_ok());
        if !sent || done.recv().is_err() {
            return self.stopped();
        }
        self.take_error()
    }
}

impl Drop for Sink {
    /// Batches already handed over are still committed (each is complete); then the committer
    /// thread ends.
    fn drop(&mut self) {
        drop(self.jobs.take());
        if let Some(w) = self.committer.take() {
            let _ = w.join();
        }
    }
}

/// The committer thread: commit batches in the order they arrive until the sink hangs up.
fn commit_loop(dirs: &PartDirs, jobs: &mpsc::Receiver<Job>, shared: &Mutex<Shared>) {
    let lock = || shared.lock().unwrap_or_else(|p| p.into_inner());
    for job in jobs.iter() {
        let ack = match job {
            Job::Sync(ack) => Some(ack),
            Job::Commit(e) => {
                if lock().failed {
                    // Nothing is committed after a failure; the next session would remove
                    // these temporaries anyway.
                    for suffix in ["series", "runs"] {
                        let _ = fs::remove_file(dirs.tmp.join(format!("{}.{suffix}", e.name)));
                    }
                    continue;
                }
                let start = Instant::now();
                let committed = commit_encoded(dirs, &e.name);
                let mut sh = lock();
                match committed {
                    Ok(()) => {
                        let st = &mut sh.stats;
                        st.written += e.runs;
                        st.series_rows += e.series_rows;
                        st.series_bytes += e.series_bytes;
                        st.run_seconds += e.run_seconds;
                        st.encode_seconds += e.encode_seconds;
                        if let Some(c) = e.encode_cpu_seconds {
                            *st.encode_cpu_seconds.get_or_insert(0.0) += c;
                        }
                        st.commit_seconds += start.elapsed().as_secs_f64();
                    }
                    Err(err) => sh.fail(err),
                }
                None
            }
        };
        // The thread's whole clock, waits on the channel included: the serial part as it is.
        if let Some(c) = thread_cpu_seconds() {
            lock().stats.commit_cpu_seconds = Some(c);
        }
        if let Some(ack) = ack {
            let _ = ack.send(());
        }
    }
}

/// The folders a session writes into.
struct PartDirs {
    /// Parts being written (`DIR/.tmp`): outside the parts' folders, same file system.
    tmp: PathBuf,
    runs: PathBuf,
    series: PathBuf,
}

/// Encode a batch into `.tmp/NAME.series` and `.tmp/NAME.runs` (complete files, not synced:
/// the committer syncs them, so an encoding thread never waits on the disk), measuring the
/// calling thread's CPU.
fn encode_batch(dirs: &PartDirs, batch: Batch) -> Result<Encoded, SinkError> {
    let start = Instant::now();
    let cpu_start = thread_cpu_seconds();
    let Batch { name, rows, series } = batch;
    let series_rows: u64 = series.iter().map(|(_, s)| s.len() as u64).sum();
    let series_tmp = dirs.tmp.join(format!("{name}.series"));
    let series_bytes = encode_to_file(&series_tmp, |out| parquet::write_series(out, series))?;
    let runs_tmp = dirs.tmp.join(format!("{name}.runs"));
    encode_to_file(&runs_tmp, |out| {
        parquet::write_runs(out, &parquet::record_batch(RunRecord::to_columns(&rows))?)
    })?;
    let encode_cpu_seconds = match (cpu_start, thread_cpu_seconds()) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    Ok(Encoded {
        runs: rows.len(),
        run_seconds: rows.iter().map(|r| r.wall_time_s * r.repeats as f64).sum(),
        name,
        series_rows,
        series_bytes,
        encode_seconds: start.elapsed().as_secs_f64(),
        encode_cpu_seconds,
    })
}

/// Most bytes an encoding thread keeps of its part buffer between batches: a part of the
/// overhead sweep is ≈ 1 MB (24.3 MB in 25 parts); a larger one is written from a buffer
/// that is then freed.
const KEPT_PART_BUFFER: usize = 8 << 20;

thread_local! {
    /// The part buffer of an encoding thread, kept from batch to batch: a fresh buffer per part
    /// (the 1 MB `BufWriter` of [`write_file`]) is fresh pages each time. Measured on the
    /// overhead sweep (`--threads 1`, 4 interleaved pairs): 12 500–14 500 page faults a
    /// command against 16 000–18 500 for the writer thread before, and the encoding's CPU
    /// back to the writer's (0.30 against 0.32 s), where fresh buffers on the workers took
    /// 7 % more.
    static PART_BUFFER: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Encode a part into this thread's buffer, then write it to `path` in one call (not synced);
/// returns its size.
fn encode_to_file(
    path: &Path,
    encode: impl FnOnce(&mut Vec<u8>) -> Result<(), ::parquet::errors::ParquetError>,
) -> Result<u64, SinkError> {
    PART_BUFFER.with_borrow_mut(|buf| {
        buf.clear();
        let written = encode(buf)
            .map_err(|source| SinkError::Format {
                path: path.to_path_buf(),
                source,
            })
            .and_then(|()| fs::write(path, &buf[..]).map_err(io(path)));
        let bytes = buf.len() as u64;
        if buf.capacity() > KEPT_PART_BUFFER {
            *buf = Vec::new();
        }
        written.map(|()| bytes)
    })
}

/// Commit an encoded batch: sync its series part and rename it into `series/`, then the same
/// for the runs part that commits it, then sync both folders.
fn commit_encoded(dirs: &PartDirs, name: &str) -> Result<(), SinkError> {
    for (suffix, dir) in [("series", &dirs.series), ("runs", &dirs.runs)] {
        let tmp = dirs.tmp.join(format!("{name}.{suffix}"));
        // fsync applies to the file, whichever descriptor asks for it.
        File::options()
            .write(true)
            .open(&tmp)
            .and_then(|f| f.sync_all())
            .map_err(io(&tmp))?;
        let dst = dir.join(name);
        fs::rename(&tmp, &dst).map_err(io(&dst))?;
    }
    sync_dir(&dirs.series)?;
    sync_dir(&dirs.runs)
}

/// Read every committed runs part of DIR into one frame (diagonal concat tolerates parts
/// written by versions with other columns).
pub fn read_runs(dir: &Path) -> Result<DataFrame, SinkError> {
    read_parts(&dir.join("runs"))
}

/// Read every committed series part of DIR.
pub fn read_series(dir: &Path) -> Result<DataFrame, SinkError> {
    read_parts(&dir.join("series"))
}

/// Unreadable parts are skipped (see [`unreadable_parts`] for the warning).
fn read_parts(dir: &Path) -> Result<DataFrame, SinkError> {
    let parts = parquet_parts(dir)?;
    let mut frames = Vec::with_capacity(parts.len());
    for p in &parts {
        let file = File::open(p).map_err(io(p))?;
        if let Ok(df) = ParquetReader::new(file).finish() {
            frames.push(df.lazy());
        }
    }
    if frames.is_empty() {
        return Ok(DataFrame::empty());
    }
    // Parts written by other versions may store a column with another type: supertypes.
    concat_lf_diagonal(
        frames,
        UnionArgs {
            to_supertypes: true,
            ..UnionArgs::default()
        },
    )
    .and_then(|lf| lf.collect())
    .map_err(|source| SinkError::Parquet {
        path: dir.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::SeriesRow;

    fn row(step: i64, theta: Option<f64>, exact: Option<f64>) -> SeriesRow {
        SeriesRow {
            step,
            t: step as f64 * 0.25,
            u_contact: -1e-3 * step as f64,
            v_contact: 0.5,
            sigma_contact: -(step as f64),
            energy: 1.0 + 1e-16 * step as f64,
            energy_theta: theta,
            u_contact_exact: exact,
            sigma_contact_exact: exact.map(|e| -e),
            energy_kinetic: Some(0.5 + step as f64),
            energy_elastic: Some(0.5 - step as f64),
            energy_gravity: None,
            u_lowest: theta.map(|t| -t),
            sigma_t_contact: None,
            v_t_contact: None,
            friction_work: exact.map(|e| 2.0 * e),
            u_contact_b: None,
            momentum: None,
        }
    }

    /// Write a series batch as the sink does, into `dir/series/part-0.parquet`.
    fn write_series(dir: &Path, batch: &[(String, Vec<SeriesRow>)]) -> PathBuf {
        let runs: Vec<(String, Series)> = batch
            .iter()
            .map(|(id, rows)| (id.clone(), rows.iter().cloned().collect()))
            .collect();
        let (tmp, series) = (dir.join(".tmp"), dir.join("series"));
        fs::create_dir_all(&tmp).unwrap();
        fs::create_dir_all(&series).unwrap();
        write_part_atomic(&tmp, &series, "part-0.parquet", "series", |out| {
            parquet::write_series(out, runs)
        })
        .unwrap();
        // Nothing is left behind where the part is being written.
        assert_eq!(fs::read_dir(&tmp).unwrap().count(), 0);
        series.join("part-0.parquet")
    }

    /// A series part is one row group whose columns carry the encodings chosen for their
    /// type (BYTE_STREAM_SPLIT floats, delta integers, a dictionary for run_id), with page
    /// statistics and the page index: the pages of run_id inside a run have min = max = its
    /// id, so a reader of one run prunes the others' pages; and a reader of two of three runs
    /// gets exactly their rows back, bit for bit.
    #[test]
    fn series_parts_are_typed_and_page_indexed() {
        use ::parquet::basic::Encoding;
        use ::parquet::file::page_index::column_index::ColumnIndexMetaData;
        use ::parquet::file::reader::{FileReader, SerializedFileReader};
        // 3 runs of 2.5 pages each: pages straddle runs, as they do in a real part.
        let n = parquet::PAGE_ROWS * 5 / 2;
        let batch: Vec<(String, Vec<SeriesRow>)> = ["run-a", "run-b", "run-c"]
            .iter()
            .enumerate()
            .map(|(k, id)| {
                let rows = (0..n as i64)
                    .map(|s| row(s, None, Some((s + k as i64) as f64)))
                    .collect();
                (id.to_string(), rows)
            })
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let part = write_series(dir.path(), &batch);
        let options = ::parquet::file::serialized_reader::ReadOptionsBuilder::new()
            .with_page_index()
            .build();
        let reader =
            SerializedFileReader::new_with_options(File::open(&part).unwrap(), options).unwrap();
        let md = reader.metadata();
        assert_eq!(md.num_row_groups(), 1);
        let rg = md.row_group(0);
        let encodings = |name: &str| {
            rg.columns()
                .iter()
                .find(|c| c.column_path().string() == name)
                .unwrap()
                .encodings()
                .collect::<Vec<_>>()
        };
        assert!(encodings("t").contains(&Encoding::BYTE_STREAM_SPLIT));
        assert!(encodings("energy").contains(&Encoding::BYTE_STREAM_SPLIT));
        assert!(encodings("step").contains(&Encoding::DELTA_BINARY_PACKED));
        assert!(encodings("run_id").contains(&Encoding::RLE_DICTIONARY));
        let col = rg
            .columns()
            .iter()
            .position(|c| c.column_path().string() == "run_id")
            .unwrap();
        let index = &md.column_index().expect("page index written")[0][col];
        let ColumnIndexMetaData::BYTE_ARRAY(pages) = index else {
            panic!("run_id's column index is of byte arrays")
        };
        let offsets = &md.offset_index().expect("offset index written")[0][col];
        let first_rows: Vec<i64> = offsets
            .page_locations()
            .iter()
            .map(|p| p.first_row_index)
            .collect();
        // The row limit holds: the writer checks it after each mini-batch, which for a column
        // without nulls is PAGE_ROWS rows long (arrow-rs's writer), so a page ends once it holds
        // PAGE_ROWS rows and holds fewer than 2·PAGE_ROWS.
        let bounds: Vec<i64> = first_rows.iter().copied().chain([3 * n as i64]).collect();
        for w in bounds.windows(2) {
            assert!(w[1] - w[0] < 2 * parquet::PAGE_ROWS as i64, "{bounds:?}");
        }
        assert!(first_rows.len() >= (3 * n).div_ceil(2 * parquet::PAGE_ROWS));
        // The pages wholly inside run-b say so.
        let mut pure_b = 0;
        for (k, first) in first_rows.iter().enumerate() {
            let (lo, hi) = (pages.min_value(k).unwrap(), pages.max_value(k).unwrap());
            let last = first_rows.get(k + 1).map_or(3 * n as i64, |&f| f) - 1;
            if *first >= n as i64 && last < 2 * n as i64 {
                assert_eq!((lo, hi), (b"run-b".as_ref(), b"run-b".as_ref()));
                pure_b += 1;
            }
        }
        assert!(pure_b >= 1);
        // Two of the three runs, through the page index.
        let wanted: HashSet<&str> = ["run-a", "run-c"].into();
        let ranges = parquet::run_ranges(&part, &wanted).unwrap();
        assert_eq!(
            ranges,
            vec![
                ("run-a".to_string(), 0..n),
                ("run-c".to_string(), 2 * n..3 * n)
            ]
        );
        let r: Vec<_> = ranges.iter().map(|(_, r)| r.clone()).collect();
        let cols = parquet::read_rows_f64(&part, &r, &["t", "u_contact_exact", "nope"]).unwrap();
        let want_t: Vec<Option<f64>> = (0..2 * n).map(|k| Some((k % n) as f64 * 0.25)).collect();
        assert_eq!(cols[0], want_t);
        let want_exact: Vec<Option<f64>> = (0..n)
            .map(|s| Some(s as f64))
            .chain((0..n).map(|s| Some((s + 2) as f64)))
            .collect();
        assert_eq!(cols[1], want_exact);
        assert_eq!(cols[2], vec![None; 2 * n]);
    }

    /// The series columns are stored by column (dense columns moved into the batch, the
    /// run_id as one chunk per run, all-null columns without a vector of Nones): what comes
    /// back from the Parquet part must be the rows that went in, bit for bit, with the nulls
    /// where a run has no value.
    #[test]
    fn series_parts_round_trip_bit_for_bit() {
        let a: Vec<SeriesRow> = (0..5).map(|n| row(n, Some(n as f64), None)).collect();
        let b: Vec<SeriesRow> = (0..3).map(|n| row(n, None, None)).collect();
        let batch = vec![("run-a".to_string(), a.clone()), ("run-b".to_string(), b)];
        let dir = tempfile::tempdir().unwrap();
        let part = write_series(dir.path(), &batch);
        // Read back by polars, the summaries' reader.
        let back = ParquetReader::new(File::open(part).unwrap())
            .finish()
            .unwrap();
        assert_eq!(back.height(), 8);
        let ids: Vec<Option<&str>> = back
            .column("run_id")
            .unwrap()
            .str()
            .unwrap()
            .iter()
            .collect();
        assert_eq!(ids[..5], [Some("run-a"); 5]);
        assert_eq!(ids[5..], [Some("run-b"); 3]);
        let f = |name: &str| -> Vec<Option<f64>> {
            back.column(name).unwrap().f64().unwrap().iter().collect()
        };
        let rows: Vec<&SeriesRow> = batch.iter().flat_map(|(_, s)| s).collect();
        for (name, get) in [
            (
                "t",
                (|r: &SeriesRow| Some(r.t)) as fn(&SeriesRow) -> Option<f64>,
            ),
            ("u_contact", |r| Some(r.u_contact)),
            ("sigma_contact", |r| Some(r.sigma_contact)),
            ("energy", |r| Some(r.energy)),
            ("energy_theta", |r| r.energy_theta),
            ("energy_kinetic", |r| r.energy_kinetic),
            ("energy_elastic", |r| r.energy_elastic),
            ("u_lowest", |r| r.u_lowest),
        ] {
            let want: Vec<Option<f64>> = rows.iter().map(|r| get(r)).collect();
            assert_eq!(f(name), want, "column {name}");
        }
        // No run of the batch has an exact solution: a Float64 column of nulls.
        assert_eq!(
            back.column("u_contact_exact").unwrap().dtype(),
            &DataType::Float64
        );
        assert_eq!(back.column("u_contact_exact").unwrap().null_count(), 8);
        assert_eq!(back.column("energy_gravity").unwrap().null_count(), 8);
        let steps: Vec<Option<i64>> = back.column("step").unwrap().i64().unwrap().iter().collect();
        assert_eq!(steps, [0, 1, 2, 3, 4, 0, 1, 2].map(Some));
    }
}
