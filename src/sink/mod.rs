//! Crash-safe Parquet output (SPEC §8).
//!
//! Layout of DIR:
//! - `runs/part-*.parquet` — rows of [`RunRecord`], one file per batch;
//! - `series/part-*.parquet` — the time series of the same batch, same file name;
//! - `manifest.json` — the sweep file's text, tool version, git commit, machine, sessions.
//!
//! A batch is committed by an atomic sequence: write `series/.tmp-NAME`, fsync, rename to
//! `series/NAME`; then the same for `runs/NAME`; then fsync the folders. The runs part is the
//! commit record: a run counts as done iff its row is in a runs part. After a SIGKILL at any
//! moment the folder holds only complete Parquet files plus perhaps dot-named temporaries
//! (ignored by polars' glob and by pyarrow's dataset) and a series part whose runs part never
//! landed; [`Sink::open`] removes both, so `--resume` loses only the runs in flight and never
//! duplicates a row. Batches are flushed every `batch_runs` runs or `batch_seconds`, whichever
//! comes first, so a long sweep never holds much unsaved work.
//!
//! Several sessions may write into one DIR at once (the shards of a job array): each holds a
//! shared lock on `DIR/.lock` while it writes, and the clean-up above takes the exclusive lock
//! — so it runs only when no other session is writing, and never removes a temporary or a
//! series part that another session is about to commit.
//!
//! Damage from outside (a part truncated or overwritten by hand, a disk error): a runs part that
//! cannot be read whole, or a series part whose footer cannot be read, is moved aside with its
//! partner to `runs/.damaged-NAME` and `series/.damaged-NAME` ([`quarantine`], called by
//! [`Sink::open`]); its runs are then missing and a resume computes them again, so every run is
//! present exactly once. Renaming is safe while other shards write (their parts are complete
//! files, never rewritten). Readers ([`read_runs`], the summaries) skip unreadable parts, with
//! the same warning ([`Damaged::warning`]).

use std::collections::HashSet;
use std::fs::{self, File};
use std::io::{BufWriter, Write as _};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, mpsc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use polars::prelude::*;
use polars_parquet::write::{
    CompressionOptions, Encoding, FileWriter, StatisticsOptions, Version, WriteOptions, ZstdLevel,
    get_dtype_encoding, row_group_iter, to_parquet_schema,
};

pub mod manifest;

pub use manifest::{Manifest, ManifestState};

use crate::exec::RunResult;
use crate::run::record::{ColumnData, series_columns};
use crate::run::{RunRecord, SeriesRow};

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
    #[error(
        "{path}: holds results of sweep `{found}`, not `{expected}`; choose another --out, or pass --resume to add this sweep's runs to it"
    )]
    ForeignSweep {
        path: PathBuf,
        found: String,
        expected: String,
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

/// Build a DataFrame from typed columns.
pub fn frame(columns: Vec<(&'static str, ColumnData)>) -> PolarsResult<DataFrame> {
    let height = match columns.first() {
        Some((_, ColumnData::F64(v))) => v.len(),
        Some((_, ColumnData::I64(v))) => v.len(),
        Some((_, ColumnData::Str(v))) => v.len(),
        Some((_, ColumnData::StrRuns(v))) => v.iter().map(|(_, n)| n).sum(),
        Some((_, ColumnData::ListI64(v))) => v.len(),
        Some((_, ColumnData::ListF64(v))) => v.len(),
        Some((_, ColumnData::F64Dense(v))) => v.len(),
        Some((_, ColumnData::I64Dense(v))) => v.len(),
        Some((_, ColumnData::Null(n))) => *n,
        None => 0,
    };
    let cols = columns
        .into_iter()
        .map(|(name, data)| match data {
            ColumnData::F64(v) => Column::new(name.into(), &v),
            ColumnData::I64(v) => Column::new(name.into(), &v),
            ColumnData::Str(v) => Column::new(name.into(), &v),
            // Moved, not copied: a series batch has ~10⁶ rows.
            ColumnData::F64Dense(v) => Float64Chunked::from_vec(name.into(), v).into_column(),
            ColumnData::I64Dense(v) => Int64Chunked::from_vec(name.into(), v).into_column(),
            ColumnData::Null(n) => Column::full_null(name.into(), n, &DataType::Float64),
            ColumnData::StrRuns(v) => {
                // One chunk per run, each value stored once: a series batch has ~10⁶ rows
                // and a handful of runs.
                let mut out = StringChunked::full_null(name.into(), 0);
                for (value, n) in &v {
                    out.append(&StringChunked::full(name.into(), value, *n))
                        .expect("same name and type");
                }
                out.into_column()
            }
            // Built with the inner type given, so a column of empty or null lists is still
            // List(Int64)/List(Float64), not List(Null).
            ColumnData::ListI64(v) => {
                let values = v.iter().flatten().map(Vec::len).sum();
                let mut b = ListPrimitiveChunkedBuilder::<Int64Type>::new(
                    name.into(),
                    v.len(),
                    values,
                    DataType::Int64,
                );
                for l in &v {
                    b.append_opt_slice(l.as_deref());
                }
                b.finish().into_column()
            }
            ColumnData::ListF64(v) => {
                let values = v.iter().flatten().map(Vec::len).sum();
                let mut b = ListPrimitiveChunkedBuilder::<Float64Type>::new(
                    name.into(),
                    v.len(),
                    values,
                    DataType::Float64,
                );
                for l in &v {
                    match l {
                        Some(l) => b.append_iter(l.iter().copied()),
                        None => b.append_null(),
                    }
                }
                b.finish().into_column()
            }
        })
        .collect();
    DataFrame::new(height, cols)
}

/// Write a DataFrame to `dir/name` atomically (temporary dot-file, fsync, rename); returns the
/// file's size in bytes.
pub fn write_parquet_atomic(dir: &Path, name: &str, df: &mut DataFrame) -> Result<u64, SinkError> {
    write_parquet_parts_atomic(dir, name, df, None, Durability::Synced)
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

/// [`write_parquet_atomic`] with row groups of the given lengths (None: one per 512² rows) and
/// the given durability.
pub fn write_parquet_parts_atomic(
    dir: &Path,
    name: &str,
    df: &mut DataFrame,
    row_groups: Option<&[usize]>,
    durability: Durability,
) -> Result<u64, SinkError> {
    let tmp = dir.join(format!(".tmp-{name}"));
    let dst = dir.join(name);
    let file = File::create(&tmp).map_err(io(&tmp))?;
    // zstd: the series' floats barely compress, but step, t and the closed-form columns do —
    // 20.3 bytes per series row against 28.8 with lz4 and 59.7 uncompressed (measured on the
    // benches/sweeps/overhead_1d.toml series with polars' encodings). Level 1, not polars'
    // default 3: 20.45 against 20.31 bytes per row for 27 % less compression time (197 against
    // 269 ns per row of writer CPU; the writer takes its CPU from the workers when every core
    // runs one). Encodings per column type and row groups as the caller asks: see
    // [`encode_parquet`]. Not parallel: the sink's writer thread is already off the workers'
    // path, and a pool would compete with them for the cores.
    // Buffered: polars writes a part page by page (≈ 40 000 write calls for the summary's
    // tables and series parts of one sweep without the buffer).
    let mut buf = BufWriter::with_capacity(1 << 20, &file);
    encode_parquet(&mut buf, df, row_groups).map_err(|source| SinkError::Parquet {
        path: tmp.clone(),
        source,
    })?;
    buf.flush().map_err(io(&tmp))?;
    drop(buf);
    if durability == Durability::Synced {
        file.sync_all().map_err(io(&tmp))?;
    }
    let bytes = file.metadata().map_err(io(&tmp))?.len();
    drop(file);
    fs::rename(&tmp, &dst).map_err(io(&dst))?;
    Ok(bytes)
}

/// Encode `df` as Parquet into `out`, with row groups of the lengths given (summing to the
/// frame's height), else of 512² rows.
///
/// Polars' own `ParquetWriter` asks for a dictionary on every primitive column and, for a
/// float column, first estimates its cardinality with a HyperLogLog pass, only to fall back to
/// plain encoding: the values of a simulation are nearly all distinct. On the series that pass
/// was 16 % of the writer's CPU. Here each column gets its encoding from its type:
/// - Float64: plain (zstd then finds the repeats a dictionary would: the closed-form stress is
///   piecewise constant);
/// - Int64: delta (`step` is 0, 1, 2, …: a few bits a page, where plain was 8 bytes before
///   compression);
/// - everything else (run ids, strings, lists): polars' choice, a dictionary for strings.
///
/// Statistics as polars writes them (min/max/null count), so readers prune row groups.
fn encode_parquet(
    out: &mut impl std::io::Write,
    df: &mut DataFrame,
    row_groups: Option<&[usize]>,
) -> PolarsResult<()> {
    df.rechunk_mut();
    let schema = df.schema().to_arrow(CompatLevel::newest());
    let encodings: Vec<Vec<Encoding>> = schema
        .iter_values()
        .map(|field| match field.dtype() {
            ArrowDataType::Float64 => vec![Encoding::Plain],
            ArrowDataType::Int64 => vec![Encoding::DeltaBinaryPacked],
            other => get_dtype_encoding(other),
        })
        .collect();
    let options = WriteOptions {
        statistics: StatisticsOptions::default(),
        version: Version::V1,
        compression: CompressionOptions::Zstd(Some(zstd_level())),
        data_page_size: None,
    };
    let fields = to_parquet_schema(&schema)?.fields().to_vec();
    let mut writer = FileWriter::try_new(out, schema, options)?;
    let whole: Vec<usize>;
    let lengths = match row_groups {
        Some(l) => l,
        None => {
            const ROWS: usize = 512 * 512;
            whole = (0..df.height().div_ceil(ROWS))
                .map(|k| ROWS.min(df.height() - k * ROWS))
                .collect();
            &whole
        }
    };
    let mut offset = 0;
    for &rows in lengths.iter().filter(|&&n| n > 0) {
        // A slice of a single-chunk frame is one record batch, without a copy.
        let group = df.slice(offset as i64, rows);
        offset += rows;
        for batch in group.iter_chunks(CompatLevel::newest(), false) {
            let n = batch.len() as u64;
            writer.write(
                n,
                row_group_iter(batch, encodings.clone().into(), fields.clone(), options),
            )?;
        }
    }
    writer.end(None)?;
    Ok(())
}

/// The writer's zstd level (see [`write_parquet_atomic`]).
fn zstd_level() -> ZstdLevel {
    ZstdLevel::try_new(1).expect("1 is a valid zstd level")
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
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = dir.join(format!(".tmp-{name}"));
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
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) => return Some(e.to_string()),
    };
    let mut reader = ParquetReader::new(file);
    let r = if whole {
        reader.finish().map(|_| ())
    } else {
        reader.num_rows().map(|_| ())
    };
    r.err().map(|e| {
        let text = e.to_string();
        // polars' messages can run over several lines: the first says what failed.
        text.lines()
            .next()
            .unwrap_or("unreadable")
            .trim()
            .to_string()
    })
}

/// The damaged-file name of a part: `.damaged-NAME` beside it (dot-named, so every glob and
/// [`parquet_parts`] skip it).
pub fn damaged_name(path: &Path) -> PathBuf {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("part");
    path.with_file_name(format!(".damaged-{name}"))
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

/// Move every unreadable part of DIR aside, with its partner in the other folder (a batch is a
/// runs part and a series part of one name: a batch with either damaged is computed again).
pub fn quarantine(dir: &Path) -> Result<Vec<Damaged>, SinkError> {
    let mut out = Vec::new();
    for mut d in unreadable_parts(dir)? {
        let name = d.path.file_name().expect("a part file").to_owned();
        for sub in ["runs", "series"] {
            let p = dir.join(sub).join(&name);
            let to = damaged_name(&p);
            match fs::rename(&p, &to) {
                Ok(()) => {
                    if p == d.path {
                        d.moved_to = Some(to);
                    }
                }
                // Another session moved it first, or the batch has no such partner.
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    if p == d.path {
                        d.moved_to = Some(to);
                    }
                }
                Err(e) => return Err(io(&p)(e)),
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

/// Read the run_id column of every committed runs part.
pub fn committed_run_ids(runs_dir: &Path) -> Result<HashSet<String>, SinkError> {
    let mut ids = HashSet::new();
    for part in parquet_parts(runs_dir)? {
        let file = File::open(&part).map_err(io(&part))?;
        let df = ParquetReader::new(file)
            .with_columns(Some(vec!["run_id".into()]))
            .finish()
            .map_err(|source| SinkError::Parquet {
                path: part.clone(),
                source,
            })?;
        let col = df
            .column("run_id")
            .and_then(|c| c.str().cloned())
            .map_err(|source| SinkError::Parquet {
                path: part.clone(),
                source,
            })?;
        ids.extend(col.iter().flatten().map(String::from));
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
    /// Time the writer thread spent building frames and writing parts.
    pub write_seconds: f64,
    /// CPU time of the writer thread (None where the platform has no per-thread clock): on a
    /// machine with as many workers as cores this is the time the writer takes from them, so
    /// the best speed-up of N workers is bounded by N·R/(R + W) (R the runs' own time).
    pub write_cpu_seconds: Option<f64>,
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

/// A batch on its way to the writer thread.
enum Job {
    Batch {
        name: String,
        rows: Vec<RunRecord>,
        series: Vec<(String, Vec<SeriesRow>)>,
    },
    /// Answered once every job sent before has been handled.
    Sync(mpsc::Sender<()>),
}

/// State shared with the writer thread.
#[derive(Default)]
struct Shared {
    stats: SinkStats,
    /// The first failure; the writer commits nothing after it.
    error: Option<SinkError>,
}

/// Batches queued behind the one being written. One is enough to keep the workers busy while
/// a part is written, and bounds the memory held by a slow disk (the producer then waits).
const QUEUED_BATCHES: usize = 1;

/// The writer of one session into DIR.
///
/// Batches are committed by a writer thread, so the thread collecting results (and, with
/// `--threads 1`, the run loop itself) never waits for Parquet encoding or fsync. Commit order
/// and atomicity are unchanged: batches are written one after another, each series part before
/// its runs part. A write failure is reported by the next [`Sink::push`] or by
/// [`Sink::flush`]; nothing is committed after it.
pub struct Sink {
    runs_dir: PathBuf,
    rows: Vec<RunRecord>,
    series: Vec<(String, Vec<SeriesRow>)>,
    policy: BatchPolicy,
    last_flush: Instant,
    tag: String,
    seq: usize,
    /// Parts found unreadable when the folder was opened, now moved aside.
    pub damaged: Vec<Damaged>,
    shared_with_others: bool,
    shared: Arc<Mutex<Shared>>,
    jobs: Option<mpsc::SyncSender<Job>>,
    writer: Option<JoinHandle<()>>,
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
        if alone {
            Self::clean(&runs_dir, &series_dir)?;
            lock.unlock().map_err(io(&lock_path))?;
        }
        lock.lock_shared().map_err(io(&lock_path))?;
        let damaged = quarantine(dir)?;
        let done = committed_run_ids(&runs_dir)?;
        let stamp = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .unwrap_or_default()
            .as_millis();
        let shared = Arc::new(Mutex::new(Shared::default()));
        let (jobs, rx) = mpsc::sync_channel::<Job>(QUEUED_BATCHES);
        let writer = {
            let (runs_dir, shared) = (runs_dir.clone(), Arc::clone(&shared));
            std::thread::Builder::new()
                .name("parquet-writer".into())
                .spawn(move || write_loop(&runs_dir, &series_dir, &rx, &shared))
                .map_err(io(dir))?
        };
        Ok((
            Sink {
                runs_dir,
                rows: Vec::new(),
                series: Vec::new(),
                policy,
                last_flush: Instant::now(),
                tag: format!("{stamp}-{}", std::process::id()),
                seq: 0,
                damaged,
                shared_with_others: !alone,
                shared,
                jobs: Some(jobs),
                writer: Some(writer),
                _lock: lock,
            },
            done,
        ))
    }

    /// Remove what a killed session left: temporaries and series parts whose runs part never
    /// landed. Only called under the exclusive lock.
    fn clean(runs_dir: &Path, series_dir: &Path) -> Result<(), SinkError> {
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

    /// What has been committed so far (batches still queued are not counted).
    pub fn stats(&self) -> SinkStats {
        self.lock().stats
    }

    /// Runs committed so far.
    pub fn written(&self) -> usize {
        self.stats().written
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Shared> {
        // A poisoned lock means the writer panicked while holding it; its stats are still valid.
        self.shared.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The writer's failure, if any (taken: reported once).
    fn take_error(&self) -> Result<(), SinkError> {
        match self.lock().error.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Add a finished run; hand the batch to the writer if it is full or old.
    pub fn push(&mut self, result: RunResult) -> Result<(), SinkError> {
        self.take_error()?;
        if !result.series.is_empty() {
            self.series
                .push((result.record.run_id.clone(), result.series));
        }
        self.rows.push(result.record);
        if self.rows.len() >= self.policy.runs
            || self.last_flush.elapsed() >= Duration::from_secs_f64(self.policy.seconds)
        {
            self.send_batch()?;
        }
        Ok(())
    }

    /// Queue the pending batch for the writer (waits only if a batch is already queued).
    fn send_batch(&mut self) -> Result<(), SinkError> {
        self.last_flush = Instant::now();
        if self.rows.is_empty() {
            return Ok(());
        }
        let name = format!("part-{}-{:05}.parquet", self.tag, self.seq);
        self.seq += 1;
        let job = Job::Batch {
            name,
            rows: std::mem::take(&mut self.rows),
            series: std::mem::take(&mut self.series),
        };
        self.send(job)
    }

    fn send(&self, job: Job) -> Result<(), SinkError> {
        let sent = self.jobs.as_ref().is_some_and(|tx| tx.send(job).is_ok());
        if sent {
            Ok(())
        } else {
            self.take_error()?;
            Err(io(&self.runs_dir)(std::io::Error::other(
                "the Parquet writer thread stopped",
            )))
        }
    }

    /// Commit the pending batch and wait until every batch handed over is on disk.
    pub fn flush(&mut self) -> Result<(), SinkError> {
        self.send_batch()?;
        let (ack, done) = mpsc::channel();
        self.send(Job::Sync(ack))?;
        if done.recv().is_err() {
            self.take_error()?;
            return Err(io(&self.runs_dir)(std::io::Error::other(
                "the Parquet writer thread stopped",
            )));
        }
        self.take_error()
    }
}

impl Drop for Sink {
    /// Batches already handed over are still committed (each is complete); then the writer
    /// thread ends.
    fn drop(&mut self) {
        drop(self.jobs.take());
        if let Some(w) = self.writer.take() {
            let _ = w.join();
        }
    }
}

/// The writer thread: commit batches in order until the sink hangs up.
fn write_loop(
    runs_dir: &Path,
    series_dir: &Path,
    jobs: &mpsc::Receiver<Job>,
    shared: &Mutex<Shared>,
) {
    let lock = || shared.lock().unwrap_or_else(|p| p.into_inner());
    for job in jobs.iter() {
        match job {
            Job::Sync(ack) => {
                let _ = ack.send(());
            }
            Job::Batch { name, rows, series } => {
                if lock().error.is_some() {
                    continue; // nothing is committed after a failure
                }
                let start = Instant::now();
                let cpu_start = thread_cpu_seconds();
                let written = commit_batch(runs_dir, series_dir, &name, &rows, &series);
                let mut sh = lock();
                match written {
                    Ok(series_bytes) => {
                        let st = &mut sh.stats;
                        st.written += rows.len();
                        st.series_rows += series.iter().map(|(_, s)| s.len() as u64).sum::<u64>();
                        st.series_bytes += series_bytes;
                        st.run_seconds += rows
                            .iter()
                            .map(|r| r.wall_time_s * r.repeats as f64)
                            .sum::<f64>();
                        st.write_seconds += start.elapsed().as_secs_f64();
                        if let (Some(a), Some(b)) = (cpu_start, thread_cpu_seconds()) {
                            *st.write_cpu_seconds.get_or_insert(0.0) += b - a;
                        }
                    }
                    Err(e) => sh.error = Some(e),
                }
            }
        }
    }
}

/// Commit one batch (series first, then the runs part that commits it); returns the bytes of
/// the series part.
fn commit_batch(
    runs_dir: &Path,
    series_dir: &Path,
    name: &str,
    rows: &[RunRecord],
    series: &[(String, Vec<SeriesRow>)],
) -> Result<u64, SinkError> {
    let mut sdf = frame(series_columns(series)).map_err(|source| SinkError::Parquet {
        path: series_dir.join(name),
        source,
    })?;
    // A row group per run: a reader of one run's series (the report,
    // `pl.scan_parquet(...).filter(pl.col("run_id") == id)`) decodes that run's pages only.
    let lengths: Vec<usize> = series.iter().map(|(_, s)| s.len()).collect();
    let series_bytes = write_parquet_parts_atomic(
        series_dir,
        name,
        &mut sdf,
        Some(&lengths),
        Durability::Synced,
    )?;
    let mut rdf = frame(RunRecord::to_columns(rows)).map_err(|source| SinkError::Parquet {
        path: runs_dir.join(name),
        source,
    })?;
    write_parquet_atomic(runs_dir, name, &mut rdf)?;
    sync_dir(series_dir)?;
    sync_dir(runs_dir)?;
    Ok(series_bytes)
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
        }
    }

    /// A series part written with a row group per run: the footer names each group's run
    /// (run_id statistics min = max), so a reader of one run decodes that run only; the rows
    /// come back bit for bit through the typed encodings (delta `step`, plain floats).
    #[test]
    fn series_parts_have_a_row_group_per_run_with_typed_encodings() {
        use polars_parquet::parquet::statistics::Statistics;
        let a: Vec<SeriesRow> = (0..5).map(|n| row(n, None, Some(n as f64))).collect();
        let b: Vec<SeriesRow> = (0..3).map(|n| row(n, None, Some(1.0))).collect();
        let batch = vec![("run-a".to_string(), a), ("run-b".to_string(), b)];
        let dir = tempfile::tempdir().unwrap();
        let mut df = frame(series_columns(&batch)).unwrap();
        let before = df.clone();
        write_parquet_parts_atomic(
            dir.path(),
            "part-0.parquet",
            &mut df,
            Some(&[5, 3]),
            Durability::Synced,
        )
        .unwrap();
        let mut reader = ParquetReader::new(File::open(dir.path().join("part-0.parquet")).unwrap());
        let md = reader.get_metadata().unwrap().clone();
        let groups: Vec<(String, usize)> = md
            .row_groups
            .iter()
            .map(|rg| {
                let chunk = rg
                    .columns_under_root_iter("run_id")
                    .unwrap()
                    .next()
                    .unwrap();
                let Statistics::Binary(st) = chunk.statistics(&md.footer_buf).unwrap().unwrap()
                else {
                    panic!("run_id statistics are binary")
                };
                assert_eq!(st.min_value, st.max_value);
                (
                    String::from_utf8(st.min_value.unwrap()).unwrap(),
                    rg.num_rows(),
                )
            })
            .collect();
        assert_eq!(
            groups,
            vec![("run-a".to_string(), 5), ("run-b".to_string(), 3)]
        );
        let back = reader.finish().unwrap();
        assert!(back.equals_missing(&before));
    }

    /// The series columns are built in one pass (dense columns moved into the frame, the
    /// run_id as one chunk per run, all-null columns without a vector of Nones): what comes
    /// back from the Parquet part must be the rows that went in, bit for bit, with the nulls
    /// where a run has no value.
    #[test]
    fn series_parts_round_trip_bit_for_bit() {
        let a: Vec<SeriesRow> = (0..5).map(|n| row(n, Some(n as f64), None)).collect();
        let b: Vec<SeriesRow> = (0..3).map(|n| row(n, None, None)).collect();
        let batch = vec![("run-a".to_string(), a.clone()), ("run-b".to_string(), b)];
        let dir = tempfile::tempdir().unwrap();
        let mut df = frame(series_columns(&batch)).unwrap();
        write_parquet_atomic(dir.path(), "part-0.parquet", &mut df).unwrap();
        let back = ParquetReader::new(File::open(dir.path().join("part-0.parquet")).unwrap())
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
