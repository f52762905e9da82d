//! Loading `DIR/runs` into plain rows, and grouping them into method groups and refinement
//! paths.
//!
//! Only the columns this module knows are read (by name, cast to the type this version
//! expects); anything else in the Parquet — columns of another version — is ignored and
//! listed, never an error. A known column of an unusable type (a list, a struct) is treated as
//! absent.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use anyhow::{Context as _, bail};
use polars::prelude::*;

use super::columns::{Kind, columns};

/// Parameter columns (contract §7, §8) that identify a method group, in output order. The
/// refinement axes ([`REFINEMENT`]) and the derived `label` are not among them: `label` is a
/// function of these parameters and is carried, not grouped by. `sweep` is not a parameter:
/// the same method run by two sweeps into one folder (`--resume`) is one group.
pub(crate) const PARAMS: &[(&str, Kind)] = &columns![
    scene: Str, space: Str, mass: Str, mass_weights: Str, contact_init: Str, scheme: Str,
    scheme_label: Str, nitsche_theta: F64, nitsche_gamma0: F64, penalty_gamma0: F64,
    newmark_beta: F64, newmark_gamma: F64, theta_scheme: F64, restitution: F64, rho_inf: F64,
    hht_alpha: F64, length: F64, young: F64, density: F64, amplitude: F64, gap: F64,
    lame_lambda: F64, lame_mu: F64, gravity: F64, degree: I64, right_end: Str, velocity: F64,
    point_mass: F64, stiffness: F64, force: F64, impact_law: F64, solver: Str, cg_tol: F64,
    T: F64, ensemble_sample: I64, ensemble_perturbation: F64, friction: Str,
    friction_coefficient: F64, tresca_threshold: F64, height: F64, velocity_tangential: F64,
    friction_force: F64, incline: F64, length_b: F64, young_b: F64, density_b: F64,
    velocity_b: F64, far_end: Str, mass_side: Str, nitsche_sides: Str, width: F64, height_b: F64,
    lame_lambda_b: F64, lame_mu_b: F64, pressure: F64, mesh_ratio: F64, pairing: Str,
    mortar_basis: Str, interface_quadrature: Str, start: Str,
];

/// The parameters already spelled out in a run's `label` (contact method · mass · scheme);
/// the other parameters are added to a group's title when they vary across the folder.
const IN_LABEL: &[&str] = &[
    "space",
    "mass",
    "mass_weights",
    "contact_init",
    "scheme",
    "scheme_label",
    "friction",
    "friction_coefficient",
    "tresca_threshold",
];

/// The contact methods' and schemes' numeric parameters: spelled out in a run's label too,
/// and the candidate axes of a stability map ([`super::stability`]).
pub(crate) const METHOD_PARAMS: &[&str] = &[
    "nitsche_theta",
    "nitsche_gamma0",
    "penalty_gamma0",
    "newmark_beta",
    "newmark_gamma",
    "theta_scheme",
    "restitution",
    "rho_inf",
    "hht_alpha",
];

/// The refinement axes: `h` (or `elements`), `dt` (or `courant`).
pub(crate) const REFINEMENT: &[(&str, Kind)] = &columns![
    h: F64, elements: I64, dt: F64, courant: F64,
];

/// The error columns of contract §5, in output order.
pub(crate) const ERRORS: &[&str] = crate::model::ERROR_COLUMNS;

/// Measured columns read besides parameters and errors.
const MEASURED: &[(&str, Kind)] = &columns![
    run_id: Str, label: Str, status: Str, message: Str, wall_time_s: F64, wall_time_min_s: F64,
    wall_time_max_s: F64, repeats: I64, steps: I64, dofs: I64, energy_initial: F64,
    energy_final: F64, energy_drift: F64, energy_max_dev: F64, energy_max_increase: F64,
    energy_theta_max_increase: F64, energy_theta_drift: F64, energy_theta_initial: F64,
    length_scale: F64, energy_scale: F64, search: Str, max_penetration: F64,
    pressure_oscillation: F64, friction_work: F64, energy_balance_drift: F64,
    energy_balance_max_increase: F64, patch_stress_error: F64, patch_pressure_error: F64,
];

/// One parameter value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Cell {
    F64(Option<f64>),
    I64(Option<i64>),
    Str(Option<String>),
}

impl Cell {
    /// The grouping key of a value. Floats are rounded to 11 significant digits so that a
    /// value recomputed in another order (a Courant number derived as c0·dt/h) still matches;
    /// parameters of a sweep differ far above that.
    pub(crate) fn key(&self) -> String {
        match self {
            Cell::F64(Some(x)) if x.is_finite() => format!("{x:.10e}"),
            Cell::F64(Some(x)) => format!("{x}"),
            Cell::I64(Some(i)) => i.to_string(),
            Cell::Str(Some(s)) => format!("'{s}'"),
            _ => "null".into(),
        }
    }

    /// The value as a person reads it (shortest round-trip form of floats; below 1e-4 in
    /// exponent form: `cg_tol=1e-12`, not twelve zeros).
    pub(crate) fn show(&self) -> Option<String> {
        match self {
            Cell::F64(x) => x.map(|x| {
                if x != 0.0 && x.abs() < 1e-4 {
                    format!("{x:e}")
                } else {
                    format!("{x}")
                }
            }),
            Cell::I64(x) => x.map(|x| x.to_string()),
            Cell::Str(x) => x.clone(),
        }
    }
}

/// The key of a refinement value (same rounding as [`Cell::key`]).
pub(crate) fn float_key(x: f64) -> String {
    format!("{x:.10e}")
}

/// One row of `DIR/runs`, reduced to what the summary uses.
#[derive(Debug, Clone)]
pub(crate) struct Run {
    pub run_id: String,
    pub label: String,
    pub status: String,
    pub message: Option<String>,
    /// Aligned with [`Runs::params`].
    pub params: Vec<Cell>,
    pub h: Option<f64>,
    pub elements: Option<i64>,
    pub dt: Option<f64>,
    pub courant: Option<f64>,
    /// Aligned with [`Runs::errors`].
    pub errors: Vec<Option<f64>>,
    pub wall_time_s: Option<f64>,
    pub wall_time_min_s: Option<f64>,
    pub wall_time_max_s: Option<f64>,
    pub repeats: Option<i64>,
    pub steps: Option<i64>,
    pub dofs: Option<i64>,
    pub energy_initial: Option<f64>,
    pub energy_final: Option<f64>,
    pub energy_drift: Option<f64>,
    pub energy_max_dev: Option<f64>,
    pub energy_max_increase: Option<f64>,
    pub energy_theta_max_increase: Option<f64>,
    pub energy_theta_drift: Option<f64>,
    pub energy_theta_initial: Option<f64>,
    /// The body's size (runs column `length_scale`; None in folders of older versions).
    pub length_scale: Option<f64>,
    /// The energy unit of `energy_drift` (runs column `energy_scale`: E⁰ for the bars, m·g·gap
    /// under gravity; None in folders of older versions).
    pub energy_scale: Option<f64>,
    /// Ensemble member index (null outside ensembles).
    pub ensemble_sample: Option<i64>,
    /// Runs columns `max_penetration`, `pressure_oscillation` (None in older folders).
    pub max_penetration: Option<f64>,
    pub pressure_oscillation: Option<f64>,
    /// Runs columns `friction_work` (W_f(T)), `energy_balance_drift` ((E + W_f)(T) − E⁰) and
    /// `energy_balance_max_increase` (largest one-step rise of E + W_f), all over
    /// `energy_scale`; None for frictionless runs and older folders (contract §5).
    pub friction_work: Option<f64>,
    pub energy_balance_drift: Option<f64>,
    pub energy_balance_max_increase: Option<f64>,
    /// Runs columns `patch_stress_error`, `patch_pressure_error` (two bodies with a pressure,
    /// contract §1.10; None elsewhere and in older folders).
    pub patch_stress_error: Option<f64>,
    pub patch_pressure_error: Option<f64>,
    /// The `[search]` whose probe this run is (null for grid runs).
    pub search: Option<String>,
    /// The runs part the row was read from (`series/` holds the run's rows under the same name).
    pub part: Option<String>,
    /// The contact phases the run recorded online (the `impact_*` list columns); None for a
    /// row that observed no step.
    pub impacts: Option<Vec<crate::run::impacts::Phase>>,
    /// The row's part stores the phase lists; false for a row of an older version (the energy
    /// section then finds the phases in `series/`).
    pub impacts_stored: bool,
    /// Index into [`Runs::groups`].
    pub group: usize,
}

impl Run {
    pub(crate) fn ok(&self) -> bool {
        self.status == "ok"
    }

    /// E(T)/E⁰ as every table and the terminal print it ([`energy_ratio`]).
    pub(crate) fn energy_ratio(&self) -> Option<f64> {
        energy_ratio(self.energy_initial, self.energy_final, self.energy_drift)
    }
}

/// E(T)/E⁰ of a run, one definition for the summary, the report and the terminal:
/// 1 + `energy_drift` = 1 + (E(T) − E⁰)/energy_scale. The bars' energy_scale is E⁰, so this is
/// E(T)/E⁰; under gravity E⁰ = 0 (at rest, potential measured from the start) and the plain
/// quotient would be ±∞, while the drift is relative to m·g·gap. Folders without the drift
/// column fall back to the quotient.
pub fn energy_ratio(initial: Option<f64>, last: Option<f64>, drift: Option<f64>) -> Option<f64> {
    drift
        .map(|d| 1.0 + d)
        .or_else(|| initial.zip(last).map(|(a, b)| b / a))
        .filter(|x| x.is_finite())
}

impl Runs {
    /// A run's value of the parameter column `name` (None when the folder lacks the column).
    pub(crate) fn param<'a>(&self, r: &'a Run, name: &str) -> Option<&'a Cell> {
        let j = self.params.iter().position(|(n, _)| *n == name)?;
        r.params.get(j)
    }

    /// A text parameter of a run.
    pub(crate) fn param_str<'a>(&self, r: &'a Run, name: &str) -> Option<&'a str> {
        match self.param(r, name)? {
            Cell::Str(s) => s.as_deref(),
            _ => None,
        }
    }

    /// A numeric parameter of a run.
    pub(crate) fn param_f64(&self, r: &Run, name: &str) -> Option<f64> {
        match self.param(r, name)? {
            Cell::F64(x) => *x,
            Cell::I64(i) => i.map(|i| i as f64),
            Cell::Str(_) => None,
        }
    }
}

/// A method group: runs equal in every parameter except the refinement axes.
#[derive(Debug, Clone)]
pub(crate) struct Group {
    /// Title: the label plus the parameters that vary across the folder but are not in it.
    pub title: String,
    /// Run indices.
    pub runs: Vec<usize>,
    /// Distinct (h, dt) levels.
    pub levels: usize,
}

/// What is fixed along a refinement path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Fixed {
    Courant(f64),
    /// dt/h held (equivalent to a fixed Courant number, c0 being constant in a group), for
    /// runs without a courant column.
    Ratio(f64),
    Dt(f64),
    H(f64),
}

impl Fixed {
    pub(crate) fn name(&self) -> &'static str {
        match self {
            Fixed::Courant(_) => "courant",
            Fixed::Ratio(_) => "dt/h",
            Fixed::Dt(_) => "dt",
            Fixed::H(_) => "h",
        }
    }

    pub(crate) fn value(&self) -> f64 {
        match *self {
            Fixed::Courant(x) | Fixed::Ratio(x) | Fixed::Dt(x) | Fixed::H(x) => x,
        }
    }

    /// The refined axis: h when Courant or dt is held, dt when h is held.
    pub(crate) fn refined(&self) -> &'static str {
        match self {
            Fixed::Courant(_) | Fixed::Ratio(_) | Fixed::Dt(_) => "h",
            Fixed::H(_) => "dt",
        }
    }

    pub(crate) fn describe(&self) -> String {
        let name = self.name();
        format!(
            "{name} = {} fixed, {} refined",
            self.value(),
            self.refined()
        )
    }

    /// The terminal's form: `ν=0.5, h↓` (the Courant number as ν).
    pub(crate) fn short(&self) -> String {
        let name = match self {
            Fixed::Courant(_) => "ν",
            _ => self.name(),
        };
        format!("{name}={}, {}↓", self.value(), self.refined())
    }
}

/// A refinement path: ≥ 2 distinct levels of one group along one axis, coarse → fine.
#[derive(Debug, Clone)]
pub(crate) struct RefPath {
    pub group: usize,
    pub fixed: Fixed,
    /// (refinement value x = h or dt, run index), x strictly decreasing.
    pub levels: Vec<(f64, usize)>,
}

/// The runs of a folder.
#[derive(Debug, Clone)]
pub(crate) struct Runs {
    /// Parameter columns present in the Parquet.
    pub params: Vec<(&'static str, Kind)>,
    /// Error columns present with at least one value.
    pub errors: Vec<&'static str>,
    pub runs: Vec<Run>,
    pub groups: Vec<Group>,
    pub paths: Vec<RefPath>,
    /// Columns of the Parquet this version does not know (ignored).
    pub ignored: Vec<String>,
    /// Duplicate rows of one run_id dropped (a run committed by two shards).
    pub duplicates: usize,
    /// The folder had no `status` column: every run counted as ok.
    pub status_assumed: bool,
}

impl Runs {
    /// Parameter columns as declared output columns.
    pub(crate) fn param_columns(&self) -> Vec<(String, Kind)> {
        self.params
            .iter()
            .map(|(n, k)| (n.to_string(), *k))
            .collect()
    }

    /// Parameters that vary across the folder, excluding those in the label.
    fn varying(&self) -> Vec<usize> {
        (0..self.params.len())
            .filter(|&i| {
                let name = &self.params[i].0;
                !IN_LABEL.contains(name) && !METHOD_PARAMS.contains(name)
            })
            .filter(|&i| self.params[i].0 != "ensemble_sample")
            .filter(|&i| {
                let keys: HashSet<String> = self.runs.iter().map(|r| r.params[i].key()).collect();
                keys.len() > 1
            })
            .collect()
    }
}

fn dtype(kind: Kind) -> DataType {
    match kind {
        Kind::F64 => DataType::Float64,
        Kind::I64 => DataType::Int64,
        Kind::Str => DataType::String,
        Kind::Bool => DataType::Boolean,
    }
}

/// Whether a stored column can be read (a non-strict cast turns unparsable values into nulls;
/// nested types are not read).
fn castable(found: &DataType) -> bool {
    // Every scalar type casts to every kind read here (numbers to text for string columns,
    // text to numbers for numeric ones, unparsable → null).
    found.is_primitive_numeric() || found.is_bool() || found.is_string() || found.is_null()
}

/// The column [`read_parts`] adds to name the part file each row came from.
pub(crate) const PART_COLUMN: &str = "__part";

/// The column [`read_parts`] adds, when asked for list columns: whether the row's part stores
/// every one of them (a part of this version, even if a row's lists are null).
const LISTS_COLUMN: &str = "__lists";

/// Read the committed Parquet parts of `folder` (all, or those named in `only`), keeping only
/// the `known` columns, each cast to the type this version expects, and the `lists` (list
/// columns, read when the stored column is a list of numbers, cast to the given list type);
/// concatenate them diagonally (a column missing from a part is null there). Every row carries
/// the file name of its part in [`PART_COLUMN`]: the sink writes `runs/NAME` and `series/NAME`
/// per batch, so a run's part names its series part too. Returns the frame and the columns
/// that were not read.
///
/// Why not `sink::read_runs`: it concatenates the parts as stored, which fails when two
/// versions stored a column with different types (`repeats` as i32 and i64, `elements` as
/// integer and float) or a foreign column differs between parts; casting each part first
/// makes the union always well-typed.
pub(crate) fn read_parts(
    folder: &Path,
    known: &[(&'static str, DataType)],
    lists: &[(&'static str, DataType)],
    only: Option<&HashSet<String>>,
) -> anyhow::Result<(DataFrame, Vec<String>)> {
    use rayon::prelude::*;
    // Parts are read on every core (a runs folder is many small parts: 25 for issue 12's
    // 400-run sweep, each a few hundred columns of a few rows, where polars' per-file cost
    // dominates), then stacked in file order.
    let parts = crate::sink::parquet_parts(folder)?;
    let read = parts
        .par_iter()
        .map(|part| -> anyhow::Result<Option<(LazyFrame, Vec<String>)>> {
            let mut ignored: Vec<String> = Vec::new();
            let name = part
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            if only.is_some_and(|o| !o.contains(&name)) {
                return Ok(None);
            }
            let file = std::fs::File::open(part).with_context(|| format!("{}", part.display()))?;
            let mut reader = ParquetReader::new(file);
            // An unreadable part is skipped: `summarize` warns about it (sink::unreadable_parts).
            let Ok(schema) = reader.schema() else {
                return Ok(None);
            };
            let stored: Vec<String> = schema.iter_names().map(|n| n.to_string()).collect();
            let is_known = |n: &str| known.iter().chain(lists).any(|(k, _)| *k == n);
            // Read only the known columns (a series part can be large; the rest is never loaded).
            let wanted: Vec<String> = stored.iter().filter(|n| is_known(n)).cloned().collect();
            let raw = match reader.with_columns(Some(wanted)).finish() {
                Ok(raw) => raw,
                Err(_) => return Ok(None),
            };
            let schema = raw.schema().clone();
            let list_ok = |n: &str| {
                lists.iter().any(|(k, _)| *k == n)
                    && schema.get(n).is_some_and(|t| match t {
                        DataType::List(inner) => inner.is_primitive_numeric() || inner.is_null(),
                        _ => false,
                    })
            };
            for name in &stored {
                let usable = schema.get(name).is_some_and(castable) || list_ok(name);
                if !usable {
                    ignored.push(name.clone());
                }
            }
            let mut exprs: Vec<Expr> = known
                .iter()
                .filter(|(n, _)| schema.get(n).is_some_and(castable))
                .map(|(n, t)| col(*n).cast(t.clone()))
                .collect();
            exprs.extend(
                lists
                    .iter()
                    .filter(|(n, _)| list_ok(n))
                    .map(|(n, t)| col(*n).cast(t.clone())),
            );
            if exprs.is_empty() {
                return Ok(None);
            }
            exprs.push(lit(name.as_str()).alias(PART_COLUMN));
            if !lists.is_empty() {
                let all = lists.iter().all(|(n, _)| list_ok(n));
                exprs.push(lit(all).alias(LISTS_COLUMN));
            }
            Ok(Some((raw.lazy().select(exprs), ignored)))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut ignored: Vec<String> = Vec::new();
    let mut frames = Vec::new();
    for (frame, names) in read.into_iter().flatten() {
        for n in names {
            if !ignored.contains(&n) {
                ignored.push(n);
            }
        }
        frames.push(frame);
    }
    if frames.is_empty() {
        return Ok((DataFrame::empty(), ignored));
    }
    let df = concat_lf_diagonal(frames, UnionArgs::default())
        .and_then(|lf| lf.collect())
        .map_err(anyhow::Error::new)
        .with_context(|| format!("{}: reading the parts", folder.display()))?;
    Ok((df, ignored))
}

fn f64s(df: &DataFrame, name: &str) -> anyhow::Result<Option<Vec<Option<f64>>>> {
    match df.column(name) {
        Ok(c) => Ok(Some(c.f64()?.iter().collect())),
        Err(_) => Ok(None),
    }
}

fn i64s(df: &DataFrame, name: &str) -> anyhow::Result<Option<Vec<Option<i64>>>> {
    match df.column(name) {
        Ok(c) => Ok(Some(c.i64()?.iter().collect())),
        Err(_) => Ok(None),
    }
}

fn strs(df: &DataFrame, name: &str) -> anyhow::Result<Option<Vec<Option<String>>>> {
    match df.column(name) {
        Ok(c) => Ok(Some(
            c.str()?.iter().map(|s| s.map(str::to_string)).collect(),
        )),
        Err(_) => Ok(None),
    }
}

/// The runs table's list columns of the contact phases (issue 12), in [`Phase`] field order;
/// `true`: Int64 elements.
///
/// [`Phase`]: crate::run::impacts::Phase
const IMPACT_COLUMNS: &[(&str, bool)] = &[
    ("impact_step_first", true),
    ("impact_step_last", true),
    ("impact_t_first", false),
    ("impact_t_last", false),
    ("impact_energy_before", false),
    ("impact_energy_after", false),
    ("impact_energy_theta_before", false),
    ("impact_energy_theta_after", false),
];

/// Each row's contact phases, from the `impact_*` list columns: None for the whole frame
/// when a column is missing, None for a row whose lists are null or of unequal lengths (a row
/// this version did not write).
#[allow(clippy::type_complexity)]
fn impact_lists(
    df: &DataFrame,
) -> anyhow::Result<Option<Vec<Option<Vec<crate::run::impacts::Phase>>>>> {
    if IMPACT_COLUMNS.iter().any(|(n, _)| df.column(n).is_err()) {
        return Ok(None);
    }
    let ints = |n: &str| -> anyhow::Result<Vec<Option<Vec<i64>>>> {
        let ca = df.column(n)?.list()?.clone();
        Ok((0..ca.len())
            .map(|i| {
                let s = ca.get_as_series(i)?;
                s.i64().ok().map(|c| c.iter().flatten().collect())
            })
            .collect())
    };
    let floats = |n: &str| -> anyhow::Result<Vec<Option<Vec<Option<f64>>>>> {
        let ca = df.column(n)?.list()?.clone();
        Ok((0..ca.len())
            .map(|i| {
                let s = ca.get_as_series(i)?;
                s.f64().ok().map(|c| c.iter().collect())
            })
            .collect())
    };
    let (first, last) = (ints("impact_step_first")?, ints("impact_step_last")?);
    let fl: Vec<_> = IMPACT_COLUMNS[2..]
        .iter()
        .map(|(n, _)| floats(n))
        .collect::<anyhow::Result<_>>()?;
    let out = (0..df.height())
        .map(|i| {
            let (f, l) = (first[i].as_ref()?, last[i].as_ref()?);
            let cols: Vec<&Vec<Option<f64>>> =
                fl.iter().map(|c| c[i].as_ref()).collect::<Option<_>>()?;
            let n = f.len();
            if l.len() != n || cols.iter().any(|c| c.len() != n) {
                return None;
            }
            Some(
                (0..n)
                    .map(|k| crate::run::impacts::Phase {
                        step_first: f[k],
                        step_last: l[k],
                        t_first: cols[0][k].unwrap_or(f64::NAN),
                        t_last: cols[1][k].unwrap_or(f64::NAN),
                        energy_before: cols[2][k],
                        energy_after: cols[3][k],
                        energy_theta_before: cols[4][k],
                        energy_theta_after: cols[5][k],
                    })
                    .collect(),
            )
        })
        .collect();
    Ok(Some(out))
}

/// Read and group the runs of `dir`.
pub(crate) fn load(dir: &Path) -> anyhow::Result<Runs> {
    if !dir.is_dir() {
        bail!(
            "{}: no such folder (expected a results folder with runs/)",
            dir.display()
        );
    }
    let (df, ignored) = read_runs_frame(dir)?;
    let n = df.height();
    let cols = RunColumns::read(&df)?;
    let mut seen: HashSet<String> = HashSet::new();
    let mut duplicates = 0;
    let mut runs = Vec::with_capacity(n);
    for i in 0..n {
        // A run without an id (another version) still counts; it gets its row number.
        let id = cols
            .run_id
            .as_ref()
            .and_then(|v| v[i].clone())
            .unwrap_or_else(|| format!("row-{i}"));
        if !seen.insert(id.clone()) {
            // The same run committed twice (two shards, a re-run): same id, same parameters.
            duplicates += 1;
            continue;
        }
        runs.push(cols.run(i, id));
    }
    let mut out = Runs {
        params: cols.params,
        errors: cols.errors,
        runs,
        groups: Vec::new(),
        paths: Vec::new(),
        ignored,
        duplicates,
        status_assumed: cols.status_assumed,
    };
    group(&mut out);
    Ok(out)
}

/// The committed parts of `DIR/runs` as one frame of the known columns and the impact lists,
/// and the stored columns neither this version's schema nor the summary knows. Errors: no
/// committed part.
fn read_runs_frame(dir: &Path) -> anyhow::Result<(DataFrame, Vec<String>)> {
    let known: Vec<(&'static str, Kind)> = MEASURED
        .iter()
        .chain(PARAMS)
        .chain(REFINEMENT)
        .copied()
        .chain(ERRORS.iter().map(|e| (*e, Kind::F64)))
        .collect();
    let known: Vec<(&'static str, DataType)> = known.iter().map(|(n, k)| (*n, dtype(*k))).collect();
    let list = |t: DataType| DataType::List(Box::new(t));
    let lists: Vec<(&'static str, DataType)> = IMPACT_COLUMNS
        .iter()
        .map(|&(n, int)| {
            (
                n,
                list(if int {
                    DataType::Int64
                } else {
                    DataType::Float64
                }),
            )
        })
        .collect();
    let (df, mut ignored) = read_parts(&dir.join("runs"), &known, &lists, None)?;
    // Columns of this version's own schema that the summary does not need are not foreign.
    ignored.retain(|n| !crate::run::RunRecord::COLUMNS.iter().any(|c| c.0 == n));
    if df.height() == 0 {
        bail!(
            "{}: no runs to summarize: {} holds no committed *.parquet part (is this a contact-sweep output folder?)",
            dir.display(),
            dir.join("runs").display()
        );
    }
    Ok((df, ignored))
}

/// A finite value (NaN and ±∞ read as missing).
fn finite(x: Option<f64>) -> Option<f64> {
    x.filter(|x| x.is_finite())
}

/// The columns of the runs frame the summary reads, one value per row (a column the folder
/// lacks: None in every row; a text column: None as a whole).
struct RunColumns {
    run_id: Option<Vec<Option<String>>>,
    label: Option<Vec<Option<String>>>,
    status: Option<Vec<Option<String>>>,
    status_assumed: bool,
    message: Option<Vec<Option<String>>>,
    /// The parameter columns present, and their values (aligned).
    params: Vec<(&'static str, Kind)>,
    param_values: Vec<Vec<Cell>>,
    /// The error columns with a value, and their values (aligned).
    errors: Vec<&'static str>,
    error_values: Vec<Vec<Option<f64>>>,
    h: Vec<Option<f64>>,
    elements: Vec<Option<i64>>,
    dt: Vec<Option<f64>>,
    courant: Vec<Option<f64>>,
    wt: Vec<Option<f64>>,
    wt_min: Vec<Option<f64>>,
    wt_max: Vec<Option<f64>>,
    repeats: Vec<Option<i64>>,
    steps: Vec<Option<i64>>,
    dofs: Vec<Option<i64>>,
    theta_drift: Vec<Option<f64>>,
    theta_initial: Vec<Option<f64>>,
    length_scale: Vec<Option<f64>>,
    energy_scale: Vec<Option<f64>>,
    max_pen: Vec<Option<f64>>,
    press_osc: Vec<Option<f64>>,
    w_f: Vec<Option<f64>>,
    balance_drift: Vec<Option<f64>>,
    balance_inc: Vec<Option<f64>>,
    patch: [Vec<Option<f64>>; 2],
    sample: Vec<Option<i64>>,
    search: Option<Vec<Option<String>>>,
    e_init: Vec<Option<f64>>,
    e_fin: Vec<Option<f64>>,
    drift: Vec<Option<f64>>,
    max_dev: Vec<Option<f64>>,
    max_inc: Vec<Option<f64>>,
    theta_inc: Vec<Option<f64>>,
    part: Option<Vec<Option<String>>>,
    impacts: Option<Vec<Option<Vec<crate::run::impacts::Phase>>>>,
    stored: Option<Vec<Option<bool>>>,
}

impl RunColumns {
    /// Read every column of `df` the summary uses, each cast to the type this version expects.
    fn read(df: &DataFrame) -> anyhow::Result<RunColumns> {
        let n = df.height();
        let run_id = strs(df, "run_id")?;
        let label = strs(df, "label")?;
        let status = strs(df, "status")?;
        let status_assumed = status.is_none();
        let message = strs(df, "message")?;
        let get_f = |name: &str| -> anyhow::Result<Vec<Option<f64>>> {
            Ok(f64s(df, name)?.unwrap_or_else(|| vec![None; n]))
        };
        let get_i = |name: &str| -> anyhow::Result<Vec<Option<i64>>> {
            Ok(i64s(df, name)?.unwrap_or_else(|| vec![None; n]))
        };
        let params: Vec<(&'static str, Kind)> = PARAMS
            .iter()
            .filter(|(name, _)| df.column(name).is_ok())
            .copied()
            .collect();
        let mut param_values: Vec<Vec<Cell>> = Vec::with_capacity(params.len());
        for (name, kind) in &params {
            let v: Vec<Cell> = match kind {
                Kind::F64 => get_f(name)?.into_iter().map(Cell::F64).collect(),
                Kind::I64 => get_i(name)?.into_iter().map(Cell::I64).collect(),
                _ => strs(df, name)?
                    .unwrap_or_else(|| vec![None; n])
                    .into_iter()
                    .map(Cell::Str)
                    .collect(),
            };
            param_values.push(v);
        }
        let mut errors: Vec<&'static str> = Vec::new();
        let mut error_values: Vec<Vec<Option<f64>>> = Vec::new();
        for e in ERRORS {
            if let Some(v) = f64s(df, e)?
                && v.iter().any(|x| x.is_some_and(|x| !x.is_nan()))
            {
                errors.push(e);
                error_values.push(v);
            }
        }
        let (h, elements, dt, courant) = (
            get_f("h")?,
            get_i("elements")?,
            get_f("dt")?,
            get_f("courant")?,
        );
        let (wt, wt_min, wt_max) = (
            get_f("wall_time_s")?,
            get_f("wall_time_min_s")?,
            get_f("wall_time_max_s")?,
        );
        let (repeats, steps, dofs) = (get_i("repeats")?, get_i("steps")?, get_i("dofs")?);
        let theta_drift = get_f("energy_theta_drift")?;
        let theta_initial = get_f("energy_theta_initial")?;
        let length_scale = get_f("length_scale")?;
        let energy_scale = get_f("energy_scale")?;
        let (max_pen, press_osc) = (get_f("max_penetration")?, get_f("pressure_oscillation")?);
        let (w_f, balance_drift, balance_inc) = (
            get_f("friction_work")?,
            get_f("energy_balance_drift")?,
            get_f("energy_balance_max_increase")?,
        );
        let patch = [get_f("patch_stress_error")?, get_f("patch_pressure_error")?];
        let sample = get_i("ensemble_sample")?;
        let search = strs(df, "search")?;
        let (e_init, e_fin, drift, max_dev, max_inc, theta_inc) = (
            get_f("energy_initial")?,
            get_f("energy_final")?,
            get_f("energy_drift")?,
            get_f("energy_max_dev")?,
            get_f("energy_max_increase")?,
            get_f("energy_theta_max_increase")?,
        );
        let part = strs(df, PART_COLUMN)?;
        let impacts = impact_lists(df)?;
        let stored: Option<Vec<Option<bool>>> = df
            .column(LISTS_COLUMN)
            .ok()
            .map(|c| c.bool().map(|b| b.iter().collect()))
            .transpose()?;
        Ok(RunColumns {
            run_id,
            label,
            status,
            status_assumed,
            message,
            params,
            param_values,
            errors,
            error_values,
            h,
            elements,
            dt,
            courant,
            wt,
            wt_min,
            wt_max,
            repeats,
            steps,
            dofs,
            theta_drift,
            theta_initial,
            length_scale,
            energy_scale,
            max_pen,
            press_osc,
            w_f,
            balance_drift,
            balance_inc,
            patch,
            sample,
            search,
            e_init,
            e_fin,
            drift,
            max_dev,
            max_inc,
            theta_inc,
            part,
            impacts,
            stored,
        })
    }

    /// Row `i` as a run named `id` (group 0 until [`group`] assigns it).
    fn run(&self, i: usize, id: String) -> Run {
        let params_i: Vec<Cell> = self.param_values.iter().map(|v| v[i].clone()).collect();
        let lbl = self.label_of(i, &params_i);
        let h_i = self.h_of(i, &params_i);
        Run {
            run_id: id,
            label: lbl,
            status: match &self.status {
                Some(v) => v[i].clone().unwrap_or_else(|| "unknown".into()),
                None => "ok".into(),
            },
            message: self.message.as_ref().and_then(|v| v[i].clone()),
            params: params_i,
            h: h_i,
            elements: self.elements[i].filter(|m| *m > 0),
            dt: finite(self.dt[i]).filter(|x| *x > 0.0),
            courant: finite(self.courant[i]).filter(|x| *x > 0.0),
            errors: self.error_values.iter().map(|v| v[i]).collect(),
            wall_time_s: finite(self.wt[i]),
            wall_time_min_s: finite(self.wt_min[i]),
            wall_time_max_s: finite(self.wt_max[i]),
            repeats: self.repeats[i],
            steps: self.steps[i],
            dofs: self.dofs[i],
            energy_initial: self.e_init[i],
            energy_final: self.e_fin[i],
            energy_drift: self.drift[i],
            energy_max_dev: self.max_dev[i],
            energy_max_increase: self.max_inc[i],
            energy_theta_max_increase: self.theta_inc[i],
            energy_theta_drift: self.theta_drift[i],
            energy_theta_initial: self.theta_initial[i],
            length_scale: finite(self.length_scale[i]).filter(|l| *l > 0.0),
            energy_scale: finite(self.energy_scale[i]).filter(|e| *e > 0.0),
            ensemble_sample: self.sample[i],
            max_penetration: finite(self.max_pen[i]),
            pressure_oscillation: finite(self.press_osc[i]),
            friction_work: self.w_f[i],
            energy_balance_drift: self.balance_drift[i],
            energy_balance_max_increase: self.balance_inc[i],
            patch_stress_error: finite(self.patch[0][i]),
            patch_pressure_error: finite(self.patch[1][i]),
            search: self.search.as_ref().and_then(|v| v[i].clone()),
            part: self.part.as_ref().and_then(|v| v[i].clone()),
            impacts: self.impacts.as_ref().and_then(|v| v[i].clone()),
            impacts_stored: self.stored.as_ref().and_then(|v| v[i]).unwrap_or(false),
            group: 0,
        }
    }

    /// Row `i`'s label; without a label column, one composed from the method parameters that
    /// exist (`params_i`: the row's parameter values).
    fn label_of(&self, i: usize, params_i: &[Cell]) -> String {
        self.label
            .as_ref()
            .and_then(|v| v[i].clone())
            .unwrap_or_else(|| {
                // No label column: compose one from the method parameters that exist.
                let pick = |name: &str| {
                    self.params
                        .iter()
                        .position(|(n, _)| *n == name)
                        .and_then(|j| params_i[j].show())
                };
                [
                    pick("space"),
                    pick("mass"),
                    pick("scheme_label").or(pick("scheme")),
                ]
                .into_iter()
                .flatten()
                .collect::<Vec<_>>()
                .join(" · ")
            })
    }

    /// Row `i`'s h: h is always filled by this version (contract §8); an older row with only
    /// `elements` gets h = length / elements.
    fn h_of(&self, i: usize, params_i: &[Cell]) -> Option<f64> {
        finite(self.h[i]).filter(|x| *x > 0.0).or_else(|| {
            let m = self.elements[i].filter(|m| *m > 0)? as f64;
            let j = self.params.iter().position(|(n, _)| *n == "length")?;
            match params_i[j] {
                Cell::F64(Some(l)) if l > 0.0 => Some(l / m),
                _ => None,
            }
        })
    }
}

/// Group the runs and find the refinement paths of every group.
fn group(r: &mut Runs) {
    let varying = r.varying();
    // Ensemble members are one method: the sample index is not part of a group's identity.
    let sample_col = r.params.iter().position(|(n, _)| *n == "ensemble_sample");
    let mut by_key: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (i, run) in r.runs.iter().enumerate() {
        let key = run
            .params
            .iter()
            .enumerate()
            .filter(|(j, _)| Some(*j) != sample_col)
            .map(|(_, c)| c.key())
            .collect::<Vec<_>>()
            .join("|");
        by_key.entry(key).or_default().push(i);
    }
    let mut groups: Vec<(String, String, Vec<usize>)> = by_key
        .into_iter()
        .map(|(key, idx)| {
            let first = &r.runs[idx[0]];
            let extra: Vec<String> = varying
                .iter()
                .filter_map(|&j| {
                    first.params[j]
                        .show()
                        .map(|v| format!("{}={v}", r.params[j].0))
                })
                .collect();
            let title = if extra.is_empty() {
                first.label.clone()
            } else {
                format!("{} [{}]", first.label, extra.join(", "))
            };
            (title, key, idx)
        })
        .collect();
    // Deterministic order: by title, then by the full key.
    groups.sort_by(|a, b| (&a.0, &a.1).cmp(&(&b.0, &b.1)));
    // Two groups with the same title (a parameter the label does not show and that does not
    // vary as a whole) get a number so the tables stay distinguishable.
    let mut count: BTreeMap<String, usize> = BTreeMap::new();
    for g in &groups {
        *count.entry(g.0.clone()).or_default() += 1;
    }
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    for (gi, (title, _, idx)) in groups.into_iter().enumerate() {
        let title = if count[&title] > 1 {
            let k = seen.entry(title.clone()).or_default();
            *k += 1;
            format!("{title} (#{k})")
        } else {
            title
        };
        let levels: HashSet<(String, String)> = idx
            .iter()
            .map(|&i| {
                let run = &r.runs[i];
                (opt_key(run.h), opt_key(run.dt))
            })
            .collect();
        for &i in &idx {
            r.runs[i].group = gi;
        }
        r.paths.extend(paths_of(&r.runs, gi, &idx));
        r.groups.push(Group {
            title,
            runs: idx,
            levels: levels.len(),
        });
    }
}

fn opt_key(x: Option<f64>) -> String {
    x.map(float_key).unwrap_or_else(|| "null".into())
}

/// The refinement paths of one group: Courant held (h refined), dt held (h refined), h held
/// (dt refined); each with ≥ 2 distinct levels. A fixed Courant number is detected as a fixed
/// dt/h (the wave speed c0 is a function of the group's parameters), so rows of a version
/// without the courant column still join their path; the path is labelled by the Courant
/// number when every level reports the same one.
fn paths_of(runs: &[Run], group: usize, idx: &[usize]) -> Vec<RefPath> {
    let mut out = Vec::new();
    type Axis = fn(&Run) -> Option<f64>;
    type Make = fn(f64) -> Fixed;
    let axes: [(Axis, Axis, Make); 3] = [
        (|r| Some(r.dt? / r.h?), |r| r.h, Fixed::Ratio),
        (|r| r.dt, |r| r.h, Fixed::Dt),
        (|r| r.h, |r| r.dt, Fixed::H),
    ];
    for (held, refined, make) in axes {
        let mut sub: BTreeMap<String, (f64, Vec<usize>)> = BTreeMap::new();
        for &i in idx {
            if let (Some(f), Some(_)) = (held(&runs[i]), refined(&runs[i])) {
                sub.entry(float_key(f)).or_insert((f, Vec::new())).1.push(i);
            }
        }
        let mut found: Vec<RefPath> = Vec::new();
        for (_, (f, members)) in sub {
            // One run per level. Ensemble members share a level: the ok member of lowest
            // sample index represents it (the spread over the members is the ensemble
            // table's business); otherwise two runs share a level only when another version
            // hashed differently, and an ok one wins.
            let mut levels: BTreeMap<String, (f64, usize)> = BTreeMap::new();
            for i in members {
                let x = refined(&runs[i]).expect("filtered above");
                let e = levels.entry(float_key(x)).or_insert((x, i));
                let rank = |r: &Run| (!r.ok(), r.ensemble_sample.unwrap_or(-1));
                if rank(&runs[i]) < rank(&runs[e.1]) {
                    *e = (x, i);
                }
            }
            if levels.len() < 2 {
                continue;
            }
            let mut lv: Vec<(f64, usize)> = levels.into_values().collect();
            // Coarse → fine.
            lv.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut fixed = make(f);
            if let Fixed::Ratio(_) = fixed {
                let c: HashSet<Option<String>> = lv
                    .iter()
                    .map(|&(_, i)| runs[i].courant.map(float_key))
                    .collect();
                if let (1, Some(c)) = (c.len(), lv.first().and_then(|&(_, i)| runs[i].courant)) {
                    fixed = Fixed::Courant(c);
                }
            }
            found.push(RefPath {
                group,
                fixed,
                levels: lv,
            });
        }
        found.sort_by(|a, b| a.fixed.value().total_cmp(&b.fixed.value()));
        out.extend(found);
    }
    out
}

/// Title of a group with its index, as the tables show it.
pub(crate) fn group_heading(runs: &Runs, g: usize) -> String {
    format!("group {}: {}", g + 1, runs.groups[g].title)
}
