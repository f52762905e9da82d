//! Energy tables: per run and per group (drift, largest deviation, largest one-step increase,
//! and the run's energy class), and the energy lost at each impact: from the contact phases
//! each run found at every step (the runs table's `impact_*` lists, [`crate::run::impacts`]),
//! or, for rows of older versions without them, from the time series (resolved to its
//! recording stride; `series_decimated`/`series_stride` say so, stride 1 for online phases).
//!
//! # Energy classes
//! Every run is classified by the energy functional F its scheme controls — E_Θ for Nitsche
//! (003 §2.3; E^h itself may rise within a step although the scheme is stable), E^h plus the
//! penalty potential for penalty (the `energy` column already holds it), E^h otherwise — into
//! `conservative`, `dissipative`, `growing` or `diverged` (status `diverged`; the other non-ok
//! statuses are carried as the class). With the relative drift d = (F^N − F⁰)/F⁰ and
//!
//! ```text
//!     δ = max(h, c0 τ) / L = max(1, ν) · h / L
//! ```
//!
//! (L the run's `length_scale`: the bar's length, the disc's or ball's diameter; the oscillator,
//! which has no mesh, δ = c0τ = ωτ), a run is growing if d > δ, dissipative if d < −δ, conservative otherwise. δ is the consistency error of the contact discretisation:
//! the contact node is resolved to one cell and one step, and the energy it exchanges over an
//! impact is exact only up to O(max(h, c0τ)) — mod3 + CN, whose energy is conserved up to
//! that error, moves by up to 0.31 δ on the quickstart ladder (+3.9 % at h = 1/8, ν = 1),
//! while an ill-posed method (consistent mass or Nitsche with γ0 → 0, with CN) gains 15 % to
//! 1100 %, far above δ at every h. For the schemes with a proven non-increasing functional —
//! the hybrid with Nitsche Θ = 1 and E_Θ (003 Cor 3.8), the 000 §5 hybrid (mixed, massless
//! contact node) and E^h (Lemma 5.1), backward Euler with Nitsche Θ = 1 and E_Θ (003 Cor 3.2),
//! and the methods of contract §3.2 with a proof (kane with inertia on the contact node,
//! contact-stabilized Newmark, Moreau–Jean with θ = ½ and e = 1, the discrete gradient)
//! — a single step that raises F by more than [`ENERGY_TOL`]·F⁰ is growth as well: the proof
//! forbids it, and rounding stays below 1e-12 (contract §6).
//!
//! # Frictional runs
//! With `friction` ≠ `none` the energy alone says nothing about the scheme: E falls by the
//! frictional work W_f ≥ 0 whatever the method (0.16 E⁰ on the layer's slip regime, contract §6),
//! so every frictional run would read `dissipative`. Such runs are judged by the balance
//! F + W_f instead (contract §5's `energy_balance_drift`, `energy_balance_max_increase`; F is the
//! `energy` column, which holds the penalty potential for penalty): growing if it rises by
//! more than δ (or, for the methods contract §2.5 proves never raise E + W_f — `kane` with inertia
//! on the contact node, `moreau-jean` with θ = ½ and e = 1 — one step by more than
//! [`ENERGY_TOL`]), dissipative if it falls by more than δ (energy lost besides the friction's
//! work: the scheme's own dissipation), and otherwise [`FRICTION_ACCOUNTED`] when E itself
//! falls by more than δ and the friction did more than δ of work — the fall is the friction's
//! work — or conservative (a stuck base
//! does no work). δ is the same consistency error: the tangential exchange happens at the
//! same contact node, resolved to one cell and one step.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::fmt::Write as _;

use super::columns::columns;
use super::runs::{Run, Runs};
use super::table::{self, Table, TextTable, text_columns};

/// A one-step increase of a provably non-increasing functional above this fraction of its
/// initial value is growth. Contract §6: the schemes that provably do not gain energy stay below
/// 1e-12·E⁰ (worst seen 5e-13), so 1e-10 leaves two decades for rounding.
pub const ENERGY_TOL: f64 = 1e-10;

/// The class of a frictional run whose E + W_f stays within δ while E falls by more than δ:
/// the energy lost is the friction's work, not the scheme's (module header).
pub const FRICTION_ACCOUNTED: &str = "dissipative with friction accounted";

/// The energy classes, in the order tables list them.
pub const CLASSES: [&str; 5] = [
    "conservative",
    FRICTION_ACCOUNTED,
    "dissipative",
    "growing",
    "diverged",
];

/// The run has a friction law (`friction` ≠ `none`) and its row the energy balance.
pub(crate) fn frictional(runs: &Runs, r: &Run) -> bool {
    let law = runs.param_str(r, "friction").is_some_and(|f| f != "none");
    // The oscillator's dry friction is its `friction_force` (contract §1.5), not a `friction` law.
    let dry = runs.param_f64(r, "friction_force").is_some_and(|f| f > 0.0);
    (law || dry) && r.energy_balance_drift.is_some()
}

/// How a run's energy behaved, judged by its scheme's functional.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct EnergyClass {
    /// conservative | dissipative | growing | diverged, or the run's status when it ended
    /// otherwise (solver-failed, invalid, timeout); None when the row has no energies.
    pub class: Option<String>,
    /// Which functional: "E_Θ", "E^h + penalty", "E^h".
    pub functional: &'static str,
    pub drift: Option<f64>,
    pub max_increase: Option<f64>,
    /// δ = max(1, ν)·h/L.
    pub tolerance: Option<f64>,
    /// The functional provably never increases for this method and scheme.
    pub monotone: bool,
}

/// Classify one run (see the module header).
pub(crate) fn classify(runs: &Runs, r: &Run) -> EnergyClass {
    let space = runs.param_str(r, "space").unwrap_or("");
    let scheme = runs.param_str(r, "scheme").unwrap_or("");
    let scheme_label = runs.param_str(r, "scheme_label").unwrap_or("");
    let hybrid = scheme == "hybrid" || scheme_label == "hybrid";
    let backward_euler = scheme_label == "backward-euler";
    let theta = runs.param_f64(r, "nitsche_theta");
    let theta_scheme = runs.param_f64(r, "theta_scheme");
    let friction = frictional(runs, r);
    let (functional, drift, max_increase) = match space {
        // The `energy` column already holds the penalty potential (contract §5).
        "penalty" if friction => (
            "E^h + penalty + W_f",
            r.energy_balance_drift,
            r.energy_balance_max_increase,
        ),
        _ if friction => (
            "E^h + W_f",
            r.energy_balance_drift,
            r.energy_balance_max_increase,
        ),
        "nitsche" if r.energy_theta_drift.is_some() => {
            ("E_Θ", r.energy_theta_drift, r.energy_theta_max_increase)
        }
        "penalty" => ("E^h + penalty", r.energy_drift, r.energy_max_increase),
        _ => ("E^h", r.energy_drift, r.energy_max_increase),
    };
    let nitsche_theta_one = space == "nitsche" && theta == Some(1.0) && functional == "E_Θ";
    // contract §3.2: kane (contact node with inertia), contact-stabilized Newmark, Moreau–Jean with
    // θ = ½ and e = 1 (the impulses do no work; e < 1 may gain on a separating active row, see
    // tests/properties.rs) never increase E^h; the discrete gradient conserves its functional.
    let with_inertia = matches!(runs.param_str(r, "mass"), Some("consistent" | "lumped"));
    let comparison = (scheme == "kane" && with_inertia)
        || scheme == "contact-stabilized-newmark"
        || (scheme == "moreau-jean"
            && theta_scheme == Some(0.5)
            && runs.param_f64(r, "restitution") == Some(1.0))
        || (scheme == "discrete-gradient" && (space == "penalty" || nitsche_theta_one));
    // With friction only what contract §2.5 states of E + W_f: kane with inertia and Moreau–Jean
    // (θ = ½; e = 1 as without friction, e < 1 may gain on a separating row) never raise it.
    // The other proofs are of the frictionless functional and say nothing of the balance.
    let monotone = if friction {
        (scheme == "kane" && with_inertia)
            || (scheme == "moreau-jean"
                && theta_scheme == Some(0.5)
                && runs.param_f64(r, "restitution") == Some(1.0))
    } else {
        (hybrid && (space == "mixed" || nitsche_theta_one))
            || ((backward_euler || scheme == "theta" && theta_scheme == Some(1.0))
                && nitsche_theta_one)
            || comparison
    };
    // The run's own length scale; folders of older versions: the bar's `length`, else 1.
    let length = r.length_scale.unwrap_or_else(|| {
        runs.param_f64(r, "length")
            .filter(|l| *l > 0.0)
            .unwrap_or(1.0)
    });
    // The oscillator has no mesh (its h = 1 is a placeholder, which made δ = 1: every run
    // within E⁰ of its start read conservative, its dry friction's fall included): δ is its
    // step's alone, c0τ/L = ωτ, its courant (module header).
    let tolerance = if runs.param_str(r, "scene") == Some("oscillator") {
        r.courant
    } else {
        r.h.map(|h| r.courant.unwrap_or(1.0).max(1.0) * h / length)
    };
    let class = match r.status.as_str() {
        "ok" => match (drift, tolerance) {
            (Some(d), Some(tol)) => Some(
                if d > tol || (monotone && max_increase.is_some_and(|m| m > ENERGY_TOL)) {
                    "growing"
                } else if d < -tol {
                    "dissipative"
                } else if friction
                    && r.energy_drift.is_some_and(|e| e < -tol)
                    && r.friction_work.is_some_and(|w| w > tol)
                {
                    FRICTION_ACCOUNTED
                } else {
                    "conservative"
                }
                .to_string(),
            ),
            _ => None,
        },
        other => Some(other.to_string()),
    };
    EnergyClass {
        class,
        functional,
        drift,
        max_increase,
        tolerance,
        monotone,
    }
}

/// One contact phase of a run.
#[derive(Debug, Clone)]
struct Impact {
    first: usize,
    last: usize,
    before: Option<usize>,
    after: Option<usize>,
}

/// The rows of one run's series, ordered by step.
#[derive(Debug, Default, Clone)]
struct Series {
    step: Vec<i64>,
    t: Vec<Option<f64>>,
    sigma: Vec<Option<f64>>,
    energy: Vec<Option<f64>>,
    theta: Vec<Option<f64>>,
}

impl Series {
    /// Order the rows by step and keep one row per step (the same run committed twice, by two
    /// shards, repeats its rows: the first kept). A no-op for a series as the sink writes it.
    fn normalize(&mut self) {
        if self.step.windows(2).all(|w| w[0] < w[1]) {
            return;
        }
        let mut order: Vec<usize> = (0..self.step.len()).collect();
        order.sort_by_key(|&k| self.step[k]); // stable: the first of equal steps stays first
        order.dedup_by_key(|k| self.step[*k]);
        let pick = |v: &[Option<f64>]| order.iter().map(|&k| v[k]).collect::<Vec<_>>();
        let (t, sigma, energy, theta) = (
            pick(&self.t),
            pick(&self.sigma),
            pick(&self.energy),
            pick(&self.theta),
        );
        self.step = order.iter().map(|&k| self.step[k]).collect();
        (self.t, self.sigma, self.energy, self.theta) = (t, sigma, energy, theta);
    }

    /// Largest gap between recorded steps: 1 for a complete series, k for `series_every = k`.
    fn stride(&self) -> i64 {
        self.step
            .windows(2)
            .map(|w| w[1] - w[0])
            .max()
            .unwrap_or(1)
            .max(1)
    }

    /// Contact phases: maximal runs of rows with σ_C < 0, where a gap of at most
    /// [`MERGE_GAP`] row without pressure does not end a phase — it is the step-to-step
    /// alternation of the pressure (Nitsche-Hybrid's σ_C^n alternates between 0 and about
    /// three times the exact value while the node stays on the obstacle), not a lift-off.
    fn impacts(&self) -> Vec<Impact> {
        let n = self.step.len();
        let contact = |i: usize| self.sigma[i].is_some_and(|s| s < 0.0);
        let mut out = Vec::new();
        let mut i = 0;
        while i < n {
            if contact(i) {
                let first = i;
                let mut last = i;
                let mut j = i + 1;
                while j < n && j - last <= MERGE_GAP + 1 {
                    if contact(j) {
                        last = j;
                    }
                    j += 1;
                }
                out.push(Impact {
                    first,
                    last,
                    before: first.checked_sub(1),
                    after: (last + 1 < n).then_some(last + 1),
                });
                i = last;
            }
            i += 1;
        }
        out
    }
}

/// Rows without pressure that do not end a contact phase: the online detector's rule.
use crate::run::impacts::MERGE_GAP;

/// The series of the runs `need` (those without online phases), keyed by run_id; `Err(reason)`
/// when there are none. Only the series parts that hold them are read: the sink writes a
/// batch's series under its runs part's name. Every scene stores σ_C < 0 while in contact
/// (2D/3D: minus the total contact force), so the impacts are read the same way whatever the
/// scene.
fn read_series(
    dir: &std::path::Path,
    need: &[&Run],
) -> anyhow::Result<Result<HashMap<String, Series>, String>> {
    let wanted: HashMap<&str, ()> = need.iter().map(|r| (r.run_id.as_str(), ())).collect();
    if wanted.is_empty() {
        return Ok(Err("no runs".into()));
    }
    // A row without its part's name (not read by `runs::load`) means: read every part.
    let parts: Option<HashSet<String>> = need.iter().map(|r| r.part.clone()).collect();
    use polars::prelude::DataType;
    // Typed per part (another version may store a column with another type).
    let (raw, _) = super::runs::read_parts(
        &dir.join("series"),
        &[
            ("run_id", DataType::String),
            ("step", DataType::Int64),
            ("t", DataType::Float64),
            ("sigma_contact", DataType::Float64),
            ("energy", DataType::Float64),
            ("energy_theta", DataType::Float64),
        ],
        &[],
        parts.as_ref(),
    )?;
    if raw.height() == 0 {
        return Ok(Err("no time series in series/ (series_every = 0?)".into()));
    }
    let need = ["run_id", "step", "t", "sigma_contact", "energy"];
    if let Some(m) = need.iter().find(|c| raw.column(c).is_err()) {
        return Ok(Err(format!("the series have no `{m}` column")));
    }
    let has_theta = raw.column("energy_theta").is_ok();
    // No global sort by (run_id, step): a string sort of every row cost more than the rest of
    // the summary. The sink writes each run's rows together and in step order, so rows are
    // grouped by run as they come, and a run's rows are sorted by step only if they are not
    // already (rows of another writer, or one run committed by two shards).
    let mut df = raw;
    df.rechunk_mut(); // one chunk: `get(i)` without a search over the parts
    let ids = df.column("run_id")?.str()?.clone();
    let steps = df.column("step")?.i64()?.clone();
    let ts = df.column("t")?.f64()?.clone();
    let sig = df.column("sigma_contact")?.f64()?.clone();
    let en = df.column("energy")?.f64()?.clone();
    let th = if has_theta {
        Some(df.column("energy_theta")?.f64()?.clone())
    } else {
        None
    };
    // Blocks of consecutive rows of one run: the map is looked up once per block, not per row.
    let mut out: HashMap<String, Series> = HashMap::new();
    let mut i = 0;
    while i < df.height() {
        let Some(id) = ids.get(i) else {
            i += 1;
            continue;
        };
        let mut end = i + 1;
        while end < df.height() && ids.get(end) == Some(id) {
            end += 1;
        }
        if wanted.contains_key(id) {
            let s = out.entry(id.to_string()).or_default();
            for r in i..end {
                let Some(step) = steps.get(r) else { continue };
                s.step.push(step);
                s.t.push(ts.get(r));
                s.sigma.push(sig.get(r));
                s.energy.push(en.get(r));
                s.theta.push(th.as_ref().and_then(|c| c.get(r)));
            }
        }
        i = end;
    }
    for s in out.values_mut() {
        s.normalize();
    }
    Ok(Ok(out))
}

/// One contact phase as the impacts table lists it.
#[derive(Debug, Clone, PartialEq)]
struct PhaseRow {
    step_first: i64,
    step_last: i64,
    t_first: Option<f64>,
    t_last: Option<f64>,
    step_before: Option<i64>,
    step_after: Option<i64>,
    energy_before: Option<f64>,
    energy_after: Option<f64>,
    theta_before: Option<f64>,
    theta_after: Option<f64>,
}

/// A run's phases, the stride of the steps they were found on (1: every step) and the units
/// E⁰, E_Θ⁰ of the losses.
struct RunPhases {
    list: Vec<PhaseRow>,
    stride: i64,
    e0: Option<f64>,
    e0_theta: Option<f64>,
}

/// The phases of a run: the ones it recorded online (every step, stride 1) when its row has
/// them, else those of its stored series (resolved to the series' stride); None when neither
/// exists. Both paths read the same per-step values (the observer's E^n, E_Θ^n, t^n, copied
/// unchanged into the row's lists or the series), so a complete series gives the same table.
fn phases_of(r: &Run, series: &Result<HashMap<String, Series>, String>) -> Option<RunPhases> {
    // E⁰: the run's initial energy (contract §5); E(t⁰) from the data when the row lacks it or
    // it is 0 (a disc's E⁰ = 0: the losses are then not finite, as before).
    let e0_row = r.energy_initial.filter(|e| e.is_finite() && *e != 0.0);
    if let Some(online) = &r.impacts {
        let list = online
            .iter()
            .map(|p| PhaseRow {
                step_first: p.step_first,
                step_last: p.step_last,
                t_first: Some(p.t_first),
                t_last: Some(p.t_last),
                step_before: p.energy_before.map(|_| p.step_first - 1),
                step_after: p.energy_after.map(|_| p.step_last + 1),
                energy_before: p.energy_before,
                energy_after: p.energy_after,
                theta_before: p.energy_theta_before,
                theta_after: p.energy_theta_after,
            })
            .collect();
        return Some(RunPhases {
            list,
            stride: 1,
            e0: e0_row.or(r.energy_initial),
            e0_theta: r.energy_theta_initial,
        });
    }
    let s = series.as_ref().ok()?.get(&r.run_id)?;
    if s.step.is_empty() {
        return None;
    }
    let list = s
        .impacts()
        .into_iter()
        .map(|ph| PhaseRow {
            step_first: s.step[ph.first],
            step_last: s.step[ph.last],
            t_first: s.t[ph.first],
            t_last: s.t[ph.last],
            step_before: ph.before.map(|i| s.step[i]),
            step_after: ph.after.map(|i| s.step[i]),
            energy_before: ph.before.and_then(|i| s.energy[i]),
            energy_after: ph.after.and_then(|i| s.energy[i]),
            theta_before: ph.before.and_then(|i| s.theta[i]),
            theta_after: ph.after.and_then(|i| s.theta[i]),
        })
        .collect();
    Some(RunPhases {
        list,
        stride: s.stride(),
        e0: e0_row.or(s.energy[0]),
        e0_theta: s.theta[0],
    })
}

/// The energy section's outputs.
pub(crate) struct Section {
    pub runs: Table,
    pub groups: Table,
    pub impacts: Table,
    pub markdown: String,
    pub terminal: String,
}

fn minmax(v: impl Iterator<Item = Option<f64>>) -> (Option<f64>, Option<f64>) {
    let mut lo: Option<f64> = None;
    let mut hi: Option<f64> = None;
    for x in v.flatten().filter(|x| x.is_finite()) {
        lo = Some(lo.map_or(x, |l| l.min(x)));
        hi = Some(hi.map_or(x, |h| h.max(x)));
    }
    (lo, hi)
}

fn range(lo: Option<f64>, hi: Option<f64>) -> String {
    match (lo, hi) {
        (Some(a), Some(b)) if a == b => table::sci(Some(a)),
        (Some(a), Some(b)) => format!("{} … {}", table::sci(Some(a)), table::sci(Some(b))),
        _ => String::new(),
    }
}

/// Build the energy section.
pub(crate) fn section(dir: &std::path::Path, runs: &Runs) -> anyhow::Result<Section> {
    let series = series_of_older_rows(dir, runs)?;
    let found = impacts_table(runs, &series);
    let classes: Vec<EnergyClass> = runs.runs.iter().map(|r| classify(runs, r)).collect();
    let per_run = per_run_table(runs, &classes, &found.run_impacts);
    let per_group = per_group_table(runs, &classes);
    let status = series.as_ref().map(|_| ()).map_err(String::as_str);
    let md = markdown(runs, status, &found, per_group.rows, per_run.rows);
    let terminal = terminal(
        runs,
        status,
        &found,
        &per_run.counts,
        &per_group.class_lines,
    );
    Ok(Section {
        runs: per_run.table,
        groups: per_group.table,
        impacts: found.table,
        markdown: md,
        terminal,
    })
}

/// The series of the rows without online phases (rows of older versions), keyed by run_id;
/// `Err(reason)` when none could be found and no run has online phases.
fn series_of_older_rows(
    dir: &std::path::Path,
    runs: &Runs,
) -> anyhow::Result<Result<HashMap<String, Series>, String>> {
    // Runs of a version without the online phases fall back to their series.
    let need: Vec<&Run> = runs.runs.iter().filter(|r| !r.impacts_stored).collect();
    let online = runs.runs.len() - need.len();
    Ok(if need.is_empty() {
        Ok(HashMap::new())
    } else {
        match read_series(dir, &need)? {
            // Some runs have online phases: the others' missing series is not the section's
            // failure.
            Err(_) if online > 0 => Ok(HashMap::new()),
            other => other,
        }
    })
}

/// The impacts table and what the other tables say of it.
struct Impacts {
    table: Table,
    /// Per run: (number of impacts, total relative loss over complete phases, series
    /// decimated, series stride); None for a run without phases.
    run_impacts: Vec<Option<(usize, f64, bool, i64)>>,
    /// Contact phases over every run.
    impact_count: usize,
    /// Runs with phases (online or from their series).
    runs_with_series: usize,
    /// Runs whose phases come from a decimated series.
    decimated_runs: usize,
}

/// One row per contact phase of every run.
fn impacts_table(runs: &Runs, series: &Result<HashMap<String, Series>, String>) -> Impacts {
    // One row per contact phase: tens of thousands of rows on a large sweep, so the run's
    // parameters are not repeated on each (25 columns, half of impacts.csv's 7.9 MB and of its
    // encoding time on issue 12's sweep); they are one join away, on `run_id`, in the energy
    // table or `runs/`.
    let mut out = Impacts {
        table: Table::new(&table::owned(&columns![
            group: I64, group_title: Str, run_id: Str, label: Str, status: Str, h: F64, dt: F64,
            impact: I64, step_first: I64, step_last: I64, t_first: F64, t_last: F64,
            step_before: I64, step_after: I64, energy_e0: F64, energy_before: F64,
            energy_after: F64, energy_loss_rel: F64, energy_theta_before: F64,
            energy_theta_after: F64, energy_theta_loss_rel: F64, phase_complete: Bool,
            series_decimated: Bool, series_stride: I64,
        ])),
        run_impacts: vec![None; runs.runs.len()],
        impact_count: 0,
        runs_with_series: 0,
        decimated_runs: 0,
    };
    for (ri, r) in runs.runs.iter().enumerate() {
        let Some(found) = phases_of(r, series) else {
            continue;
        };
        out.runs_with_series += 1;
        let decimated = found.stride > 1;
        out.decimated_runs += decimated as usize;
        let mut total = 0.0;
        for (k, ph) in found.list.iter().enumerate() {
            if let Some(l) = impact_row(&mut out.table, runs, r, k, ph, &found) {
                total += l;
            }
        }
        out.impact_count += found.list.len();
        out.run_impacts[ri] = Some((found.list.len(), total, decimated, found.stride));
    }
    out
}

/// The impacts table's row of phase `k` of run `r`; returns its relative loss (None when an
/// energy or E⁰ is missing).
fn impact_row(
    impacts: &mut Table,
    runs: &Runs,
    r: &Run,
    k: usize,
    ph: &PhaseRow,
    found: &RunPhases,
) -> Option<f64> {
    let (stride, e0, e0_theta) = (found.stride, found.e0, found.e0_theta);
    let decimated = stride > 1;
    let complete = ph.step_before.is_some() && ph.step_after.is_some();
    let (eb, ea) = (ph.energy_before, ph.energy_after);
    let loss = match (eb, ea, e0) {
        (Some(b), Some(a), Some(e0)) => Some((b - a) / e0),
        _ => None,
    };
    let (tb, ta) = (ph.theta_before, ph.theta_after);
    let tloss = match (tb, ta, e0_theta) {
        (Some(b), Some(a), Some(e0)) if e0 != 0.0 => Some((b - a) / e0),
        _ => None,
    };
    impacts.run_group(runs, r);
    impacts.run_identity(r);
    impacts.f64("h", r.h);
    impacts.f64("dt", r.dt);
    impacts.i64("impact", Some(k as i64 + 1));
    impacts.i64("step_first", Some(ph.step_first));
    impacts.i64("step_last", Some(ph.step_last));
    impacts.f64("t_first", ph.t_first);
    impacts.f64("t_last", ph.t_last);
    impacts.i64("step_before", ph.step_before);
    impacts.i64("step_after", ph.step_after);
    // The energy across the phase: E^h, and E_Θ where the scheme has it.
    let energies = [
        ("energy_e0", e0),
        ("energy_before", eb),
        ("energy_after", ea),
    ];
    let theta = [("energy_theta_before", tb), ("energy_theta_after", ta)];
    for (name, v) in energies {
        impacts.f64(name, v);
    }
    impacts.f64("energy_loss_rel", loss);
    for (name, v) in theta {
        impacts.f64(name, v);
    }
    impacts.f64("energy_theta_loss_rel", tloss);
    impacts.bool("phase_complete", Some(complete));
    impacts.bool("series_decimated", Some(decimated));
    impacts.i64("series_stride", Some(stride));
    impacts.end_row();
    loss
}

/// The per-run energy table, its Markdown rows and the number of runs of each class.
struct PerRun<'a> {
    table: Table,
    rows: Vec<Vec<String>>,
    counts: BTreeMap<&'a str, usize>,
}

/// One row per run: its energies, its class and its impacts.
fn per_run_table<'a>(
    runs: &Runs,
    classes: &'a [EnergyClass],
    run_impacts: &[Option<(usize, f64, bool, i64)>],
) -> PerRun<'a> {
    let mut per_run = Table::new(&table::with_params(
        &columns![
            group: I64, group_title: Str, run_id: Str, label: Str, status: Str, search: Str,
            h: F64, dt: F64, courant: F64, energy_initial: F64, energy_final: F64,
            energy_drift: F64, energy_max_dev: F64, energy_max_increase: F64,
            energy_theta_max_increase: F64, energy_theta_drift: F64, energy_class: Str,
            energy_functional: Str, energy_functional_drift: F64,
            energy_functional_max_increase: F64, energy_tolerance: F64,
            energy_monotone_by_proof: Bool, impacts: I64, impact_loss_total: F64,
            series_decimated: Bool, series_stride: I64,
        ],
        runs,
    ));
    let mut run_rows_md: Vec<Vec<String>> = Vec::new();
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for (ri, r) in runs.runs.iter().enumerate() {
        let c = &classes[ri];
        let b = c.class.as_deref();
        *counts.entry(b.unwrap_or("unknown")).or_default() += 1;
        per_run.run_group(runs, r);
        per_run.run_identity(r);
        per_run.str("search", r.search.as_deref());
        per_run.run_level(r);
        per_run.f64("energy_initial", r.energy_initial);
        per_run.f64("energy_final", r.energy_final);
        per_run.f64("energy_drift", r.energy_drift);
        per_run.f64("energy_max_dev", r.energy_max_dev);
        per_run.f64("energy_max_increase", r.energy_max_increase);
        per_run.f64("energy_theta_max_increase", r.energy_theta_max_increase);
        per_run.f64("energy_theta_drift", r.energy_theta_drift);
        per_run.str("energy_class", b);
        per_run.str("energy_functional", Some(c.functional));
        per_run.f64("energy_functional_drift", c.drift);
        per_run.f64("energy_functional_max_increase", c.max_increase);
        per_run.f64("energy_tolerance", c.tolerance);
        per_run.bool("energy_monotone_by_proof", Some(c.monotone));
        let imp = run_impacts[ri];
        per_run.i64("impacts", imp.map(|i| i.0 as i64));
        per_run.f64("impact_loss_total", imp.map(|i| i.1));
        per_run.bool("series_decimated", imp.map(|i| i.2));
        per_run.i64("series_stride", imp.map(|i| i.3));
        for ((n, _), c) in runs.params.iter().zip(&r.params) {
            per_run.cell(n, c);
        }
        per_run.end_row();
        run_rows_md.push(vec![
            (r.group + 1).to_string(),
            r.label.clone(),
            table::sci(r.h),
            table::sci(r.dt),
            r.status.clone(),
            table::sci(r.energy_drift),
            table::sci(r.energy_max_dev),
            table::sci(r.energy_max_increase),
            format!("{} {}", c.functional, table::sci(c.drift)),
            table::sci(c.tolerance),
            b.unwrap_or("").to_string(),
            imp.map(|i| i.0.to_string()).unwrap_or_default(),
            imp.map(|i| table::sci(Some(i.1))).unwrap_or_default(),
            imp.map(|i| {
                if i.2 {
                    format!("every {}", i.3)
                } else {
                    "no".into()
                }
            })
            .unwrap_or_default(),
        ]);
    }
    PerRun {
        table: per_run,
        rows: run_rows_md,
        counts,
    }
}

/// The per-group energy table, its Markdown rows and the terminal's line per group.
struct PerGroup {
    table: Table,
    rows: Vec<Vec<String>>,
    class_lines: Vec<String>,
}

/// One row per group, across refinement: ranges over the ok runs (a diverged run's energy is
/// where it stopped, not a property of the method) and the count of each class.
fn per_group_table(runs: &Runs, classes: &[EnergyClass]) -> PerGroup {
    let mut groups = Table::new(&table::with_params(
        &columns![
            group: I64, group_title: Str, label: Str, runs: I64, ok_runs: I64,
            energy_drift_min: F64, energy_drift_max: F64, energy_max_dev_min: F64,
            energy_max_dev_max: F64, energy_max_increase_min: F64, energy_max_increase_max: F64,
            energy_theta_max_increase_min: F64, energy_theta_max_increase_max: F64,
            conservative_runs: I64, dissipative_runs: I64, growing_runs: I64, diverged_runs: I64,
            failed_runs: I64, energy_classes: Str,
        ],
        runs,
    ));
    let mut group_rows_md: Vec<Vec<String>> = Vec::new();
    let mut class_lines: Vec<String> = Vec::new();
    for (gi, g) in runs.groups.iter().enumerate() {
        let ok: Vec<&Run> = g
            .runs
            .iter()
            .map(|&i| &runs.runs[i])
            .filter(|r| r.ok())
            .collect();
        let drift = minmax(ok.iter().map(|r| r.energy_drift));
        let dev = minmax(ok.iter().map(|r| r.energy_max_dev));
        let inc = minmax(ok.iter().map(|r| r.energy_max_increase));
        let th = minmax(ok.iter().map(|r| r.energy_theta_max_increase));
        let mut per_class: BTreeMap<String, usize> = BTreeMap::new();
        for &i in &g.runs {
            let c = classes[i].class.clone().unwrap_or_else(|| "unknown".into());
            *per_class.entry(c).or_default() += 1;
        }
        let count = |c: &str| per_class.get(c).copied().unwrap_or(0);
        let failed: usize = per_class
            .iter()
            .filter(|(k, _)| !CLASSES.contains(&k.as_str()))
            .map(|(_, v)| v)
            .sum();
        let summary = class_summary(&per_class);
        let first = &runs.runs[g.runs[0]];
        groups.i64("group", Some(gi as i64 + 1));
        groups.str("group_title", Some(&g.title));
        groups.str("label", Some(&first.label));
        groups.i64("runs", Some(g.runs.len() as i64));
        groups.i64("ok_runs", Some(ok.len() as i64));
        groups.f64("energy_drift_min", drift.0);
        groups.f64("energy_drift_max", drift.1);
        groups.f64("energy_max_dev_min", dev.0);
        groups.f64("energy_max_dev_max", dev.1);
        groups.f64("energy_max_increase_min", inc.0);
        groups.f64("energy_max_increase_max", inc.1);
        groups.f64("energy_theta_max_increase_min", th.0);
        groups.f64("energy_theta_max_increase_max", th.1);
        groups.i64("conservative_runs", Some(count("conservative") as i64));
        groups.i64("dissipative_runs", Some(count("dissipative") as i64));
        groups.i64("growing_runs", Some(count("growing") as i64));
        groups.i64("diverged_runs", Some(count("diverged") as i64));
        groups.i64("failed_runs", Some(failed as i64));
        groups.str("energy_classes", Some(&summary));
        for ((n, _), c) in runs.params.iter().zip(&first.params) {
            groups.cell(n, c);
        }
        groups.end_row();
        group_rows_md.push(vec![
            (gi + 1).to_string(),
            g.title.clone(),
            format!("{}/{}", ok.len(), g.runs.len()),
            range(drift.0, drift.1),
            range(dev.0, dev.1),
            range(inc.0, inc.1),
            range(th.0, th.1),
            summary.clone(),
        ]);
        class_lines.push(format!("  {:<60} {summary}", g.title));
    }
    PerGroup {
        table: groups,
        rows: group_rows_md,
        class_lines,
    }
}

/// `energy.md`: what the columns and classes mean, the per-group table, then the per-run one.
/// `series` is `Err(reason)` when the impacts could not be computed.
fn markdown(
    runs: &Runs,
    series: Result<(), &str>,
    found: &Impacts,
    group_rows_md: Vec<Vec<String>>,
    run_rows_md: Vec<Vec<String>>,
) -> String {
    let (impact_count, runs_with_series, decimated_runs) = (
        found.impact_count,
        found.runs_with_series,
        found.decimated_runs,
    );
    let mut md = String::from("# Energy\n\n");
    let _ = writeln!(
        md,
        "Relative to E⁰ (the run's initial discrete energy): drift = (E^N − E⁰)/E⁰, max dev = \
         max |E^n − E⁰|/E⁰, max increase = max (E^(n+1) − E^n)/E⁰ (E_Θ for the Θ column). \
         Energy class, by the functional F the scheme controls (E_Θ for Nitsche, E^h + penalty \
         potential for penalty, E^h otherwise) with d = (F^N − F⁰)/F⁰ and δ = max(1, ν)·h/L, \
         the contact's consistency error: growing if d > δ (or, for a functional proven \
         non-increasing — hybrid with Nitsche Θ = 1 or the 000 §5 hybrid, backward Euler with \
         Nitsche Θ = 1 — if one step raises F by more than {ENERGY_TOL:e}·F⁰), dissipative if \
         d < −δ, conservative otherwise; diverged and failed runs by their status. Group ranges \
         are over the ok runs.\n"
    );
    // Only folders with frictional runs: the frictionless energy.md keeps its bytes.
    if runs.runs.iter().any(|r| frictional(runs, r)) {
        let _ = writeln!(
            md,
            "Frictional runs (friction ≠ none) are judged by the balance F + W_f (W_f the \
             frictional work, contract §5's energy_balance_drift and energy_balance_max_increase; \
             functional \"… + W_f\"), since E alone falls by W_f whatever the scheme: growing if \
             it rises by more than δ (or one step by more than {ENERGY_TOL:e}·E⁰ for kane with \
             inertia and Moreau–Jean θ = ½, e = 1), dissipative if it falls by more than δ, \
             {FRICTION_ACCOUNTED} if it stays within δ while E falls by more than δ, \
             conservative otherwise.\n"
        );
    }
    md.push_str("## Per group (across refinement)\n\n");
    let per_group = TextTable::new(text_columns![
        "#" => Right, "group" => Left, "ok/runs" => Right, "drift" => Right, "max dev" => Right,
        "max increase" => Right, "max increase E_Θ" => Right, "energy classes" => Left,
    ]);
    md.push_str(&per_group.with_rows(group_rows_md).markdown());
    md.push_str("\n## Per run\n\n");
    match series {
        Ok(_) => {
            let _ = writeln!(
                md,
                "Impacts: contact phases = maximal runs of steps with σ_C < 0 (a one-step gap \
                 without pressure does not end one), found by each run at every step (folders of \
                 older versions: from the recorded series); loss = (E just before − E just \
                 after)/E⁰ summed over complete phases; full list in impacts.parquet. \
                 {impact_count} contact phases in {runs_with_series} runs{}.\n",
                if decimated_runs > 0 {
                    format!(
                        "; {decimated_runs} series are decimated (phase ends resolved to the \
                         recording stride only, energy change outside contact within the stride \
                         is attributed to the impact)"
                    )
                } else {
                    String::new()
                }
            );
        }
        Err(why) => {
            let _ = writeln!(md, "Impacts: not computed ({why}).\n");
        }
    }
    let run_text = TextTable::new(text_columns![
        "#" => Right, "label" => Left, "h" => Right, "dt" => Right, "status" => Left,
        "drift" => Right, "max dev" => Right, "max increase" => Right,
        "functional drift" => Right, "δ" => Right, "class" => Left, "impacts" => Right,
        "impact loss" => Right, "decimated" => Left,
    ]);
    md.push_str(&run_text.with_rows(run_rows_md).markdown());
    md
}

/// The terminal's lines: the count of each class, one line per group, the largest one-step
/// gain and the impacts found. `series` is `Err(reason)` when the impacts could not be
/// computed.
fn terminal(
    runs: &Runs,
    series: Result<(), &str>,
    found: &Impacts,
    counts: &BTreeMap<&str, usize>,
    class_lines: &[String],
) -> String {
    let (impact_count, runs_with_series, decimated_runs) = (
        found.impact_count,
        found.runs_with_series,
        found.decimated_runs,
    );
    let mut terminal = format!(
        "energy classes (scheme's functional, δ = max(1, ν)·h/L): {} runs —",
        runs.runs.len()
    );
    let parts: Vec<String> = counts.iter().map(|(k, v)| format!(" {v} {k}")).collect();
    terminal.push_str(&parts.join(","));
    terminal.push('\n');
    for l in class_lines {
        terminal.push_str(l.trim_end());
        terminal.push('\n');
    }
    if let Some(worst) = runs
        .runs
        .iter()
        .filter(|r| r.ok())
        .filter(|r| r.energy_max_increase.is_some_and(|x| x.is_finite()))
        .max_by(|a, b| {
            a.energy_max_increase
                .unwrap_or(f64::NEG_INFINITY)
                .total_cmp(&b.energy_max_increase.unwrap_or(f64::NEG_INFINITY))
        })
        .filter(|r| r.energy_max_increase.is_some_and(|x| x > ENERGY_TOL))
    {
        let _ = writeln!(
            terminal,
            "  largest one-step gain {} E⁰: {} (h = {}, dt = {})",
            table::eng_opt(worst.energy_max_increase),
            worst.label,
            table::eng_opt(worst.h),
            table::eng_opt(worst.dt)
        );
    }
    match series {
        Ok(_) => {
            let _ = writeln!(
                terminal,
                "  impacts: {impact_count} contact phases in {runs_with_series} runs{}",
                if decimated_runs > 0 {
                    format!(" ({decimated_runs} decimated)")
                } else {
                    String::new()
                }
            );
        }
        Err(why) => {
            let _ = writeln!(terminal, "  impacts: not computed ({why})");
        }
    }
    terminal
}

/// "10 conservative, 2 growing" in the order of [`CLASSES`], then the other statuses.
fn class_summary(per_class: &BTreeMap<String, usize>) -> String {
    let mut keys: Vec<&String> = per_class.keys().collect();
    keys.sort_by_key(|k| CLASSES.iter().position(|c| c == k).unwrap_or(CLASSES.len()));
    keys.iter()
        .map(|k| format!("{} {k}", per_class[*k]))
        .collect::<Vec<_>>()
        .join(", ")
}
