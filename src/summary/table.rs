//! Output plumbing shared by the summary tables: a typed column builder that becomes a polars
//! `DataFrame` (written as Parquet and CSV), and the text formatting of Markdown and LaTeX
//! (booktabs) tables.
//!
//! Tables are built row by row because the per-group arithmetic is plain Rust; every column is
//! declared up front so that a table with no rows still has its schema (a reader filtering an
//! empty `impacts.parquet` must find the columns, not fail on them).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use polars::prelude::*;

use super::columns::Kind;
use super::runs::{Cell, Run, Runs};

/// A text table's declared columns, several to a line: `text_columns!["#" => Right, "label" =>
/// Left, …]` — each header with its [`Align`] — as [`TextTable::new`] takes them.
macro_rules! text_columns {
    ($($header:expr => $align:ident),* $(,)?) => {
        [$(($header, $crate::summary::table::Align::$align)),*]
    };
}
pub(crate) use text_columns;

/// Declared columns with owned names (a table's own, before the parameter columns that vary
/// by folder are appended).
pub(crate) fn owned(list: &[(&str, Kind)]) -> Vec<(String, Kind)> {
    list.iter().map(|(n, k)| (n.to_string(), *k)).collect()
}

/// A table's own columns, then the folder's parameter columns (every parameter that varies).
pub(crate) fn with_params(list: &[(&str, Kind)], runs: &Runs) -> Vec<(String, Kind)> {
    let mut c = owned(list);
    c.extend(runs.param_columns());
    c
}

/// A text column without one allocation per cell: the cells' bytes in one buffer, each cell
/// a byte range of it (None: null). The impacts table has ~10⁴ rows of a dozen text cells.
#[derive(Debug, Clone, Default)]
struct StrValues {
    buf: String,
    spans: Vec<Option<(usize, usize)>>,
}

impl StrValues {
    fn push(&mut self, x: Option<&str>) {
        self.spans.push(x.map(|x| {
            let start = self.buf.len();
            self.buf.push_str(x);
            (start, self.buf.len())
        }));
    }

    fn iter(&self) -> impl Iterator<Item = Option<&str>> {
        self.spans.iter().map(|s| s.map(|(a, b)| &self.buf[a..b]))
    }
}

#[derive(Debug, Clone)]
enum Values {
    F64(Vec<Option<f64>>),
    I64(Vec<Option<i64>>),
    Str(StrValues),
    Bool(Vec<Option<bool>>),
}

impl Values {
    fn new(kind: Kind) -> Self {
        match kind {
            Kind::F64 => Values::F64(Vec::new()),
            Kind::I64 => Values::I64(Vec::new()),
            Kind::Str => Values::Str(StrValues::default()),
            Kind::Bool => Values::Bool(Vec::new()),
        }
    }

    fn len(&self) -> usize {
        match self {
            Values::F64(v) => v.len(),
            Values::I64(v) => v.len(),
            Values::Str(v) => v.spans.len(),
            Values::Bool(v) => v.len(),
        }
    }

    fn push_null(&mut self) {
        match self {
            Values::F64(v) => v.push(None),
            Values::I64(v) => v.push(None),
            Values::Str(v) => v.spans.push(None),
            Values::Bool(v) => v.push(None),
        }
    }
}

/// A table under construction: declared columns, filled one row at a time. A column not set
/// in a row is null in that row.
#[derive(Debug, Clone)]
pub(crate) struct Table {
    names: Vec<String>,
    values: Vec<Values>,
    index: HashMap<String, usize>,
    rows: usize,
    /// The column after the one set last: rows are filled in declaration order, so the next
    /// name is almost always this one (a string comparison instead of a hash lookup per cell).
    next: usize,
}

impl Table {
    pub(crate) fn new(columns: &[(String, Kind)]) -> Self {
        let mut t = Table {
            names: Vec::new(),
            values: Vec::new(),
            index: HashMap::new(),
            rows: 0,
            next: 0,
        };
        for (name, kind) in columns {
            // A name declared twice keeps its first declaration (parameter columns are appended
            // after the fixed ones and must not shadow them).
            if !t.index.contains_key(name) {
                t.index.insert(name.clone(), t.names.len());
                t.names.push(name.clone());
                t.values.push(Values::new(*kind));
            }
        }
        t
    }

    fn slot(&mut self, name: &str) -> &mut Values {
        let i = if self.names.get(self.next).is_some_and(|n| n == name) {
            self.next
        } else {
            *self
                .index
                .get(name)
                .unwrap_or_else(|| panic!("summary table: column `{name}` was not declared"))
        };
        self.next = i + 1;
        let rows = self.rows;
        let v = &mut self.values[i];
        assert_eq!(
            v.len(),
            rows,
            "summary table: column `{name}` set twice in one row"
        );
        v
    }

    pub(crate) fn f64(&mut self, name: &str, x: Option<f64>) {
        match self.slot(name) {
            // NaN is a missing value in every output (Parquet readers disagree on NaN, and a
            // NaN in a Markdown table reads as a bug).
            Values::F64(v) => v.push(x.filter(|x| !x.is_nan())),
            _ => panic!("summary table: column `{name}` is not f64"),
        }
    }

    pub(crate) fn i64(&mut self, name: &str, x: Option<i64>) {
        match self.slot(name) {
            Values::I64(v) => v.push(x),
            _ => panic!("summary table: column `{name}` is not i64"),
        }
    }

    pub(crate) fn str(&mut self, name: &str, x: Option<&str>) {
        match self.slot(name) {
            Values::Str(v) => v.push(x),
            _ => panic!("summary table: column `{name}` is not a string"),
        }
    }

    pub(crate) fn bool(&mut self, name: &str, x: Option<bool>) {
        match self.slot(name) {
            Values::Bool(v) => v.push(x),
            _ => panic!("summary table: column `{name}` is not bool"),
        }
    }

    /// A run's method group: `group` (numbered from 1) and `group_title`.
    pub(crate) fn run_group(&mut self, runs: &Runs, r: &Run) {
        self.i64("group", Some(r.group as i64 + 1));
        self.str("group_title", Some(&runs.groups[r.group].title));
    }

    /// The cells every per-run table names a run by: `run_id`, `label`, `status`.
    pub(crate) fn run_identity(&mut self, r: &Run) {
        self.str("run_id", Some(&r.run_id));
        self.str("label", Some(&r.label));
        self.str("status", Some(&r.status));
    }

    /// A run's level: `h`, `dt`, `courant`.
    pub(crate) fn run_level(&mut self, r: &Run) {
        self.f64("h", r.h);
        self.f64("dt", r.dt);
        self.f64("courant", r.courant);
    }

    pub(crate) fn cell(&mut self, name: &str, c: &Cell) {
        match c {
            Cell::F64(x) => self.f64(name, *x),
            Cell::I64(x) => self.i64(name, *x),
            Cell::Str(x) => self.str(name, x.as_deref()),
        }
    }

    /// Rows closed so far.
    pub(crate) fn height(&self) -> usize {
        self.rows
    }

    /// Close the current row: columns not set are null.
    pub(crate) fn end_row(&mut self) {
        for v in &mut self.values {
            if v.len() == self.rows {
                v.push_null();
            }
        }
        self.rows += 1;
        self.next = 0;
    }

    pub(crate) fn to_frame(&self) -> PolarsResult<DataFrame> {
        let cols = self
            .names
            .iter()
            .zip(&self.values)
            .map(|(n, v)| {
                let name: PlSmallStr = n.as_str().into();
                match v {
                    Values::F64(x) => Column::new(name, x),
                    Values::I64(x) => Column::new(name, x),
                    Values::Str(x) => {
                        let mut b = StringChunkedBuilder::new(name, x.spans.len());
                        for v in x.iter() {
                            b.append_option(v);
                        }
                        b.finish().into_column()
                    }
                    Values::Bool(x) => Column::new(name, x),
                }
            })
            .collect();
        DataFrame::new(self.rows, cols)
    }
}

/// Write `table` as `dir/stem.parquet` and `dir/stem.csv`, both atomically. Returns the paths.
pub(crate) fn write_table(dir: &Path, stem: &str, table: &Table) -> anyhow::Result<Vec<PathBuf>> {
    let mut df = table
        .to_frame()
        .map_err(anyhow::Error::new)
        .with_context(|| format!("building {stem} table"))?;
    let parquet = format!("{stem}.parquet");
    crate::sink::write_frame_atomic(dir, &parquet, &mut df, crate::sink::Durability::Derived)?;
    // Sized up front (≈ 12 bytes a cell): growing an 8 MB impacts.csv by doubling copied it
    // and faulted in fresh pages about as often as it was written. Capacity never written is
    // never touched.
    let mut csv = Vec::with_capacity(df.height() * df.width() * 12);
    CsvWriter::new(&mut csv)
        .finish(&mut df)
        .map_err(anyhow::Error::new)
        .with_context(|| format!("{}: csv", dir.join(format!("{stem}.csv")).display()))?;
    let csv_path = dir.join(format!("{stem}.csv"));
    crate::sink::write_derived(&csv_path, &csv)?;
    Ok(vec![dir.join(parquet), csv_path])
}

/// Write text atomically; returns the path.
pub(crate) fn write_text(dir: &Path, name: &str, text: &str) -> anyhow::Result<PathBuf> {
    let path = dir.join(name);
    crate::sink::write_derived(&path, text.as_bytes())?;
    Ok(path)
}

/// Alignment of a Markdown column.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Align {
    Left,
    Right,
}

/// A text table declared column by column — each column its header with its alignment — and
/// filled row by row; one renderer per format ([`markdown`], [`plain`]) serves every table.
#[derive(Debug, Clone, Default)]
pub(crate) struct TextTable {
    header: Vec<String>,
    align: Vec<Align>,
    rows: Vec<Vec<String>>,
}

impl TextTable {
    pub(crate) fn new<S: Into<String>>(cols: impl IntoIterator<Item = (S, Align)>) -> Self {
        let (header, align) = cols.into_iter().map(|(h, a)| (h.into(), a)).unzip();
        TextTable {
            header,
            align,
            rows: Vec::new(),
        }
    }

    /// The table with these rows (built before the columns were declared).
    pub(crate) fn with_rows(mut self, rows: Vec<Vec<String>>) -> Self {
        self.rows = rows;
        self
    }

    pub(crate) fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    pub(crate) fn header(&self) -> &[String] {
        &self.header
    }

    pub(crate) fn rows(&self) -> &[Vec<String>] {
        &self.rows
    }

    /// Whether each column is right-aligned (the report's HTML tables).
    pub(crate) fn right(&self) -> Vec<bool> {
        self.align
            .iter()
            .map(|a| matches!(a, Align::Right))
            .collect()
    }

    pub(crate) fn markdown(&self) -> String {
        markdown(&self.header, &self.align, &self.rows)
    }

    pub(crate) fn plain(&self) -> String {
        plain(&self.header, &self.align, &self.rows)
    }
}

/// A GitHub-flavoured Markdown table. `|` inside cells is escaped.
fn markdown(header: &[String], align: &[Align], rows: &[Vec<String>]) -> String {
    let esc = |s: &str| s.replace('|', "\\|");
    let mut out = String::new();
    out.push_str("| ");
    out.push_str(
        &header
            .iter()
            .map(|h| esc(h))
            .collect::<Vec<_>>()
            .join(" | "),
    );
    out.push_str(" |\n|");
    for i in 0..header.len() {
        out.push_str(match align.get(i).copied().unwrap_or(Align::Right) {
            Align::Left => ":---|",
            Align::Right => "---:|",
        });
    }
    out.push('\n');
    for r in rows {
        out.push_str("| ");
        out.push_str(&r.iter().map(|c| esc(c)).collect::<Vec<_>>().join(" | "));
        out.push_str(" |\n");
    }
    out
}

/// A plain-text table for the terminal: columns padded to their widest cell (counted in
/// characters, the labels carry Θ, γ, ·).
fn plain(header: &[String], align: &[Align], rows: &[Vec<String>]) -> String {
    let n = header.len();
    let mut width = vec![0usize; n];
    for r in std::iter::once(header).chain(rows.iter().map(|r| r.as_slice())) {
        for (i, c) in r.iter().enumerate().take(n) {
            width[i] = width[i].max(c.chars().count());
        }
    }
    let line = |r: &[String]| {
        let mut s = String::from(" ");
        for (i, c) in r.iter().enumerate().take(n) {
            let pad = width[i] - c.chars().count();
            match align.get(i).copied().unwrap_or(Align::Right) {
                Align::Left => {
                    s.push_str(c);
                    s.push_str(&" ".repeat(pad));
                }
                Align::Right => {
                    s.push_str(&" ".repeat(pad));
                    s.push_str(c);
                }
            }
            s.push_str("  ");
        }
        s.trim_end().to_string() + "\n"
    };
    let mut out = line(header);
    for r in rows {
        out.push_str(&line(r));
    }
    out
}

/// `1.2346e-2`: four significant decimals, enough to recompute a rate to about 1e-4.
pub(crate) fn sci(x: Option<f64>) -> String {
    match x {
        Some(x) if x.is_finite() => format!("{x:.4e}"),
        Some(x) => format!("{x}"),
        None => String::new(),
    }
}

/// A rate or slope: two decimals, as deal.II's ConvergenceTable prints them.
pub(crate) fn rate(x: Option<f64>) -> String {
    match x {
        Some(x) if x.is_finite() => format!("{x:.2}"),
        Some(x) => format!("{x}"),
        None => String::new(),
    }
}

/// LaTeX-safe text: the ASCII specials and the non-ASCII characters of the run labels.
pub(crate) fn tex(s: &str) -> String {
    // A math symbol as `$…$`, joined with a math span just before it: "ρ∞" must read
    // `$\rho\infty$`, since `$\rho$$\infty$` opens display math in LaTeX's text mode.
    fn math(out: &mut String, inner: &str) {
        let escaped = out.ends_with("\\$");
        if out.ends_with('$') && !escaped {
            out.pop();
        } else {
            out.push('$');
        }
        out.push_str(inner);
        out.push('$');
    }
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        // γ0 in the labels is the Nitsche parameter γ₀.
        if c == 'γ' && chars.peek() == Some(&'0') {
            chars.next();
            math(&mut out, "\\gamma_0");
            continue;
        }
        let symbol = match c {
            '·' => "\\cdot",
            'Θ' => "\\Theta",
            'Φ' => "\\Phi",
            'α' => "\\alpha",
            'β' => "\\beta",
            'γ' => "\\gamma",
            'δ' => "\\delta",
            'ε' => "\\varepsilon",
            'θ' => "\\theta",
            'κ' => "\\kappa",
            'λ' => "\\lambda",
            'μ' => "\\mu",
            'ν' => "\\nu",
            'ρ' => "\\rho",
            'σ' => "\\sigma",
            'τ' => "\\tau",
            '∞' => "\\infty",
            '∝' => "\\propto",
            '×' => "\\times",
            '≤' => "\\le",
            '≥' => "\\ge",
            '→' => "\\to",
            _ => "",
        };
        if !symbol.is_empty() {
            math(&mut out, symbol);
            continue;
        }
        match c {
            '\\' => out.push_str("\\textbackslash{}"),
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                out.push('\\');
                out.push(c);
            }
            '~' => out.push_str("\\textasciitilde{}"),
            '^' => out.push_str("\\textasciicircum{}"),
            '−' => out.push('-'),
            c => out.push(c),
        }
    }
    out
}

/// A rate in LaTeX (math minus sign).
pub(crate) fn tex_rate(x: Option<f64>) -> String {
    match x {
        Some(x) if x.is_finite() => format!("${x:.2}$"),
        Some(x) => tex(&format!("{x}")),
        None => String::new(),
    }
}

/// Engineering format of the terminal: four significant digits, plain for 1e-2 ≤ |x| < 1e4
/// (`1.003`, `0.3782`, `1235`), otherwise mantissa `e` exponent (`1.235e-5`, `2.5e4` is
/// `2.500e4`); 0 prints as `0`. One format for every number of the terminal, so columns read
/// alike and a reader never meets `1.0025e0`. The rounding is done once, by the exponent
/// form, so the exponent that decides plain or not is the one of the rounded value (9.9996
/// rounds to 10.00, not 9.9996 → "10.000").
pub fn eng(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let s = format!("{x:.3e}");
    let (mantissa, exp) = s.split_once('e').expect("exponent form");
    let exp: i32 = exp.parse().expect("integer exponent");
    if (-2..4).contains(&exp) {
        let decimals = (3 - exp) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{mantissa}e{exp}")
    }
}

/// [`eng`] of an optional value; a missing one prints as `—`.
pub(crate) fn eng_opt(x: Option<f64>) -> String {
    x.map(eng).unwrap_or_else(|| "—".into())
}

/// The terminal's short name of an error column and its legend entry: columns are narrow, and
/// every abbreviation is explained once under the table.
pub(crate) fn error_abbrev(column: &str) -> (&'static str, &'static str) {
    match column {
        "err_u_l2l2" => ("l2(τ;L2)", "displacement error in l2(0,T;L2)"),
        "err_u_l2h1" => ("l2(τ;H1)", "displacement error in l2(0,T;H1)"),
        "err_u_linfl2" => ("l∞(τ;L2)", "displacement error in l∞(0,T;L2)"),
        "err_sigma_l2" => (
            "σ l2(τ)",
            "contact pressure error at the time levels, l2(0,T)",
        ),
        "err_sigma_mid_l2" => (
            "σ½ l2(τ)",
            "contact pressure error at the midpoints t^(n+½), l2(0,T)",
        ),
        "err_energy_l2" => ("E l2(τ)", "energy error E^h − E, l2(0,T)"),
        "err_u_contact_max" => ("u_C max", "max error of the contact displacement"),
        "err_sigma_t_l2" => (
            "σ_t l2(τ)",
            "tangential stress error of the layer's base, l2(0,T)",
        ),
        "err_vt_final" => ("v_t(T)", "error of the mean tangential velocity at T"),
        _ => ("?", "unknown error column"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn engineering_format_is_four_significant_digits() {
        assert_eq!(eng(1.0025), "1.002"); // 1.0025 is 1.00249999… in binary
        assert_eq!(eng(0.37816), "0.3782");
        assert_eq!(eng(0.012345), "0.01235");
        assert_eq!(eng(0.0099996), "0.01000");
        assert_eq!(eng(0.0012345), "1.234e-3");
        assert_eq!(eng(1234.5), "1234");
        assert_eq!(eng(9999.6), "1.000e4");
        assert_eq!(eng(9.9996), "10.00");
        assert_eq!(eng(-2.5e-7), "-2.500e-7");
        assert_eq!(eng(0.0), "0");
        assert_eq!(eng(f64::INFINITY), "inf");
        assert_eq!(eng_opt(None), "—");
    }
}
