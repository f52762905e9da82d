//! Command-line interface: clap structs hold the raw flags; [`main`] validates them into domain
//! types (a [`Plan`], an output folder, [`ExecOptions`]) before any work starts.
//!
//! Exit status: 0 done (failed runs are rows, not errors), 2 bad input (sweep file, flags,
//! an output folder of another sweep), 1 a runtime failure (I/O).

use std::collections::{HashMap, HashSet};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::exec::shard::ShardSpec;
use crate::exec::{self, ExecOptions};
use crate::run::{RunOptions, RunRecord, SERIES_COLUMNS, estimate};
use crate::sink::{BatchPolicy, Manifest, ManifestState, Sink, SinkError};
use crate::summary;
use crate::sweep::{self, Plan, SweepError, SweepFile};

#[derive(Debug, Parser)]
#[command(
    name = "contact-sweep",
    version,
    about = "Parameter sweeps of dynamic Signorini-contact simulations, to Parquet and convergence tables",
    after_help = "Examples:\n  contact-sweep run sweeps/quickstart.toml            # 60 runs, tables and out/quickstart/report.html\n  contact-sweep run --scene bar1d --set h=[0.1,0.05] --set courant=1\n  contact-sweep plan sweeps/003_fig10_ladder.toml\n  contact-sweep report out/quickstart"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Expand a sweep file and print its runs, without running anything.
    #[command(
        after_help = "Examples:\n  contact-sweep plan sweeps/quickstart.toml\n  contact-sweep plan sweeps/quickstart.toml --set h=[0.1,0.05]   # h becomes an axis\n  contact-sweep plan --scene bar1d --set space=nitsche --set nitsche_gamma0=1e-6"
    )]
    Plan {
        #[command(flatten)]
        source: SweepArgs,
        #[command(flatten)]
        limits: LimitArgs,
    },
    /// Run a sweep: every run in parallel, results as Parquet under --out.
    #[command(
        after_help = "Examples:\n  contact-sweep run sweeps/quickstart.toml                       # → out/quickstart/\n  contact-sweep run sweeps/quickstart.toml --table runs           # every run, not one line per group\n  contact-sweep run sweeps/quickstart.toml --set T=3 --out out/qs-T3\n  contact-sweep run sweeps/quickstart.toml --set grid.h=[0.1,0.05]\n  contact-sweep run --scene bar1d --set h=0.01 --set courant=[0.5,1] --set scheme=hybrid\n  contact-sweep run sweeps/003_fig10_ladder.toml --threads 2 --shard 0/4   # one of four shards"
    )]
    Run(RunArgs),
    /// Write convergence, energy and speed-against-error tables for a results folder.
    #[command(
        after_help = "Examples:\n  contact-sweep summarize out/quickstart\n  contact-sweep summarize out/quickstart --errors err_u_l2h1,err_energy_l2\n  contact-sweep summarize out/quickstart --errors all"
    )]
    Summarize {
        /// A folder written by `run`.
        dir: PathBuf,
        /// Error columns of the Markdown and LaTeX convergence tables, comma-separated (or
        /// `all`); overrides the sweep file's `[summary] errors`. Default: err_u_l2l2,
        /// err_u_l2h1, err_sigma_mid_l2, err_energy_l2.
        #[arg(long, value_name = "A,B,…", value_delimiter = ',')]
        errors: Option<Vec<String>>,
    },
    /// Write one self-contained HTML report of a results folder (figures and tables).
    #[command(
        after_help = "Examples:\n  contact-sweep report out/quickstart                      # → out/quickstart/report.html\n  contact-sweep report out/003-fig10-ladder --out fig10.html"
    )]
    Report {
        /// A folder written by `run`.
        dir: PathBuf,
        /// The HTML file to write (default: DIR/report.html).
        #[arg(long, value_name = "FILE.html")]
        out: Option<PathBuf>,
    },
    /// Print the output schema (runs and series columns) as Markdown.
    #[command(after_help = "Examples:\n  contact-sweep schema\n  contact-sweep schema > schema.md")]
    Schema,
    /// What a results folder holds: done, failed and missing runs per shard, damaged files,
    /// sessions, and the command that completes only what is missing.
    #[command(
        after_help = "Examples:\n  contact-sweep status out/quickstart\n  contact-sweep status out/003-fig10 --sweep sweeps/003_fig10_ladder.toml"
    )]
    Status {
        /// A folder written by `run` (or a Slurm array).
        dir: PathBuf,
        /// The sweep file (default: the one the folder's manifest records).
        #[arg(long)]
        sweep: Option<PathBuf>,
    },
    /// Write (and with --submit, submit) a Slurm job array running the sweep in shards.
    #[command(
        after_help = "Examples:\n  contact-sweep slurm sweeps/003_fig10_ladder.toml --tasks 8            # writes the scripts, prints the sbatch commands\n  contact-sweep slurm sweeps/000_table1_bar2d.toml --tasks 4 --time 01:00:00 --submit"
    )]
    Slurm(SlurmArgs),
}

/// What the planner refuses before anything runs (shared by plan, run and slurm).
#[derive(Debug, Args, Clone)]
pub struct LimitArgs {
    /// Refuse plans with more combinations than this (counted from the file before expanding).
    #[arg(long, value_name = "N", default_value_t = sweep::plan::DEFAULT_MAX_RUNS)]
    pub max_runs: u64,
    /// Refuse runs whose estimated memory exceeds this (e.g. 4G, 512M; default: half of the
    /// available memory, /proc/meminfo's MemAvailable).
    #[arg(long, value_name = "SIZE")]
    pub max_run_memory: Option<String>,
}

impl LimitArgs {
    /// The planner's limits, for runs keeping every `series_every`-th step (None: the sweep's).
    fn limits(&self, series_every: Option<usize>) -> Result<sweep::PlanLimits> {
        let max_run_bytes = match &self.max_run_memory {
            Some(text) => Some(estimate::parse_bytes(text).ok_or_else(|| {
                UsageError(format!(
                    "--max-run-memory must be a size such as 4G or 512M, got `{text}`"
                ))
            })?),
            None => estimate::available_memory().map(|b| 0.5 * b),
        };
        if self.max_runs == 0 {
            return Err(UsageError("--max-runs must be at least 1".into()).into());
        }
        Ok(sweep::PlanLimits {
            max_runs: self.max_runs,
            max_run_bytes,
            series_every,
            max_plan_bytes: estimate::available_memory().map(|b| 0.5 * b),
        })
    }
}

#[derive(Debug, Args)]
pub struct SlurmArgs {
    /// The sweep file.
    pub sweep: PathBuf,
    /// Number of array tasks.
    #[arg(long, conflicts_with_all = ["runs_per_task", "only_shards"])]
    pub tasks: Option<usize>,
    /// Size the array by runs instead: ⌈runs / R⌉ tasks.
    #[arg(long, value_name = "R", conflicts_with = "only_shards")]
    pub runs_per_task: Option<usize>,
    /// Shards per task: the plan is cut into tasks × G shards of equal estimated work, task K
    /// running shards K·G … K·G+G−1 (finer shards: a resubmission redoes less).
    #[arg(long, value_name = "G", default_value_t = 1)]
    pub shards_per_task: usize,
    /// Submit only these shards of N (what `status DIR` prints to complete a folder), e.g.
    /// `3,7-9/16`; each task takes --shards-per-task of them.
    #[arg(long, value_name = "LIST/N")]
    pub only_shards: Option<String>,
    /// At most P tasks of each array at once (the array's %P throttle).
    #[arg(long, value_name = "P")]
    pub max_parallel: Option<usize>,
    /// Split arrays at this many tasks (default: the cluster's MaxArraySize from `scontrol
    /// show config`, 1001 if it does not answer).
    #[arg(long, value_name = "M")]
    pub max_array_size: Option<usize>,
    /// Output folder shared by all tasks (default: out/<sweep name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// CPUs per task (each task runs that many threads).
    #[arg(long, default_value_t = 1)]
    pub cpus_per_task: usize,
    /// Time limit per task (Slurm syntax, e.g. 01:00:00).
    #[arg(long)]
    pub time: Option<String>,
    /// Partition.
    #[arg(long)]
    pub partition: Option<String>,
    /// Submit with sbatch (the summary job depends on the arrays).
    #[arg(long)]
    pub submit: bool,
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// Where a sweep comes from: a file, or `--scene` alone, with `--set` on top.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// The sweep file (TOML, see docs/guide.md); omit it to give everything with --scene and --set.
    pub sweep: Option<PathBuf>,
    /// Without a sweep file: the scene (bar1d, bar2d, bar3d); the sweep is named after it and
    /// its parameters come from --set.
    #[arg(long, value_name = "SCENE", conflicts_with = "sweep")]
    pub scene: Option<String>,
    /// Set a parameter, replacing the file's: `h=0.01` ([fixed]), `h=[0.01,0.005]` (an axis
    /// of [grid]), `fixed.h=…`, `grid.h=…`, `zip.dt=…`, `summary.errors=[…]`, `name=…`;
    /// repeatable, checked like the file. Bare words are strings (`scheme=hybrid`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
}

impl SweepArgs {
    /// The checked sweep: the file with the overrides, or the scene with them.
    pub fn load(&self) -> Result<SweepFile> {
        match (&self.sweep, &self.scene) {
            (Some(path), _) => Ok(SweepFile::load_with(path, &self.sets)?),
            (None, Some(scene)) => Ok(SweepFile::from_flags(scene, &self.sets)?),
            (None, None) => Err(UsageError(
                "give a sweep file, or --scene NAME with --set key=value for a sweep without one"
                    .into(),
            )
            .into()),
        }
    }
}

#[derive(Debug, Args)]
pub struct RunArgs {
    #[command(flatten)]
    pub source: SweepArgs,
    /// Output folder (default: out/<sweep name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads; 1 runs the serial reference loop; 0 uses every core.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Most runs per lockstep group: runs sharing their step matrix (2D/3D, direct solver) make
    /// one multi-column solve per step; 1 steps every run alone. Rows equal the runs alone bit
    /// for bit (only `lockstep` and the timings differ).
    #[arg(long, default_value_t = ExecOptions::LOCKSTEP_DEFAULT, value_name = "N",
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    pub lockstep: usize,
    /// Add to a folder holding results of another sweep (runs already present are skipped;
    /// resuming is automatic when the folder holds the same sweep).
    #[arg(long)]
    pub resume: bool,
    /// Stop a run after this many seconds (status `timeout`).
    #[arg(long, value_name = "SECS", allow_negative_numbers = true)]
    pub run_timeout: Option<f64>,
    /// Keep every k-th time step in DIR/series (0: none); overrides the sweep's series_every.
    #[arg(long, value_name = "K")]
    pub series_every: Option<usize>,
    /// Commit results every N runs (and at least every 2 seconds).
    #[arg(long, default_value_t = 16, value_name = "N")]
    pub batch: usize,
    /// Do not write the summary tables at the end.
    #[arg(long)]
    pub no_summary: bool,
    /// Run only shard K of N (the plan cut into N shards of equal estimated work), e.g.
    /// `--shard $SLURM_ARRAY_TASK_ID/8` in a job array; several: `0-3/16`, `1,5/16`. All shards
    /// may write into one --out folder.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Compute the sweep's reference runs into DIR/references and stop (the first job of a
    /// Slurm submission; the array depends on it).
    #[arg(long)]
    pub references_only: bool,
    /// The result table at the end: `runs` (one line per run), `groups` (one line per method
    /// group with its rates), `auto` (groups when the sweep has more than 30 runs).
    #[arg(long, value_enum, default_value_t = TableMode::Auto, value_name = "MODE")]
    pub table: TableMode,
    #[command(flatten)]
    pub limits: LimitArgs,
}

/// What the result table at the end of `run` shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableMode {
    /// groups when the sweep has more than [`COMPACT_ABOVE`] runs, else runs
    Auto,
    /// one line per run
    Runs,
    /// one line per method group with its convergence rates
    Groups,
}

/// Above this many runs the result table is one line per method group: a screen holds about 50
/// lines, and a ladder of 60 runs printed run by run pushes the rates off it.
pub const COMPACT_ABOVE: usize = 30;

/// Bad input detected by the CLI itself.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// Map an error to the exit status.
pub fn exit_code(e: &anyhow::Error) -> u8 {
    for cause in e.chain() {
        if cause.downcast_ref::<SweepError>().is_some()
            || cause.downcast_ref::<UsageError>().is_some()
        {
            return 2;
        }
        if let Some(SinkError::ForeignSweep { .. } | SinkError::Superseded { .. }) =
            cause.downcast_ref::<SinkError>()
        {
            return 2;
        }
        if let Some(
            exec::status::StatusError::Sweep(_) | exec::status::StatusError::NoSweep { .. },
        ) = cause.downcast_ref::<exec::status::StatusError>()
        {
            return 2;
        }
    }
    1
}

/// Raised by SIGINT/SIGTERM (Ctrl-C, or Slurm at a time limit): the sweep stops starting runs,
/// drops the ones in flight, commits every finished one and exits with status 130.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Validated `run` arguments.
struct RunConfig {
    plan: Plan,
    shard: Option<ShardSpec>,
    out: PathBuf,
    exec: ExecOptions,
    resume: bool,
    batch: BatchPolicy,
    summary: bool,
    references_only: bool,
    table: TableMode,
}

impl RunArgs {
    fn validate(self) -> Result<RunConfig> {
        let sweep = self.source.load()?;
        let limits = self
            .limits
            .limits(Some(self.series_every.unwrap_or(sweep.series_every)))?;
        let plan = sweep::expand_with(&sweep, &limits)?;
        if let Some(t) = self.run_timeout
            && !(t.is_finite() && t > 0.0)
        {
            return Err(UsageError(format!(
                "--run-timeout must be a positive number of seconds, got {t}"
            ))
            .into());
        }
        if self.batch == 0 {
            return Err(UsageError("--batch must be at least 1".into()).into());
        }
        let shard = match &self.shard {
            None => None,
            Some(s) => Some(ShardSpec::parse(s).map_err(UsageError)?),
        };
        let out = self
            .out
            .unwrap_or_else(|| Path::new("out").join(&plan.sweep.name));
        let series_every = self.series_every.unwrap_or(plan.sweep.series_every);
        Ok(RunConfig {
            shard,
            exec: ExecOptions {
                threads: self.threads,
                lockstep: self.lockstep,
                run: RunOptions {
                    series_every,
                    timeout: self.run_timeout.map(Duration::from_secs_f64),
                    cancel: Some(&INTERRUPTED),
                },
            },
            plan,
            out,
            resume: self.resume,
            batch: BatchPolicy {
                runs: self.batch,
                seconds: 2.0,
            },
            summary: !self.no_summary,
            references_only: self.references_only,
            table: self.table,
        })
    }
}

/// Run a subcommand.
pub fn main(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Plan { source, limits } => {
            let sf = source.load()?;
            let plan = sweep::expand_with(&sf, &limits.limits(None)?)?;
            print!("{}", plan.summary());
            println!();
            print!("{}", plan.table());
            Ok(ExitCode::SUCCESS)
        }
        Command::Run(args) => {
            let start = Instant::now();
            let cfg = args.validate()?;
            run(cfg, start)
        }
        Command::Summarize { dir, errors } => {
            let opts = summarize_options(&dir, errors.as_deref())?;
            let s = summary::summarize_with(&dir, &opts)?;
            for w in &s.warnings {
                eprintln!("warning: {w}");
            }
            print!("{}", s.terminal);
            Ok(ExitCode::SUCCESS)
        }
        Command::Report { dir, out } => {
            let r = crate::report::write(&dir, out.as_deref())?;
            println!(
                "report: {} ({} KiB, {} figures)",
                r.path.display(),
                r.bytes.div_ceil(1024),
                r.figures
            );
            for s in &r.skipped {
                eprintln!("  not drawn: {s}");
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Schema => {
            print!("{}", schema_markdown());
            Ok(ExitCode::SUCCESS)
        }
        Command::Slurm(args) => slurm(args),
        Command::Status { dir, sweep } => {
            if !dir.is_dir() {
                return Err(UsageError(format!("{}: no such folder", dir.display())).into());
            }
            let st = exec::status::status(&dir, sweep.as_deref())?;
            print!("{st}");
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// The column choice of `summarize DIR`: the `[summary]` table stored with DIR, its error
/// columns replaced by `--errors` when given (checked first: a bad flag is reported even when
/// the stored table is fine).
fn summarize_options(dir: &Path, errors: Option<&[String]>) -> Result<summary::SummaryOptions> {
    let flag = match errors {
        Some(names) => Some(
            summary::parse_errors(names)
                .map_err(|reason| UsageError(format!("--errors: {reason}")))?,
        ),
        None => None,
    };
    let mut opts = summary::stored_options(dir)?;
    if flag.is_some() {
        opts.errors = flag;
    }
    Ok(opts)
}

fn run(cfg: RunConfig, sweep_start: Instant) -> Result<ExitCode> {
    let plan = &cfg.plan;
    let dir = &cfg.out;
    check_folder(dir, plan, cfg.resume)?;
    if cfg.references_only {
        let all: Vec<&sweep::RunSpec> = plan.runs.iter().collect();
        let refs = exec::references::ensure(dir, plan, &all, &cfg.exec.run)?;
        eprintln!(
            "{} reference run(s) ready in {}",
            refs.len(),
            dir.join("references").display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let (sink, done) = open_sink(dir, cfg.batch)?;
    let mine = shard_runs(plan, cfg.shard.as_ref());
    refuse_superseded(dir, &mine, &done)?;
    let todo: Vec<&sweep::RunSpec> = mine
        .iter()
        .copied()
        .filter(|r| !done.contains(&r.run_id))
        .collect();
    let skipped = mine.len() - todo.len();
    if sink.shared_with_others() && cfg.shard.is_none() {
        eprintln!(
            "warning: another session is writing into {}; unless it runs other runs (a shard), rows may be duplicated",
            dir.display()
        );
    }
    let threads = if cfg.exec.threads == 0 {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    } else {
        cfg.exec.threads
    };
    let mut manifest = Manifest::begin(
        dir,
        plan,
        mine.len(),
        skipped,
        threads,
        cfg.shard.as_ref().map(|s| s.to_string()),
    )?;
    eprint!("{}", plan.summary());
    if let Some(spec) = &cfg.shard {
        eprintln!(
            "shard {spec}: {} of the {} runs",
            mine.len(),
            plan.runs.len()
        );
    }
    if skipped > 0 {
        eprintln!(
            "resuming in {}: {skipped} of {} runs already done",
            dir.display(),
            mine.len()
        );
    }
    let outcome = execute(&cfg, &sink, &todo, threads)?;
    let interrupted = INTERRUPTED.load(Ordering::SeqCst);
    let stats = sink.stats();
    manifest.finish(
        dir,
        stats.written,
        interrupted
            || outcome.result.is_err()
            || outcome.flushed.is_err()
            || outcome.searched.is_err(),
    )?;
    outcome.result?;
    outcome.flushed?;
    outcome.searched?;
    if interrupted {
        eprintln!(
            "interrupted: {} finished runs committed to {}; the runs in flight were dropped — run the same command to resume",
            stats.written,
            dir.display()
        );
        return Ok(ExitCode::from(130));
    }
    eprintln!(
        "{} runs written to {} ({} failed, {} diverged)",
        stats.written,
        dir.display(),
        outcome.failed,
        outcome.diverged
    );
    eprintln!("{}", cost_line(&stats, sweep_start.elapsed().as_secs_f64()));
    show_results(&cfg, &mine)?;
    Ok(ExitCode::SUCCESS)
}

/// Refuse an output folder holding another sweep (unless `--resume` adds to it), after
/// saying what became of a missing or damaged manifest.
fn check_folder(dir: &Path, plan: &Plan, resume: bool) -> Result<()> {
    let had_results = dir.join("runs").is_dir();
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let found = match Manifest::inspect(dir)? {
        ManifestState::Sweep(found) => found,
        ManifestState::Missing => {
            if had_results {
                eprintln!(
                    "warning: {} has no manifest.json: rebuilt from {}",
                    dir.display(),
                    plan.sweep.path.display()
                );
            }
            None
        }
        ManifestState::MovedAside { to, reason } => {
            eprintln!(
                "warning: {} is damaged ({reason}): moved aside to {}, rebuilt from {}",
                dir.join("manifest.json").display(),
                to.display(),
                plan.sweep.path.display()
            );
            None
        }
    };
    if let Some(found) = found
        && found != plan.sweep.name
        && !resume
    {
        return Err(SinkError::ForeignSweep {
            path: dir.to_path_buf(),
            found,
            expected: plan.sweep.name.clone(),
        }
        .into());
    }
    Ok(())
}

/// Open the folder's sink (the ids of the runs it holds beside it), saying what it repaired.
fn open_sink(dir: &Path, batch: BatchPolicy) -> Result<(Sink, HashSet<String>)> {
    let (sink, done) = Sink::open(dir, batch)?;
    for d in &sink.damaged {
        eprintln!("warning: {}", d.warning());
    }
    if !sink.migrated.is_empty() {
        eprintln!(
            "note: {} runs part(s) written by an older version given this version's columns (new columns null), so that every reader sees one schema",
            sink.migrated.len()
        );
    }
    if !sink.migrated_series.is_empty() {
        eprintln!(
            "note: {} series part(s) written by an older version given this version's columns (new columns null)",
            sink.migrated_series.len()
        );
    }
    for p in &sink.legacy_damaged {
        eprintln!(
            "note: moved {} (a damaged part set aside by an older version) out of the parts' folder",
            p.display()
        );
    }
    Ok((sink, done))
}

/// This session's runs: the plan's, or its shard's (balanced by estimated work,
/// exec::shard: every task computes the same split).
fn shard_runs<'p>(plan: &'p Plan, shard: Option<&ShardSpec>) -> Vec<&'p sweep::RunSpec> {
    match shard {
        None => plan.runs.iter().collect(),
        Some(spec) => {
            let of = exec::shard::assign(&plan.runs, spec.of);
            plan.runs
                .iter()
                .zip(of)
                .filter(|(_, s)| spec.contains(*s))
                .map(|(r, _)| r)
                .collect()
        }
    }
}

/// Refuse to run when the folder holds rows of these runs under their ids of before a
/// definition change (issue 34): their numbers are not this version's, and new rows beside
/// them would make two answers to one question in every table.
fn refuse_superseded(dir: &Path, mine: &[&sweep::RunSpec], done: &HashSet<String>) -> Result<()> {
    // An old id that is also a planned run's own (an FE run's u⁰ = 0 start kept its id as
    // `contact_init = "interpolant"`, issue 42) holds that run's rows, not superseded ones.
    let planned: HashSet<&str> = mine.iter().map(|r| r.run_id.as_str()).collect();
    let superseded: Vec<&sweep::RunSpec> = mine
        .iter()
        .copied()
        .filter(|r| {
            r.superseded_id
                .as_ref()
                .is_some_and(|old| done.contains(old) && !planned.contains(old.as_str()))
        })
        .collect();
    if let Some(first) = superseded.first() {
        return Err(SinkError::Superseded {
            path: dir.to_path_buf(),
            count: superseded.len(),
            example: first.superseded_id.clone().unwrap_or_default(),
            now: first.run_id.clone(),
        }
        .into());
    }
    Ok(())
}

/// What executing the runs came to: each step's result, kept until the manifest records
/// whether the session completed, and the runs' failures.
struct Outcome {
    result: std::result::Result<(), SinkError>,
    flushed: std::result::Result<(), SinkError>,
    searched: Result<()>,
    failed: usize,
    diverged: usize,
}

/// The progress bar of `todo`, advancing by each run's estimated work (steps × unknowns ×
/// repeats, the plan's cost model), so its ETA is weighted: the last level of a ladder costs
/// ~1000× the first, and an ETA counting runs would be wrong by that factor for most of the
/// sweep. Hidden when stderr is not a terminal.
fn progress_bar<'a>(todo: &[&'a sweep::RunSpec]) -> (ProgressBar, HashMap<&'a str, u64>) {
    let work_of = |r: &sweep::RunSpec| (r.config.work() * r.repeats as u64).max(1);
    let works: HashMap<&str, u64> = todo
        .iter()
        .map(|r| (r.run_id.as_str(), work_of(r)))
        .collect();
    let bar = ProgressBar::new(works.values().sum());
    if std::io::stderr().is_terminal() {
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {percent:>3}% of the work  {msg}  ETA {eta}")
                .expect("valid template"),
        );
    } else {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    (bar, works)
}

/// Run `todo` into the sink with the bar drawn, commit, and bisect the sweep's searches;
/// errors of the runs, the commit and the search are kept in the [`Outcome`] (the manifest
/// records them first), a failed reference run is returned at once.
fn execute(
    cfg: &RunConfig,
    sink: &Sink,
    todo: &[&sweep::RunSpec],
    threads: usize,
) -> Result<Outcome> {
    let (plan, dir) = (&cfg.plan, &cfg.out);
    let (bar, works) = progress_bar(todo);
    let (total_runs, mut done_runs) = (todo.len(), 0usize);
    // A second signal is left to the default action: the user can still kill a stuck process.
    if let Err(e) = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    }) {
        eprintln!("warning: no signal handler ({e}); an interrupt loses the batch in flight");
    }
    let (mut failed, mut diverged) = (0usize, 0usize);
    let refs = exec::references::ensure(dir, plan, todo, &cfg.exec.run)?;
    // Each run's output is encoded by the worker that ran it (`Sink::push`); this thread
    // only counts and draws the bar.
    let result = exec::execute_with(
        &plan.sweep.name,
        todo,
        &refs,
        &ExecOptions {
            threads,
            ..cfg.exec
        },
        |res| {
            let seen = (res.record.status.clone(), res.record.run_id.clone());
            sink.push(res).map(|()| seen)
        },
        |(status, run_id)| {
            match status.as_str() {
                "ok" => {}
                "diverged" => diverged += 1,
                _ => failed += 1,
            }
            done_runs += 1;
            bar.set_message(format!(
                "{done_runs}/{total_runs} runs, failed {failed}, diverged {diverged}"
            ));
            bar.inc(works.get(run_id.as_str()).copied().unwrap_or(1));
            Ok::<(), SinkError>(())
        },
    );
    let mut flushed = sink.flush();
    bar.finish_and_clear();
    let mut searched = Ok(());
    if result.is_ok() && flushed.is_ok() && !plan.searches.is_empty() {
        if cfg.shard.is_some() {
            eprintln!(
                "(a shard runs only the bracket ends of the [search]; run the sweep without --shard to bisect)"
            );
        } else {
            searched = bisect(dir, plan, &refs, &cfg.exec, threads, sink);
            if searched.is_ok() {
                flushed = sink.flush();
            }
        }
    }
    Ok(Outcome {
        result,
        flushed,
        searched,
        failed,
        diverged,
    })
}

/// The result table (run by run, or with the summary group by group) and, unless a shard or
/// `--no-summary`, the summary tables and the report.
fn show_results(cfg: &RunConfig, mine: &[&sweep::RunSpec]) -> Result<()> {
    let (plan, dir) = (&cfg.plan, &cfg.out);
    let mut ids: HashSet<&str> = mine.iter().map(|r| r.run_id.as_str()).collect();
    let probes = searched_ids(dir, plan)?;
    ids.extend(probes.iter().map(String::as_str));
    let summarized = cfg.shard.is_none() && cfg.summary;
    let per_run = match cfg.table {
        TableMode::Runs => true,
        TableMode::Groups => false,
        TableMode::Auto => ids.len() <= COMPACT_ABOVE,
    };
    if per_run {
        say(&result_table(dir, plan, &ids)?);
    } else if !summarized {
        // The group lines come with the summary; without it, say where the results are.
        say(&format!(
            "{} runs: `contact-sweep summarize {}` for the table by method group, or --table runs\n",
            ids.len(),
            dir.display()
        ));
    }
    if cfg.shard.is_some() {
        eprintln!(
            "(a shard: run `contact-sweep summarize {}` once every shard is done)",
            dir.display()
        );
    } else if cfg.summary {
        summarize_and_report(dir, plan);
    }
    Ok(())
}

/// The summary tables and the report of `dir`, a failure of either said and not an error
/// (the runs are committed). The sections are computed once for both (the report alone,
/// `contact-sweep report DIR`, reads the [summary] choice stored in the manifest: this
/// session's, i.e. plan.sweep.summary).
fn summarize_and_report(dir: &Path, plan: &Plan) {
    match summary::Sections::compute(dir, &plan.sweep.summary) {
        Ok(sections) => {
            // Tables and report from the same sections, side by side: both only read them,
            // and the sweep's workers are done, so the cores are free.
            let (tables, report) = std::thread::scope(|scope| {
                let tables = scope.spawn(|| sections.write(dir));
                let report = crate::report::write_with(dir, None, &sections);
                (tables.join(), report)
            });
            match tables {
                Ok(Ok(s)) => say(&s.terminal),
                Ok(Err(e)) => eprintln!("summary not written: {e:#}"),
                Err(_) => eprintln!("summary not written: its writer panicked"),
            }
            match report {
                Ok(r) => say(&format!(
                    "report: {} — open it in a browser: figures and every table\n",
                    r.path.display()
                )),
                Err(e) => eprintln!("report not written: {e:#}"),
            }
        }
        Err(e) => eprintln!("summary and report not written: {e:#}"),
    }
}

/// Print `run`'s results to stdout, ignoring a reader that went away (`run … | head`): the
/// runs are committed by then, and the summary and report that follow must still be written
/// (`print!` would panic on the broken pipe and skip them).
fn say(text: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
}

/// Where the session's time and bytes went: the runs' own time (summed over workers) against
/// the wall time since the command started, the output's encoding (CPU summed over the
/// workers that did it) and the committer thread's CPU — the one serial part of the output,
/// which bounds how many workers a node can use — and the size of the time series per stored
/// step.
fn cost_line(stats: &crate::sink::SinkStats, wall_s: f64) -> String {
    // "NAME N s CPU (…)": the CPU is the figure that matters (it is what the part takes from
    // the cores); wall time where the platform has no per-thread clock.
    let part = |name: &str, cpu: Option<f64>, wall: f64, where_: &str| match cpu {
        Some(c) => format!("{name} {c:.3} s CPU ({where_}, {wall:.3} s wall)"),
        None => format!("{name} {wall:.3} s wall ({where_})"),
    };
    let mut s = format!(
        "time: runs {:.3} s (summed), command {:.3} s wall so far, {}, {}",
        stats.run_seconds,
        wall_s,
        part(
            "encoding",
            stats.encode_cpu_seconds,
            stats.encode_seconds,
            "on the workers"
        ),
        part(
            "committer",
            stats.commit_cpu_seconds,
            stats.commit_seconds,
            "own thread"
        ),
    );
    if stats.series_rows > 0 {
        s.push_str(&format!(
            "; series: {} stored steps, {:.1} MB, {:.2} bytes/step",
            stats.series_rows,
            stats.series_bytes as f64 / 1e6,
            stats.series_bytes as f64 / stats.series_rows as f64
        ));
    }
    s
}

fn slurm(args: SlurmArgs) -> Result<ExitCode> {
    use crate::exec::slurm::{SlurmOptions, commands, max_array_size, submit, write_scripts};
    let positive = |v: Option<usize>, flag: &str| -> Result<()> {
        if v == Some(0) {
            return Err(UsageError(format!("{flag} must be at least 1")).into());
        }
        Ok(())
    };
    positive(args.tasks, "--tasks")?;
    positive(args.runs_per_task, "--runs-per-task")?;
    positive(Some(args.shards_per_task), "--shards-per-task")?;
    positive(Some(args.cpus_per_task), "--cpus-per-task")?;
    positive(args.max_parallel, "--max-parallel")?;
    positive(args.max_array_size, "--max-array-size")?;
    let only = match &args.only_shards {
        Some(text) => Some(
            ShardSpec::parse(text)
                .map_err(|e| UsageError(e.replace("--shard", "--only-shards")))?,
        ),
        None => None,
    };
    if only.is_none() && args.tasks.is_none() && args.runs_per_task.is_none() {
        return Err(UsageError(
            "give --tasks N or --runs-per-task R (or --only-shards LIST/N, as `status` prints)"
                .into(),
        )
        .into());
    }
    let sf = SweepFile::load(&args.sweep)?;
    let plan = sweep::expand_with(&sf, &args.limits.limits(None)?)?;
    let g = args.shards_per_task;
    let (shards, list): (usize, Vec<usize>) = match &only {
        Some(spec) => (spec.of, spec.shards.clone()),
        None => {
            let tasks = args
                .tasks
                .unwrap_or_else(|| plan.runs.len().div_ceil(args.runs_per_task.unwrap_or(1)));
            let n = tasks.saturating_mul(g);
            (n, (0..n).collect())
        }
    };
    let tasks: Vec<String> = list
        .chunks(g)
        .map(|c| {
            ShardSpec {
                shards: c.to_vec(),
                of: shards,
            }
            .to_string()
        })
        .collect();
    let out = args
        .out
        .unwrap_or_else(|| Path::new("out").join(&plan.sweep.name));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let out = out
        .canonicalize()
        .with_context(|| format!("{}", out.display()))?;
    let exe = std::env::current_exe().context("locating the contact-sweep binary")?;
    let max_array = args.max_array_size.or_else(max_array_size).unwrap_or(1001);
    let scripts = write_scripts(
        &exe,
        &plan.sweep.name,
        &plan.sweep.text,
        !plan.references.is_empty(),
        &out,
        &SlurmOptions {
            tasks: tasks.clone(),
            max_parallel: args.max_parallel,
            max_array_size: max_array,
            cpus_per_task: args.cpus_per_task,
            time: args.time,
            partition: args.partition,
        },
    )?;
    eprint!("{}", plan.summary());
    let assignment = exec::shard::assign(&plan.runs, shards);
    let loads = exec::shard::loads(&plan.runs, &assignment, shards);
    let chosen: Vec<u64> = list.iter().map(|&k| loads[k]).collect();
    eprintln!(
        "{} of the {} runs in {} of {shards} shards (balanced by estimated work: {:.2e} to {:.2e} steps × unknowns each), {} array task(s) of {g} shard(s), {} array(s) of at most {max_array} (MaxArraySize){}",
        list.iter()
            .map(|&k| assignment.iter().filter(|&&s| s == k).count())
            .sum::<usize>(),
        plan.runs.len(),
        list.len(),
        chosen.iter().min().copied().unwrap_or(0) as f64,
        chosen.iter().max().copied().unwrap_or(0) as f64,
        tasks.len(),
        scripts.arrays.len(),
        args.max_parallel
            .map(|p| format!(", at most {p} at once"))
            .unwrap_or_default()
    );
    if args.submit {
        let ids = submit(&scripts)?;
        if let Some(r) = &ids.references {
            println!("submitted reference job {r}; the arrays depend on it (afterok:{r})");
        }
        println!(
            "submitted array job {} and summary job {} (afterok:{})",
            ids.arrays.join(", "),
            ids.summary,
            ids.arrays.join(":")
        );
        println!("results: {}", out.display());
        println!("progress: contact-sweep status {}", out.display());
    } else {
        for c in commands(&scripts) {
            println!("{c}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn fmt_num(x: Option<f64>) -> String {
    x.map(summary::eng).unwrap_or_else(|| "—".into())
}

/// The legend of the per-run result table: every abbreviated column.
const RESULT_LEGEND: &str = "  E(T)/E0: final over initial discrete energy (1 + energy_drift, i.e. 1 + (E(T) − E⁰)/energy_scale, where E⁰ = 0 under gravity) · l2(τ;L2), l2(τ;H1): displacement error in l2(0,T;L2), l2(0,T;H1) · σ½ l2(τ): contact pressure error at the midpoints t^(n+½), l2(0,T)\n";

/// Per-run results of this sweep, in plan order, read back from the Parquet parts.
fn result_table(dir: &Path, plan: &Plan, ids: &HashSet<&str>) -> Result<String> {
    if ids.is_empty() {
        return Ok(String::new()); // a shard with no runs
    }
    let df = crate::sink::read_runs(dir)?;
    let get_str = |name: &str| -> Result<Vec<Option<String>>> {
        Ok(df
            .column(name)?
            .str()?
            .iter()
            .map(|s| s.map(String::from))
            .collect())
    };
    // A column absent from every part (written by an older version) prints as "—".
    let get_f64 = |name: &str| -> Result<Vec<Option<f64>>> {
        match df.column(name) {
            Ok(c) => Ok(c.f64()?.iter().collect()),
            Err(_) => Ok(vec![None; df.height()]),
        }
    };
    let run_ids = get_str("run_id")?;
    let status = get_str("status")?;
    let (e0, ef) = (get_f64("energy_initial")?, get_f64("energy_final")?);
    // The disc and ball start with E⁰ = 0 (at rest, potential measured from the start), so their
    // drift is relative to energy_scale = m·g·gap and E(T)/E⁰ would print ±inf; 1 + drift equals
    // E(T)/E⁰ wherever energy_scale = E⁰ (the bars).
    let drift = get_f64("energy_drift")?;
    let (l2, h1, sig) = (
        get_f64("err_u_l2l2")?,
        get_f64("err_u_l2h1")?,
        get_f64("err_sigma_mid_l2")?,
    );
    let header: Vec<String> = [
        "#",
        "label",
        "h",
        "dt",
        "status",
        "E(T)/E0",
        "l2(τ;L2)",
        "l2(τ;H1)",
        "σ½ l2(τ)",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let mut rows = Vec::new();
    for (i, r) in plan.runs.iter().enumerate() {
        if !ids.contains(r.run_id.as_str()) {
            continue;
        }
        let Some(j) = run_ids
            .iter()
            .position(|x| x.as_deref() == Some(r.run_id.as_str()))
        else {
            continue;
        };
        let ratio = summary::runs::energy_ratio(e0[j], ef[j], drift[j]);
        let p = |k: sweep::Key| match r.params.get(&k) {
            Some(sweep::Value::Num(x)) => summary::eng(*x),
            Some(v) => v.to_string(),
            None => String::new(),
        };
        rows.push(vec![
            i.to_string(),
            r.label.clone(),
            p(sweep::Key::H),
            p(sweep::Key::Dt),
            status[j].clone().unwrap_or_default(),
            fmt_num(ratio),
            fmt_num(l2[j]),
            fmt_num(h1[j]),
            fmt_num(sig[j]),
        ]);
    }
    if rows.is_empty() {
        bail!("no result rows found in {}", dir.display());
    }
    let mut out = sweep::render_table(&header, &rows);
    out.push_str(RESULT_LEGEND);
    Ok(out)
}

/// The schema of DIR/runs and DIR/series as Markdown tables (docs/guide.md's are generated here).
pub fn schema_markdown() -> String {
    let mut s = String::from(
        "### `DIR/runs/*.parquet` — one row per run\n\n| column | type | unit | meaning |\n|---|---|---|---|\n",
    );
    for (c, t, u, d) in RunRecord::COLUMNS {
        s.push_str(&format!("| `{c}` | {t} | {u} | {d} |\n"));
    }
    s.push_str("\n### `DIR/series/*.parquet` — one row per stored time step\n\n| column | type | unit | meaning |\n|---|---|---|---|\n");
    for (c, t, u, d) in SERIES_COLUMNS {
        s.push_str(&format!("| `{c}` | {t} | {u} | {d} |\n"));
    }
    s
}

/// The (value, criterion holds) of every probe of each search base committed in DIR.
fn probe_results(dir: &Path, plan: &Plan) -> Result<Vec<Vec<(f64, bool)>>> {
    let mut out = vec![Vec::new(); plan.searches.len()];
    let Some(search) = &plan.sweep.search else {
        return Ok(out);
    };
    let df = crate::sink::read_runs(dir)?;
    let Ok(tags) = df.column("search") else {
        return Ok(out);
    };
    let tags = tags.str()?;
    let f = |name: &str| -> Vec<Option<f64>> {
        df.column(name)
            .ok()
            .and_then(|c| c.f64().ok().map(|c| c.iter().collect()))
            .unwrap_or_else(|| vec![None; df.height()])
    };
    let key = f(search.key.name());
    let (e0, ef) = (f("energy_initial"), f("energy_final"));
    let column = match &search.criterion {
        sweep::Criterion::ErrorBelow { column, .. } => f(column),
        _ => vec![None; df.height()],
    };
    let status = df.column("status")?.str()?;
    for (i, tag) in tags.iter().enumerate() {
        let Some(b) = tag.and_then(|t| plan.searches.iter().position(|b| b.tag == t)) else {
            continue;
        };
        let (Some(v), Some(st)) = (key[i], status.get(i)) else {
            continue;
        };
        let holds = search.criterion.holds(st, e0[i], ef[i], |_| column[i]);
        out[b].push((v, holds));
    }
    Ok(out)
}

/// Run ids of the committed probes of this sweep's searches (for the result table).
fn searched_ids(dir: &Path, plan: &Plan) -> Result<Vec<String>> {
    if plan.searches.is_empty() {
        return Ok(Vec::new());
    }
    let df = crate::sink::read_runs(dir)?;
    let (Ok(tags), Ok(ids)) = (df.column("search"), df.column("run_id")) else {
        return Ok(Vec::new());
    };
    let tags: Vec<Option<String>> = tags.str()?.iter().map(|t| t.map(String::from)).collect();
    Ok(ids
        .str()?
        .iter()
        .zip(tags)
        .filter(|(_, t)| {
            t.as_deref()
                .is_some_and(|t| plan.searches.iter().any(|b| b.tag == t))
        })
        .filter_map(|(id, _)| id.map(String::from))
        .collect())
}

/// Bracket then bisect every search base: each round runs the next probe of every base still
/// open (in parallel), commits them like any run, and re-reads what is committed — so an
/// interrupted search resumes where it stopped.
fn bisect(
    dir: &Path,
    plan: &Plan,
    refs: &exec::References,
    opts: &ExecOptions,
    threads: usize,
    sink: &Sink,
) -> Result<()> {
    let search = plan
        .sweep
        .search
        .as_ref()
        .expect("searches need a [search]");
    // Each round halves every open bracket: log2(range/rel_tol) rounds suffice; the cap only
    // guards against a criterion that is not monotone in the key.
    for _round in 0..200 {
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Ok(());
        }
        let known = probe_results(dir, plan)?;
        let mut todo = Vec::new();
        for (base, k) in plan.searches.iter().zip(&known) {
            if let sweep::SearchState::Probe(v) = search.state(k) {
                todo.push(sweep::plan::probe(plan, base, v)?);
            }
        }
        if todo.is_empty() {
            break;
        }
        let specs: Vec<&sweep::RunSpec> = todo.iter().collect();
        exec::execute_with(
            &plan.sweep.name,
            &specs,
            refs,
            &ExecOptions { threads, ..*opts },
            |res| sink.push(res),
            |()| Ok::<(), SinkError>(()),
        )?;
        sink.flush()?;
    }
    let known = probe_results(dir, plan)?;
    for (base, k) in plan.searches.iter().zip(&known) {
        let what = match search.state(k) {
            sweep::SearchState::Found { holding, failing } => format!(
                "{} holds up to {holding:.6e}, fails at {failing:.6e}",
                search.criterion.name()
            ),
            sweep::SearchState::NotBracketed(h) => format!(
                "{} {} on all of [{}, {}]: no boundary",
                search.criterion.name(),
                if h { "holds" } else { "fails" },
                search.lo,
                search.hi
            ),
            sweep::SearchState::Probe(_) => "search not finished".into(),
        };
        eprintln!(
            "search {} ({}): {} — {what} ({} probes)",
            search.name,
            search.key.name(),
            base.label,
            k.len()
        );
    }
    Ok(())
}
