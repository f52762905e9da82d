//! Sweep files (contract §7): parse, validate and expand into runs.
//!
//! A sweep file names a scene and a parameter space: `[fixed]` values, a cartesian `[grid]`
//! (items may be bundles — inline tables setting several parameters at once), equal-length
//! `[zip]` lists advanced together, and `exclude` filters; a `[summary]` table chooses the
//! columns of the convergence tables ([`crate::model::SummaryOptions`]; [`summary_options`]
//! reads it back from the text stored in a results folder). Everything is checked before
//! anything runs: each problem is reported with the file, the key path, the line and the
//! reason ([`SweepError`]). [`plan::expand`] turns the file into [`plan::Plan`]: deterministic
//! order, meaningless combinations dropped, parameters that do not apply to a run's method
//! removed and the resulting duplicates merged, each run keyed by a stable [`plan::RunSpec::run_id`].

/// contract §7's keys live one layer down ([`crate::model::keys`]): a run's row names them too.
pub use crate::model::keys;
pub mod overrides;
pub mod plan;
pub mod tree;

use std::fmt;
use std::path::{Path, PathBuf};

pub use keys::{Key, Value, ValueType};
pub use plan::{Plan, PlanLimits, PlanSize, RunSpec, expand, expand_with};
use tree::{Kind, Node};

use crate::model::{SummaryOptions, parse_errors};
use crate::scene::SceneKind;

/// Where a value was written: its key path in the file and its line.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Origin {
    pub path: String,
    pub line: Option<usize>,
}

/// One problem found in a sweep file.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Issue {
    pub line: Option<usize>,
    pub key: String,
    pub reason: String,
}

impl Issue {
    pub fn at(origin: &Origin, reason: impl Into<String>) -> Self {
        Issue {
            line: origin.line,
            key: origin.path.clone(),
            reason: reason.into(),
        }
    }
}

/// A sweep file that cannot be used; nothing has run.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("{file}: cannot read the sweep file")]
    Read {
        file: PathBuf,
        source: std::io::Error,
    },
    /// `sets`: the `--set` arguments applied on top of the file (issues on their lines name
    /// the flag instead of the file).
    #[error("{}", render_issues(file, issues, sets))]
    Invalid {
        file: PathBuf,
        issues: Vec<Issue>,
        sets: Vec<String>,
    },
    /// A `--set` argument that is not `key=value`.
    #[error("{0}")]
    BadSet(String),
}

/// Where a line is: `file:line`, or the `--set` flag that wrote it.
fn place(file: &Path, line: Option<usize>, sets: &[String]) -> String {
    match line {
        Some(l) if l >= overrides::SET_LINE => {
            let arg = sets
                .get(l - overrides::SET_LINE)
                .map(String::as_str)
                .unwrap_or("?");
            format!("--set {arg}")
        }
        // A sweep without a file is named by its flag (`--scene bar1d`): the lines of its
        // generated text mean nothing to the user.
        Some(_) if file.to_string_lossy().starts_with("--") => file.display().to_string(),
        Some(l) => format!("{}:{l}", file.display()),
        None => file.display().to_string(),
    }
}

/// A line inside a message: `line 6`, or `--set h=…`.
fn line_ref(line: Option<usize>, sets: &[String]) -> String {
    match line {
        Some(l) if l >= overrides::SET_LINE => place(Path::new(""), line, sets),
        Some(l) => format!("line {l}"),
        None => "line 0".into(),
    }
}

fn render_issues(file: &Path, issues: &[Issue], sets: &[String]) -> String {
    let mut out = String::new();
    for (i, is) in issues.iter().enumerate() {
        if i > 0 {
            out.push('\n');
        }
        out.push_str(&format!(
            "{}: key `{}`: {}",
            place(file, is.line, sets),
            is.key,
            is.reason
        ));
    }
    out
}

/// A parameter value with its origin.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub key: Key,
    pub value: Value,
    pub origin: Origin,
}

/// One axis of the grid (or the zipped lists): alternatives, each a set of entries.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub name: String,
    pub items: Vec<Vec<Entry>>,
}

/// `ensemble = { perturbation, samples, seed }`: round-off sensitivity study.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ensemble {
    pub perturbation: f64,
    pub samples: usize,
    pub seed: u64,
}

/// What a `[search]` looks for: the boundary where this stops holding.
#[derive(Debug, Clone, PartialEq)]
pub enum Criterion {
    /// The run ends `ok` (no divergence, no solver failure).
    NoDivergence,
    /// The run ends ok with E(T)/E⁰ ≤ 1 + tol.
    EnergyRatioBelow(f64),
    /// The run ends ok with `column` ≤ eps.
    ErrorBelow { column: String, eps: f64 },
}

impl Criterion {
    /// The name written in sweep files.
    pub fn name(&self) -> &'static str {
        match self {
            Criterion::NoDivergence => "no-divergence",
            Criterion::EnergyRatioBelow(_) => "energy-ratio-below",
            Criterion::ErrorBelow { .. } => "error-below",
        }
    }
}

/// `[search]`: for every method of the grid, the boundary in `key` ∈ [lo, hi] where the
/// criterion changes, found by bracketing then bisection to a relative tolerance.
#[derive(Debug, Clone, PartialEq)]
pub struct Search {
    pub name: String,
    pub key: Key,
    pub lo: f64,
    pub hi: f64,
    pub criterion: Criterion,
    pub rel_tol: f64,
    /// Bisect in log(key) (geometric midpoints): the default when lo > 0.
    pub log: bool,
}

/// Columns an `error-below` criterion may name besides the error norms of contract §5
/// ([`crate::model::ERROR_COLUMNS`]): the contact force's error and the energy drift.
pub const SEARCH_EXTRA_COLUMNS: [&str; 2] = ["err_force_l2", "energy_drift"];

/// Every column an `error-below` criterion may name, in the order the refusal lists them.
pub fn search_error_columns() -> impl Iterator<Item = &'static str> {
    crate::model::ERROR_COLUMNS
        .iter()
        .chain(&SEARCH_EXTRA_COLUMNS)
        .copied()
}

/// A parsed and value-checked sweep file.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepFile {
    pub path: PathBuf,
    pub text: String,
    pub name: String,
    pub scene: SceneKind,
    pub description: Option<String>,
    pub fixed: Vec<Entry>,
    pub grid: Vec<Axis>,
    pub zip: Option<Axis>,
    pub exclude: Vec<Vec<Entry>>,
    pub repeats: usize,
    pub ensemble: Option<Ensemble>,
    /// Keep every k-th step in DIR/series (0: no time series).
    pub series_every: usize,
    /// `[fixed]` values that an axis overrides (reported by the plan).
    pub overridden: Vec<String>,
    /// `reference = {…}`: the parameters that turn each run into its reference run (contract §7;
    /// scenes without a closed form).
    pub reference: Option<Vec<Entry>>,
    /// `reference = { scene = "bar2d", … }`: the reference is a run of another scene (a mesh
    /// file's body measured against the built-in scene it meshes, contract §1.6); None: the
    /// sweep's own scene.
    pub reference_scene: Option<SceneKind>,
    /// `[search]`: a boundary to find by bisection for every method of the grid.
    pub search: Option<Search>,
    /// `allow_unstable = true`: an explicit scheme beyond its CFL limit runs (and ends
    /// `diverged`) instead of being refused; always so for the probes of a search.
    pub allow_unstable: bool,
    /// `[summary]`: what the convergence tables print.
    pub summary: SummaryOptions,
    /// The `--set key=value` arguments applied on top of the file's text, in order (recorded
    /// in the manifest; `text` stays the file's own).
    pub sets: Vec<String>,
}

const TOP_KEYS: [&str; 14] = [
    "name",
    "scene",
    "description",
    "exclude",
    "fixed",
    "grid",
    "zip",
    "reference",
    "repeats",
    "ensemble",
    "series_every",
    "search",
    "allow_unstable",
    "summary",
];

/// Collects issues while parsing.
struct Checker {
    scene: Option<SceneKind>,
    issues: Vec<Issue>,
    sets: Vec<String>,
}

impl Checker {
    fn issue(&mut self, path: &str, line: usize, reason: impl Into<String>) {
        self.issues.push(Issue {
            line: Some(line),
            key: path.to_string(),
            reason: reason.into(),
        });
    }

    /// Convert a node to the value of `key`, checking type, range and scene acceptance.
    fn value(&mut self, key: Key, node: &Node, path: &str) -> Option<Entry> {
        if let Some(scene) = self.scene
            && !accepted(scene, key)
        {
            // Name the scenes that do take it: a second body's key (`length_b`, …) on a
            // one-body scene says where it belongs.
            let takers: Vec<&str> = SceneKind::NAMES
                .iter()
                .filter_map(|(n, k)| k.filter(|k| accepted(*k, key)).map(|_| *n))
                .collect();
            let hint = if takers.is_empty() {
                String::new()
            } else {
                format!(" (scenes that take it: {})", takers.join(", "))
            };
            self.issue(
                path,
                node.line,
                format!(
                    "`{}` is not a parameter of scene {}{hint}",
                    key.name(),
                    scene.name()
                ),
            );
            return None;
        }
        let value = match (key.value_type(), &node.kind) {
            (ValueType::Float, Kind::Float(x)) => Value::Num(*x),
            (ValueType::Float, Kind::Int(i)) => Value::Num(*i as f64),
            (ValueType::Int, Kind::Int(i)) => Value::Int(*i),
            (ValueType::Str, Kind::Str(s)) => Value::Str(s.clone()),
            (ValueType::FloatList, Kind::Array(items)) => {
                let mut v = Vec::with_capacity(items.len());
                for it in items {
                    match it.kind {
                        Kind::Float(x) => v.push(x),
                        Kind::Int(i) => v.push(i as f64),
                        ref k => {
                            self.issue(
                                path,
                                it.line,
                                format!("expected a list of numbers, found a {}", k.type_name()),
                            );
                            return None;
                        }
                    }
                }
                Value::List(v)
            }
            (t, k) => {
                let want = match t {
                    ValueType::Float => "a number",
                    ValueType::Int => "an integer",
                    ValueType::Str => "a string",
                    ValueType::FloatList => "a list of numbers",
                };
                self.issue(
                    path,
                    node.line,
                    format!("expected {want}, found a {}", k.type_name()),
                );
                return None;
            }
        };
        if let Err(reason) = key.check(&value) {
            self.issue(path, node.line, reason);
            return None;
        }
        Some(Entry {
            key,
            value,
            origin: Origin {
                path: path.to_string(),
                line: Some(node.line),
            },
        })
    }

    fn key(&mut self, name: &str, path: &str, line: usize) -> Option<Key> {
        let k = Key::from_name(name);
        if k.is_none() {
            self.issue(
                path,
                line,
                format!("unknown parameter `{name}`{}", suggest(name)),
            );
        }
        k
    }

    /// The `[summary]` table: `errors` (a list of error column names), `rates`, `slopes`,
    /// `flags` (booleans). Unset keys keep their defaults.
    fn summary(&mut self, line: usize, node: &Node) -> SummaryOptions {
        let mut out = SummaryOptions::default();
        let Kind::Table(entries) = &node.kind else {
            self.issue(
                "summary",
                line,
                format!(
                    "expected a table ([summary] with errors, rates, slopes, flags), found a {}",
                    node.kind.type_name()
                ),
            );
            return out;
        };
        for (k, kl, v) in entries {
            let p = format!("summary.{k}");
            match k.as_str() {
                "errors" => {
                    let Kind::Array(items) = &v.kind else {
                        self.issue(
                            &p,
                            *kl,
                            format!(
                                "expected a list of error column names, found a {}",
                                v.kind.type_name()
                            ),
                        );
                        continue;
                    };
                    let mut names = Vec::with_capacity(items.len());
                    for (i, it) in items.iter().enumerate() {
                        match &it.kind {
                            Kind::Str(s) => names.push(s.as_str()),
                            k => self.issue(
                                &format!("{p}[{i}]"),
                                it.line,
                                format!(
                                    "expected an error column name (a string), found a {}",
                                    k.type_name()
                                ),
                            ),
                        }
                    }
                    if names.len() == items.len() {
                        match parse_errors(&names) {
                            Ok(e) => out.errors = Some(e),
                            Err(reason) => self.issue(&p, *kl, reason),
                        }
                    }
                }
                "rates" | "slopes" | "flags" => match v.kind {
                    Kind::Bool(b) => match k.as_str() {
                        "rates" => out.rates = b,
                        "slopes" => out.slopes = b,
                        _ => out.flags = b,
                    },
                    ref other => self.issue(
                        &p,
                        *kl,
                        format!("expected true or false, found a {}", other.type_name()),
                    ),
                },
                _ => self.issue(
                    &p,
                    *kl,
                    "unknown key (expected errors, rates, slopes, flags)",
                ),
            }
        }
        out
    }

    /// A bundle: an inline table of parameters.
    fn bundle(&mut self, entries: &[(String, usize, Node)], path: &str) -> Vec<Entry> {
        let mut out = Vec::new();
        for (k, kl, v) in entries {
            let p = format!("{path}.{k}");
            if let Some(key) = self.key(k, &p, *kl) {
                if out.iter().any(|e: &Entry| e.key == key) {
                    self.issue(&p, *kl, "set twice in the same bundle");
                }
                if let Some(e) = self.value(key, v, &p) {
                    out.push(e);
                }
            }
        }
        out
    }

    /// A list of alternatives for `[grid]` / `[zip]`.
    fn axis(&mut self, section: &str, name: &str, line: usize, node: &Node) -> Option<Axis> {
        let path = format!("{section}.{name}");
        let Kind::Array(items) = &node.kind else {
            self.issue(
                &path,
                line,
                format!(
                    "expected a list of values, found a {} (single values go in [fixed])",
                    node.kind.type_name()
                ),
            );
            return None;
        };
        if items.is_empty() {
            self.issue(&path, line, "empty list: the sweep would have no runs");
            return None;
        }
        let key = Key::from_name(name);
        let all_bundles = items.iter().all(|i| matches!(i.kind, Kind::Table(_)));
        if key.is_none() && !all_bundles {
            self.issue(
                &path,
                line,
                format!(
                    "unknown parameter `{name}`{} (a label axis must list only bundles {{ … }})",
                    suggest(name)
                ),
            );
            return None;
        }
        let mut alts = Vec::new();
        for (i, it) in items.iter().enumerate() {
            let ip = format!("{path}[{i}]");
            match (&it.kind, key) {
                (Kind::Table(t), _) => alts.push(self.bundle(t, &ip)),
                (_, Some(k)) if k.value_type() == ValueType::FloatList => {
                    alts.push(self.value(k, it, &ip).into_iter().collect())
                }
                (Kind::Array(_), Some(_)) => {
                    self.issue(&ip, it.line, "nested lists are not allowed here");
                }
                (_, Some(k)) => alts.push(self.value(k, it, &ip).into_iter().collect()),
                (_, None) => unreachable!(),
            }
        }
        Some(Axis {
            name: name.to_string(),
            items: alts,
        })
    }
}

/// The scene named by `reference = { scene = NAME, … }` in a sweep of scene `own`: the same
/// scene, or — for a body from a mesh file (contract §1.6) — a finite-element scene of the same
/// dimension whose errors come from a reference run (the built-in bar or disc/ball the file
/// meshes): the run's nodes are located in the reference's mesh. Other pairs have no common
/// body to compare.
fn reference_scene_of(own: SceneKind, name: &str) -> Result<SceneKind, String> {
    let kind = match SceneKind::NAMES.iter().find(|(n, _)| *n == name) {
        Some((_, Some(kind))) => *kind,
        Some((_, None)) => {
            return Err(format!(
                "scene `{name}` is specified (contract §1) but not implemented in this version"
            ));
        }
        None => {
            return Err(format!(
                "unknown scene `{name}` (expected one of {})",
                SceneKind::NAMES.map(|(n, _)| n).join(", ")
            ));
        }
    };
    if kind == own {
        return Ok(kind);
    }
    if !own.get().takes_mesh_file() {
        return Err(format!(
            "a reference of another scene ({name}) is for runs on a mesh file (mesh2d, mesh3d); scene {} is measured against its own",
            own.name()
        ));
    }
    let dim = own.get().fe_dim();
    if kind.get().fe_dim() != dim {
        let fits: Vec<&str> = SceneKind::NAMES
            .iter()
            .filter_map(|(n, k)| k.filter(|k| k.get().fe_dim() == dim).map(|_| *n))
            .collect();
        return Err(format!(
            "scene {name} cannot be the reference of scene {}: a finite-element scene of the same dimension is needed ({})",
            own.name(),
            fits.join(", ")
        ));
    }
    Ok(kind)
}

/// Whether `scene` accepts `key`: every discretisation and method key, and its own physics.
pub fn accepted(scene: SceneKind, key: Key) -> bool {
    if matches!(key, Key::Mesh | Key::Obstacle) {
        return scene.get().takes_mesh_file();
    }
    !key.is_physics() || scene.accepts_physics(key.name())
}

fn suggest(name: &str) -> String {
    let lower = name.to_ascii_lowercase();
    let near = Key::ALL
        .iter()
        .map(|k| k.name())
        .chain(TOP_KEYS)
        .find(|k| k.to_ascii_lowercase() == lower || edit_distance(k, name) <= 2);
    near.map(|k| format!(" (did you mean `{k}`?)"))
        .unwrap_or_default()
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

impl SweepFile {
    /// Read and check a sweep file.
    pub fn load(path: &Path) -> Result<SweepFile, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|source| SweepError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        SweepFile::parse(path, &text)
    }

    /// Check a sweep file's text; `path` names it in messages.
    pub fn parse(path: &Path, text: &str) -> Result<SweepFile, SweepError> {
        SweepFile::parse_with(path, text, &[])
    }

    /// Read a sweep file and apply `--set key=value` arguments on top of it
    /// ([`overrides`]); the result is checked like a file.
    pub fn load_with(path: &Path, sets: &[String]) -> Result<SweepFile, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|source| SweepError::Read {
            file: path.to_path_buf(),
            source,
        })?;
        SweepFile::parse_with(path, &text, sets)
    }

    /// A sweep without a file: scene `scene`, named after it, made of `--set` arguments only.
    /// Messages name the flags (`--scene`, `--set`).
    pub fn from_flags(scene: &str, sets: &[String]) -> Result<SweepFile, SweepError> {
        // A TOML basic string of the scene name (its quotes and backslashes escaped); an
        // unknown scene is then refused by the scene check like a file's.
        let quoted = toml::Value::String(scene.to_string()).to_string();
        let text = format!("name = {quoted}\nscene = {quoted}\n");
        SweepFile::parse_with(Path::new(&format!("--scene {scene}")), &text, sets)
    }

    /// Check a sweep file's text with `--set` arguments applied on top of it; `path` names
    /// the file in messages, the flag names an override.
    pub fn parse_with(path: &Path, text: &str, sets: &[String]) -> Result<SweepFile, SweepError> {
        let invalid = |issues: Vec<Issue>| invalid_file(path, sets, issues);
        let (top, mut ck) = overridden_tree(path, text, sets)?;
        ck.top_keys(&top);
        let name = ck.name(&top);
        ck.read_scene(&top);
        let description = ck.string(&top, "description").map(|(s, _)| s);
        let fixed = ck.fixed(&top);
        let grid = ck.grid(&top);
        let zip = ck.zip(&top);
        let exclude = ck.exclude(&top);
        let repeats = top_entry(&top, "repeats")
            .and_then(|(_, _, n)| ck.int("repeats", n, 1))
            .unwrap_or(1) as usize;
        let series_every = top_entry(&top, "series_every")
            .and_then(|(_, _, n)| ck.int("series_every", n, 0))
            .unwrap_or(1) as usize;
        let ensemble = ck.ensemble(&top);
        let summary = match top_entry(&top, "summary") {
            Some((_, line, node)) => ck.summary(*line, node),
            None => SummaryOptions::default(),
        };
        let (reference, reference_scene) = ck.reference(&top);
        let allow_unstable = ck.allow_unstable(&top);
        let search = match top_entry(&top, "search") {
            None => None,
            Some((_, line, node)) => parse_search(&mut ck, *line, node),
        };
        if let Some(sr) = &search {
            ck.search_conflicts(&top, sr, (&fixed, &grid, zip.as_ref()), ensemble.is_some());
        }
        let overridden = ck.overridden(&fixed, &grid, zip.as_ref());
        if ck.issues.is_empty() {
            Ok(SweepFile {
                path: path.to_path_buf(),
                text: text.to_string(),
                name,
                scene: ck.scene.expect("checked"),
                description,
                fixed,
                grid,
                zip,
                exclude,
                repeats,
                ensemble,
                series_every,
                overridden,
                reference,
                reference_scene,
                search,
                allow_unstable,
                summary,
                sets: sets.to_vec(),
            })
        } else {
            let mut issues = ck.issues;
            issues.sort();
            issues.dedup();
            Err(invalid(issues))
        }
    }
}

/// A top-level entry of a sweep text by its key.
fn top_entry<'a>(
    top: &'a [(String, usize, Node)],
    name: &str,
) -> Option<&'a (String, usize, Node)> {
    top.iter().find(|(k, _, _)| k == name)
}

/// The top-level sections of a sweep file, one method each, in the order
/// [`SweepFile::parse_with`] checks them.
impl Checker {
    /// Keys that are no section of a sweep file (a parameter written outside its table is
    /// told where it goes).
    fn top_keys(&mut self, top: &[(String, usize, Node)]) {
        for (k, line, _) in top {
            if !TOP_KEYS.contains(&k.as_str()) {
                let hint = if Key::from_name(k).is_some() {
                    " (parameters go in [fixed], [grid] or [zip])".to_string()
                } else {
                    suggest(k)
                };
                self.issue(
                    k,
                    *line,
                    format!(
                        "unknown top-level key{hint}; accepted: {}",
                        TOP_KEYS.join(", ")
                    ),
                );
            }
        }
    }

    /// A top-level string and its line; None when absent or not a string.
    fn string(&mut self, top: &[(String, usize, Node)], name: &str) -> Option<(String, usize)> {
        let (_, line, node) = top_entry(top, name)?;
        match &node.kind {
            Kind::Str(s) => Some((s.clone(), *line)),
            k => {
                self.issue(
                    name,
                    *line,
                    format!("expected a string, found a {}", k.type_name()),
                );
                None
            }
        }
    }

    /// `name`: required, folder-safe (it names the default output folder).
    fn name(&mut self, top: &[(String, usize, Node)]) -> String {
        match self.string(top, "name") {
            Some((n, line)) => {
                let ok = !n.is_empty()
                    && n.chars()
                        .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
                    && !n.starts_with('.');
                if !ok {
                    self.issue(
                        "name",
                        line,
                        "must be a non-empty folder-safe name (letters, digits, - _ .)",
                    );
                }
                n
            }
            None => {
                if top_entry(top, "name").is_none() {
                    self.issues.push(Issue {
                        line: None,
                        key: "name".into(),
                        reason: "required key missing (the sweep's name, also its default output folder)".into(),
                    });
                }
                String::new()
            }
        }
    }

    /// `scene`: required, one implemented; the parameters after it are checked against it.
    fn read_scene(&mut self, top: &[(String, usize, Node)]) {
        match self.string(top, "scene") {
            Some((s, line)) => match SceneKind::NAMES.iter().find(|(n, _)| *n == s) {
                Some((_, Some(kind))) => self.scene = Some(*kind),
                Some((_, None)) => self.issue(
                    "scene",
                    line,
                    format!(
                        "scene `{s}` is specified (contract §1) but not implemented in this version"
                    ),
                ),
                None => self.issue(
                    "scene",
                    line,
                    format!(
                        "unknown scene `{s}` (expected one of {})",
                        SceneKind::NAMES.map(|(n, _)| n).join(", ")
                    ),
                ),
            },
            None => {
                if top_entry(top, "scene").is_none() {
                    self.issues.push(Issue {
                        line: None,
                        key: "scene".into(),
                        reason: format!(
                            "required key missing (one of {})",
                            SceneKind::NAMES.map(|(n, _)| n).join(", ")
                        ),
                    });
                }
            }
        }
    }

    /// A top-level table's entries; empty when absent or not a table.
    fn table(&mut self, top: &[(String, usize, Node)], name: &str) -> Vec<(String, usize, Node)> {
        match top_entry(top, name) {
            None => Vec::new(),
            Some((
                _,
                _,
                Node {
                    kind: Kind::Table(t),
                    ..
                },
            )) => t.clone(),
            Some((_, line, node)) => {
                self.issue(
                    name,
                    *line,
                    format!("expected a table, found a {}", node.kind.type_name()),
                );
                Vec::new()
            }
        }
    }

    /// `[fixed]`: one value per parameter.
    fn fixed(&mut self, top: &[(String, usize, Node)]) -> Vec<Entry> {
        let mut fixed = Vec::new();
        for (k, line, v) in self.table(top, "fixed") {
            let p = format!("fixed.{k}");
            if let Some(key) = self.key(&k, &p, line) {
                if matches!(v.kind, Kind::Array(_)) && key.value_type() != ValueType::FloatList {
                    self.issue(
                        &p,
                        line,
                        "[fixed] takes one value; put lists in [grid] or [zip]",
                    );
                } else if let Some(e) = self.value(key, &v, &p) {
                    fixed.push(e);
                }
            }
        }
        fixed
    }

    /// `[grid]`: one axis per key, in file order.
    fn grid(&mut self, top: &[(String, usize, Node)]) -> Vec<Axis> {
        let mut grid = Vec::new();
        for (k, line, v) in self.table(top, "grid") {
            if let Some(ax) = self.axis("grid", &k, line, &v) {
                grid.push(ax);
            }
        }
        grid
    }

    /// `[zip]`: lists of equal lengths advanced together, as one axis named `a+b+…`.
    fn zip(&mut self, top: &[(String, usize, Node)]) -> Option<Axis> {
        let zip_entries = self.table(top, "zip");
        let mut zip_axes = Vec::new();
        for (k, line, v) in &zip_entries {
            if let Some(ax) = self.axis("zip", k, *line, v) {
                zip_axes.push((ax, *line));
            }
        }
        if zip_axes.is_empty() {
            return None;
        }
        let n = zip_axes[0].0.items.len();
        for (ax, line) in &zip_axes[1..] {
            if ax.items.len() != n {
                self.issue(
                    &format!("zip.{}", ax.name),
                    *line,
                    format!(
                        "has {} values but zip.{} has {n}: zipped lists must have equal lengths",
                        ax.items.len(),
                        zip_axes[0].0.name
                    ),
                );
            }
        }
        let items = (0..n)
            .map(|i| {
                zip_axes
                    .iter()
                    .flat_map(|(ax, _)| ax.items.get(i).cloned().unwrap_or_default())
                    .collect()
            })
            .collect();
        let names: Vec<&str> = zip_axes.iter().map(|(a, _)| a.name.as_str()).collect();
        Some(Axis {
            name: names.join("+"),
            items,
        })
    }

    /// `exclude = [{…}, …]`: filters, each a non-empty bundle of parameters.
    fn exclude(&mut self, top: &[(String, usize, Node)]) -> Vec<Vec<Entry>> {
        let mut exclude = Vec::new();
        if let Some((_, line, node)) = top_entry(top, "exclude") {
            match &node.kind {
                Kind::Array(items) => {
                    for (i, it) in items.iter().enumerate() {
                        let p = format!("exclude[{i}]");
                        match &it.kind {
                            Kind::Table(t) if !t.is_empty() => exclude.push(self.bundle(t, &p)),
                            _ => self.issue(&p, it.line, "expected a non-empty inline table of parameters, e.g. { space = \"mixed\", scheme = \"hybrid\" }"),
                        }
                    }
                }
                k => self.issue(
                    "exclude",
                    *line,
                    format!(
                        "expected a list of inline tables, found a {}",
                        k.type_name()
                    ),
                ),
            }
        }
        exclude
    }

    /// An integer ≥ `min` (`repeats`, `series_every`, the ensemble's counts).
    fn int(&mut self, path: &str, node: &Node, min: i64) -> Option<i64> {
        match node.kind {
            Kind::Int(i) if i >= min => Some(i),
            Kind::Int(i) => {
                self.issue(
                    path,
                    node.line,
                    format!("must be an integer ≥ {min}, got {i}"),
                );
                None
            }
            ref k => {
                self.issue(
                    path,
                    node.line,
                    format!("expected an integer, found a {}", k.type_name()),
                );
                None
            }
        }
    }

    /// `ensemble = { perturbation, samples, seed }`.
    fn ensemble(&mut self, top: &[(String, usize, Node)]) -> Option<Ensemble> {
        let (_, line, node) = top_entry(top, "ensemble")?;
        let Kind::Table(t) = &node.kind else {
            self.issue(
                "ensemble",
                *line,
                "expected an inline table { perturbation, samples, seed }",
            );
            return None;
        };
        let (mut pert, mut samples, mut seed) = (None, None, Some(0));
        for (k, kl, v) in t {
            let p = format!("ensemble.{k}");
            match k.as_str() {
                "perturbation" => match v.kind {
                    Kind::Float(x) if x >= 0.0 && x.is_finite() => pert = Some(x),
                    Kind::Int(i) if i >= 0 => pert = Some(i as f64),
                    _ => self.issue(&p, *kl, "expected a finite number ≥ 0 (relative amplitude of the perturbation of u⁰)"),
                },
                "samples" => samples = self.int(&p, v, 1),
                "seed" => seed = self.int(&p, v, 0),
                _ => self.issue(&p, *kl, "unknown key (expected perturbation, samples, seed)"),
            }
        }
        match (pert, samples, seed) {
            (Some(perturbation), Some(samples), Some(seed)) => Some(Ensemble {
                perturbation,
                samples: samples as usize,
                seed: seed as u64,
            }),
            _ => {
                self.issue(
                    "ensemble",
                    *line,
                    "needs perturbation and samples (seed optional)",
                );
                None
            }
        }
    }

    /// `reference = {…}`: the parameters that turn a run into its reference run, and the
    /// reference's scene when it names another (`scene = …`), for scenes whose errors come
    /// from a reference run.
    fn reference(
        &mut self,
        top: &[(String, usize, Node)],
    ) -> (Option<Vec<Entry>>, Option<SceneKind>) {
        let mut reference = None;
        let mut reference_scene = None;
        let Some((_, line, node)) = top_entry(top, "reference") else {
            return (reference, reference_scene);
        };
        let uses_reference = self.scene.map(|s| {
            let scene = s.get();
            let defaults = crate::scene::Physics(
                scene
                    .physics()
                    .iter()
                    .map(|k| (k.name, k.default))
                    .collect(),
            );
            scene.error_source(&defaults) == Some(crate::scene::ErrorSource::ReferenceRun)
        });
        match (&node.kind, uses_reference) {
            (_, Some(false)) => self.issue(
                "reference",
                *line,
                format!(
                    "scene {} has a closed-form solution (contract §1.1): errors are measured against it, a reference run is not used",
                    self.scene.map(|s| s.name()).unwrap_or_default()
                ),
            ),
            (Kind::Table(t), _) if !t.is_empty() => {
                // `scene` names the reference's scene; the other keys are that scene's
                // parameters, checked against it rather than against the sweep's.
                let (scene_entries, rest): (Vec<_>, Vec<_>) =
                    t.iter().cloned().partition(|(k, _, _)| k == "scene");
                if let Some((_, sl, node)) = scene_entries.first() {
                    match (&node.kind, self.scene) {
                        (Kind::Str(name), Some(own)) => match reference_scene_of(own, name) {
                            Ok(kind) => reference_scene = Some(kind),
                            Err(why) => self.issue("reference.scene", *sl, why),
                        },
                        (Kind::Str(_), None) => {}
                        (k, _) => self.issue(
                            "reference.scene",
                            *sl,
                            format!("expected a scene name, found a {}", k.type_name()),
                        ),
                    }
                }
                let own = self.scene;
                if reference_scene.is_some() {
                    self.scene = reference_scene;
                }
                let entries = self.bundle(&rest, "reference");
                self.scene = own;
                if !scene_entries.is_empty() && rest.is_empty() {
                    self.issue(
                        "reference",
                        *line,
                        "a reference of another scene needs its mesh and step (h or elements, dt or courant)",
                    );
                }
                reference = Some(entries);
            }
            (k, _) => self.issue(
                "reference",
                *line,
                format!(
                    "expected a non-empty inline table of parameters, e.g. {{ h = 0.0015625, dt = 0.00078125, mass = \"mod3\", scheme = \"crank-nicolson\" }}, found a {}",
                    k.type_name()
                ),
            ),
        }
        (reference, reference_scene)
    }

    /// `allow_unstable = true|false` (default false).
    fn allow_unstable(&mut self, top: &[(String, usize, Node)]) -> bool {
        match top_entry(top, "allow_unstable") {
            None => false,
            Some((
                _,
                _,
                Node {
                    kind: Kind::Bool(b),
                    ..
                },
            )) => *b,
            Some((_, line, node)) => {
                self.issue(
                    "allow_unstable",
                    *line,
                    format!("expected true or false, found a {}", node.kind.type_name()),
                );
                false
            }
        }
    }

    /// What a `[search]` cannot share the file with: its key set elsewhere (the search sets
    /// it) or an ensemble (each probe would be a whole ensemble). `set` is ([fixed], [grid],
    /// [zip]).
    fn search_conflicts(
        &mut self,
        top: &[(String, usize, Node)],
        sr: &Search,
        set: (&[Entry], &[Axis], Option<&Axis>),
        ensemble: bool,
    ) {
        let (fixed, grid, zip) = set;
        let set_elsewhere = fixed
            .iter()
            .chain(grid.iter().flat_map(|a| a.items.iter().flatten()))
            .chain(zip.iter().flat_map(|a| a.items.iter().flatten()))
            .find(|e| e.key == sr.key);
        if let Some(e) = set_elsewhere {
            self.issues.push(Issue::at(
                &e.origin,
                format!(
                    "`{}` is the key of [search]: the search sets it, remove it here",
                    sr.key.name()
                ),
            ));
        }
        if ensemble {
            self.issue(
                "search",
                *line_of_search(top),
                "a [search] cannot be combined with an ensemble (each probe would be a whole ensemble)",
            );
        }
    }

    /// [fixed] is the baseline that an axis may override (contract §7's own example sets h and dt
    /// in both [fixed] and [zip]); two axes setting one parameter would be ambiguous. Returns
    /// the notes of the [fixed] values overridden.
    fn overridden(&mut self, fixed: &[Entry], grid: &[Axis], zip: Option<&Axis>) -> Vec<String> {
        let mut sources: Vec<(Key, Origin, String)> = Vec::new();
        let mut overridden: Vec<String> = Vec::new();
        let axes = grid
            .iter()
            .map(|a| (a, format!("[grid] {}", a.name)))
            .chain(zip.iter().map(|a| (*a, "[zip]".to_string())));
        for (ax, source) in axes {
            for e in ax.items.iter().flatten() {
                if let Some((_, o, _)) =
                    sources.iter().find(|(k, _, s)| *k == e.key && *s != source)
                {
                    self.issues.push(Issue::at(
                        &e.origin,
                        format!(
                            "`{}` is also set by {} ({}): two axes may not set one parameter",
                            e.key.name(),
                            o.path,
                            line_ref(o.line, &self.sets)
                        ),
                    ));
                } else if !sources.iter().any(|(k, _, s)| *k == e.key && *s == source) {
                    sources.push((e.key, e.origin.clone(), source.clone()));
                }
                if let Some(f) = fixed.iter().find(|f| f.key == e.key) {
                    let note = format!("{} is overridden by {}", f.origin.path, source);
                    if !overridden.contains(&note) {
                        overridden.push(note);
                    }
                }
            }
        }
        overridden
    }
}

/// A sweep text's top-level entries: key, line, value.
type TopLevel = Vec<(String, usize, tree::Node)>;

/// The error of a sweep text with its `--set` arguments (`path` names the text in messages).
fn invalid_file(path: &Path, sets: &[String], issues: Vec<Issue>) -> SweepError {
    SweepError::Invalid {
        file: path.to_path_buf(),
        issues,
        sets: sets.to_vec(),
    }
}

/// A sweep text parsed into its top-level tree with the `--set` overrides applied, and the
/// checker that collects its issues: what `SweepFile::parse_with` and `summary_options` share.
fn overridden_tree(
    path: &Path,
    text: &str,
    sets: &[String],
) -> Result<(TopLevel, Checker), SweepError> {
    let parsed = overrides::parse(sets).map_err(SweepError::BadSet)?;
    let mut top = tree::parse(text).map_err(|e| {
        invalid_file(
            path,
            sets,
            vec![Issue {
                line: e.line,
                key: "(syntax)".into(),
                reason: format!("invalid TOML: {}", e.message),
            }],
        )
    })?;
    overrides::apply(&mut top, &parsed);
    let ck = Checker {
        scene: None,
        issues: Vec::new(),
        sets: sets.to_vec(),
    };
    Ok((top, ck))
}

/// Only the `[summary]` table of a sweep file's text with its `--set` arguments (the rest is
/// not checked): how `summarize DIR` reads the column choice back from the sweep file stored in
/// `DIR/manifest.json`, even when that file was written for another version. `path` names the
/// text in messages.
pub fn summary_options(
    path: &Path,
    text: &str,
    sets: &[String],
) -> Result<SummaryOptions, SweepError> {
    let (top, mut ck) = overridden_tree(path, text, sets)?;
    let out = match top.iter().find(|(k, _, _)| k == "summary") {
        Some((_, line, node)) => ck.summary(*line, node),
        None => SummaryOptions::default(),
    };
    if ck.issues.is_empty() {
        Ok(out)
    } else {
        Err(invalid_file(path, sets, ck.issues))
    }
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{} (line {l})", self.path),
            None => write!(f, "{}", self.path),
        }
    }
}

/// A plain-text table: columns padded to their widest cell (counted in characters), a dashed
/// rule under the header (the plan and the per-run result table).
pub fn render_table(header: &[String], rows: &[Vec<String>]) -> String {
    let mut width: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for r in rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: &[String]| {
        let mut s = String::new();
        for (i, (c, w)) in cells.iter().zip(&width).enumerate() {
            if i > 0 {
                s.push_str("  ");
            }
            s.push_str(c);
            s.push_str(&" ".repeat(w - c.chars().count()));
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(header);
    out.push_str(&line(
        &width.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>(),
    ));
    for r in rows {
        out.push_str(&line(r));
    }
    out
}

fn line_of_search(top: &[(String, usize, Node)]) -> &usize {
    top.iter()
        .find(|(k, _, _)| k == "search")
        .map(|(_, l, _)| l)
        .expect("called when [search] exists")
}

/// The fields of a `[search]` table as written, each of its type (unset: None, or the
/// default name and relative tolerance).
struct SearchFields {
    name: String,
    key: Option<Key>,
    lo: Option<f64>,
    hi: Option<f64>,
    criterion: Option<String>,
    tol: Option<f64>,
    eps: Option<f64>,
    column: Option<String>,
    rel_tol: f64,
    scale: Option<String>,
}

/// Check a `[search]` table.
fn parse_search(ck: &mut Checker, line: usize, node: &Node) -> Option<Search> {
    let Kind::Table(t) = &node.kind else {
        ck.issue(
            "search",
            line,
            format!("expected a table, found a {}", node.kind.type_name()),
        );
        return None;
    };
    let before = ck.issues.len();
    let f = ck.search_fields(t);
    let (key, lo, hi) = (f.key, f.lo, f.hi);
    let missing = |ck: &mut Checker, what: &str| {
        ck.issue("search", line, format!("needs `{what}`"));
    };
    if key.is_none() && !t.iter().any(|(k, _, _)| k == "key") {
        missing(ck, "key");
    }
    match (lo, hi) {
        (Some(a), Some(b)) if a < b => {}
        (Some(a), Some(b)) => ck.issue("search.hi", line, format!("must exceed lo ({a}), got {b}")),
        _ => missing(ck, "lo and hi"),
    }
    let log = match f.scale.as_deref() {
        None | Some("log") => lo.is_some_and(|a| a > 0.0),
        Some("linear") => false,
        Some(other) => {
            ck.issue(
                "search.scale",
                line,
                format!("expected \"log\" or \"linear\", got `{other}`"),
            );
            false
        }
    };
    if f.scale.as_deref() == Some("log") && lo.is_some_and(|a| a <= 0.0) {
        ck.issue("search.scale", line, "a log scale needs lo > 0");
    }
    let criterion = ck.search_criterion(line, &f);
    if ck.issues.len() > before {
        return None;
    }
    Some(Search {
        name: f.name,
        key: key?,
        lo: lo?,
        hi: hi?,
        criterion: criterion?,
        rel_tol: f.rel_tol,
        log,
    })
}

/// The parts of a `[search]` table.
impl Checker {
    /// A number of the `[search]` table.
    fn search_number(&mut self, p: &str, v: &Node) -> Option<f64> {
        match v.kind {
            Kind::Float(x) if x.is_finite() => Some(x),
            Kind::Int(i) => Some(i as f64),
            ref k => {
                self.issue(
                    p,
                    v.line,
                    format!("expected a number, found a {}", k.type_name()),
                );
                None
            }
        }
    }

    /// A string of the `[search]` table.
    fn search_text(&mut self, p: &str, v: &Node) -> Option<String> {
        match &v.kind {
            Kind::Str(s) => Some(s.clone()),
            k => {
                self.issue(
                    p,
                    v.line,
                    format!("expected a string, found a {}", k.type_name()),
                );
                None
            }
        }
    }

    /// The `[search]` table's fields, each checked for its type (and `key` for being a
    /// real-valued parameter, `rel_tol` for its range).
    fn search_fields(&mut self, t: &[(String, usize, Node)]) -> SearchFields {
        let mut f = SearchFields {
            name: "search".to_string(),
            key: None,
            lo: None,
            hi: None,
            criterion: None,
            tol: None,
            eps: None,
            column: None,
            rel_tol: 1e-3,
            scale: None,
        };
        for (k, kl, v) in t {
            let p = format!("search.{k}");
            match k.as_str() {
                "name" => {
                    if let Some(n) = self.search_text(&p, v) {
                        f.name = n;
                    }
                }
                "key" => {
                    if let Some(n) = self.search_text(&p, v) {
                        match Key::from_name(&n) {
                            Some(kk)
                                if kk.value_type() == ValueType::Float
                                    && !matches!(kk, Key::H | Key::Elements) =>
                            {
                                f.key = Some(kk)
                            }
                            Some(_) => self.issue(
                                &p,
                                *kl,
                                format!("`{n}` cannot be searched: the key must be a real-valued parameter other than h (e.g. courant, dt, nitsche_gamma0)"),
                            ),
                            None => self.issue(&p, *kl, format!("unknown parameter `{n}`{}", suggest(&n))),
                        }
                    }
                }
                "lo" => f.lo = self.search_number(&p, v),
                "hi" => f.hi = self.search_number(&p, v),
                "tol" => f.tol = self.search_number(&p, v),
                "eps" => f.eps = self.search_number(&p, v),
                "rel_tol" => {
                    if let Some(x) = self.search_number(&p, v) {
                        if x > 0.0 && x < 1.0 {
                            f.rel_tol = x;
                        } else {
                            self.issue(&p, *kl, format!("must lie in (0, 1), got {x}"));
                        }
                    }
                }
                "error" => f.column = self.search_text(&p, v),
                "scale" => f.scale = self.search_text(&p, v),
                "criterion" => f.criterion = self.search_text(&p, v),
                _ => self.issue(
                    &p,
                    *kl,
                    "unknown key (expected name, key, lo, hi, criterion, tol, eps, error, rel_tol, scale)",
                ),
            }
        }
        f
    }

    /// The `[search]` criterion with its threshold (`tol`, or `error` and `eps`).
    fn search_criterion(&mut self, line: usize, f: &SearchFields) -> Option<Criterion> {
        match f.criterion.as_deref() {
            Some("no-divergence") => Some(Criterion::NoDivergence),
            Some("energy-ratio-below") => match f.tol {
                Some(t) if t >= 0.0 => Some(Criterion::EnergyRatioBelow(t)),
                _ => {
                    self.issue(
                        "search.tol",
                        line,
                        "energy-ratio-below needs tol ≥ 0 (holds when E(T)/E⁰ ≤ 1 + tol)",
                    );
                    None
                }
            },
            Some("error-below") => {
                let column = f.column.clone().unwrap_or_else(|| "err_u_l2h1".into());
                if !search_error_columns().any(|c| c == column) {
                    let valid: Vec<&str> = search_error_columns().collect();
                    self.issue(
                        "search.error",
                        line,
                        format!(
                            "unknown error column `{column}` (one of {})",
                            valid.join(", ")
                        ),
                    );
                }
                match f.eps {
                    Some(e) if e > 0.0 => Some(Criterion::ErrorBelow { column, eps: e }),
                    _ => {
                        self.issue("search.eps", line, "error-below needs eps > 0");
                        None
                    }
                }
            }
            Some(other) => {
                self.issue(
                    "search.criterion",
                    line,
                    format!(
                        "unknown criterion `{other}` (no-divergence, energy-ratio-below, error-below)"
                    ),
                );
                None
            }
            None => {
                self.issue("search", line, "needs `criterion`");
                None
            }
        }
    }
}

impl Criterion {
    /// Whether a probe satisfies the criterion: it ended `ok` and, for the energy and error
    /// criteria, E(T)/E⁰ ≤ 1 + tol or the named column ≤ eps. `column` reads a column of the
    /// probe's row.
    pub fn holds(
        &self,
        status: &str,
        energy_initial: Option<f64>,
        energy_final: Option<f64>,
        column: impl Fn(&str) -> Option<f64>,
    ) -> bool {
        if status != "ok" {
            return false;
        }
        match self {
            Criterion::NoDivergence => true,
            Criterion::EnergyRatioBelow(tol) => match (energy_initial, energy_final) {
                (Some(e0), Some(e)) if e0 != 0.0 => e / e0 <= 1.0 + tol,
                _ => false,
            },
            Criterion::ErrorBelow { column: c, eps } => column(c).is_some_and(|x| x <= *eps),
        }
    }
}

/// Where a search stands, from the probes known so far.
#[derive(Debug, Clone, PartialEq)]
pub enum SearchState {
    /// Probe this value next (a bracket end not yet run, or the midpoint of the bracket).
    Probe(f64),
    /// The criterion is the same at lo and hi: no boundary in [lo, hi] (the value it has).
    NotBracketed(bool),
    /// The boundary lies between `holding` and `failing` (adjacent probes), within rel_tol.
    Found { holding: f64, failing: f64 },
}

impl Search {
    /// Next step of the bracket-then-bisect search, given (value, holds) of the probes run so
    /// far. The criterion is taken to change once in [lo, hi]; the bracket is the pair of
    /// adjacent probes, the one nearest lo where it changes, and it is halved (in log(key)
    /// when `log`) until (b − a)/max(|a|, |b|) ≤ rel_tol.
    pub fn state(&self, known: &[(f64, bool)]) -> SearchState {
        let at = |v: f64| {
            known
                .iter()
                .find(|(x, _)| (x - v).abs() <= 1e-12 * v.abs().max(1e-300))
                .map(|p| p.1)
        };
        let Some(lo_holds) = at(self.lo) else {
            return SearchState::Probe(self.lo);
        };
        let Some(hi_holds) = at(self.hi) else {
            return SearchState::Probe(self.hi);
        };
        if lo_holds == hi_holds {
            return SearchState::NotBracketed(lo_holds);
        }
        let mut pts: Vec<(f64, bool)> = known
            .iter()
            .copied()
            .filter(|(x, _)| *x >= self.lo && *x <= self.hi)
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        // The first change of the criterion, walking up from lo.
        let k = pts
            .windows(2)
            .position(|w| w[0].1 == lo_holds && w[1].1 != lo_holds)
            .expect("lo and hi differ, so the criterion changes somewhere");
        let (a, b) = (pts[k].0, pts[k + 1].0);
        let (holding, failing) = if lo_holds { (a, b) } else { (b, a) };
        if (b - a) / a.abs().max(b.abs()) <= self.rel_tol {
            return SearchState::Found { holding, failing };
        }
        SearchState::Probe(if self.log {
            (a * b).sqrt()
        } else {
            0.5 * (a + b)
        })
    }

    /// Parse a probe's tag ([`plan::search_tag`]) back: the search and the base index.
    pub fn from_tag(tag: &str) -> Option<(Search, usize)> {
        let mut map = std::collections::HashMap::new();
        for part in tag.split(';') {
            let (k, v) = part.split_once('=')?;
            map.insert(k, v);
        }
        let num = |k: &str| map.get(k)?.parse::<f64>().ok();
        let criterion = match *map.get("criterion")? {
            "no-divergence" => Criterion::NoDivergence,
            "energy-ratio-below" => Criterion::EnergyRatioBelow(num("tol")?),
            "error-below" => Criterion::ErrorBelow {
                column: map.get("error")?.to_string(),
                eps: num("eps")?,
            },
            _ => return None,
        };
        let (lo, hi) = (num("lo")?, num("hi")?);
        Some((
            Search {
                name: map.get("name")?.to_string(),
                key: Key::from_name(map.get("key")?)?,
                lo,
                hi,
                criterion,
                rel_tol: num("rel_tol")?,
                log: lo > 0.0,
            },
            map.get("base")?.parse().ok()?,
        ))
    }
}

#[cfg(test)]
mod search_tests {
    use super::*;

    fn search(log: bool) -> Search {
        Search {
            name: "s".into(),
            key: Key::Courant,
            lo: 0.5,
            hi: 8.0,
            criterion: Criterion::NoDivergence,
            rel_tol: 1e-3,
            log,
        }
    }

    /// Bisection against a step function at 1.7 converges to it within rel_tol, probing
    /// lo, hi, then geometric midpoints: log2(log(16)/1e-3) ≈ 12 halvings.
    #[test]
    fn bisection_brackets_a_threshold_to_the_relative_tolerance() {
        for log in [true, false] {
            let s = search(log);
            let mut known = Vec::new();
            let mut probes = 0;
            let found = loop {
                match s.state(&known) {
                    SearchState::Probe(v) => {
                        probes += 1;
                        known.push((v, v <= 1.7));
                    }
                    SearchState::Found { holding, failing } => break (holding, failing),
                    SearchState::NotBracketed(_) => panic!("bracketed"),
                }
                assert!(probes < 40);
            };
            assert!(found.0 <= 1.7 && found.1 > 1.7, "{found:?}");
            assert!((found.1 - found.0) / found.1 <= 1e-3);
            assert!(probes <= 16, "{probes} probes");
        }
        let s = search(true);
        assert_eq!(
            s.state(&[(0.5, true), (8.0, true)]),
            SearchState::NotBracketed(true)
        );
        let tag = plan::search_tag(&s, 3);
        assert_eq!(Search::from_tag(&tag), Some((s, 3)));
    }
}
