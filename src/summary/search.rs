//! Boundaries found by `[search]`: for every searched method, the bracket [lo, hi], what the
//! criterion said at its ends, and the boundary — the adjacent pair of probes between which
//! the criterion changes, the last value where it holds and the first where it fails.
//!
//! The table is rebuilt from the rows alone: each probe carries its search's tag (name, key,
//! criterion and threshold, bracket, relative tolerance, method index;
//! [`crate::sweep::plan::search_tag`]), so the criterion is re-judged here with the same
//! [`crate::sweep::Criterion::holds`] the bisection used, and a folder of a resumed or
//! interrupted search is summarised as far as it got ([`crate::sweep::Search::state`]).

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::columns::columns;
use super::runs::{Run, Runs};
use super::table::{self, Table, TextTable, text_columns};
use crate::sweep::{Search, SearchState};

/// The search section's outputs.
pub(crate) struct Section {
    pub table: Table,
    pub markdown: String,
    pub terminal: String,
}

fn key_value(runs: &Runs, r: &Run, key: &str) -> Option<f64> {
    match key {
        "courant" => r.courant,
        "dt" => r.dt,
        "h" => r.h,
        other => runs.param_f64(r, other),
    }
}

fn column(runs: &Runs, r: &Run, name: &str) -> Option<f64> {
    if name == "energy_drift" {
        return r.energy_drift;
    }
    let j = runs.errors.iter().position(|e| *e == name)?;
    r.errors[j]
}

/// The method of a base: contact treatment (with Θ, γ0 unless searched), mass, scheme.
fn method_text(runs: &Runs, r: &Run, key: &str) -> String {
    let p = |n: &str| runs.param_str(r, n).unwrap_or("").to_string();
    let mut space = p("space");
    let extra: Vec<String> = [
        ("nitsche_theta", "Θ"),
        ("nitsche_gamma0", "γ0"),
        ("penalty_gamma0", "γ0"),
    ]
    .iter()
    .filter(|(n, _)| *n != key)
    .filter_map(|(n, sym)| runs.param_f64(r, n).map(|v| format!("{sym}={v}")))
    .collect();
    if !extra.is_empty() {
        space = format!("{space}({})", extra.join(", "));
    }
    let scheme = runs
        .param_str(r, "scheme_label")
        .or(runs.param_str(r, "scheme"))
        .unwrap_or("");
    format!("{space} · {} · {scheme}", p("mass"))
}

/// Build the boundary table.
pub(crate) fn section(runs: &Runs) -> Section {
    let mut t = Table::new(
        &columns![
            search: Str, key: Str, criterion: Str, threshold: F64, method: Str, base: I64,
            lo: F64, hi: F64, holds_at_lo: Bool, holds_at_hi: Bool, state: Str, last_holding: F64,
            first_failing: F64, boundary: F64, rel_width: F64, rel_tol: F64, probes: I64,
            failing_status: Str,
        ]
        .map(|(n, k)| (n.to_string(), k)),
    );
    let mut by_tag: BTreeMap<(String, usize), (Search, Vec<usize>)> = BTreeMap::new();
    for (i, r) in runs.runs.iter().enumerate() {
        let Some((s, base)) = r.search.as_deref().and_then(Search::from_tag) else {
            continue;
        };
        by_tag
            .entry((s.name.clone(), base))
            .or_insert((s, Vec::new()))
            .1
            .push(i);
    }
    let mut md = String::from("# Boundaries found by bisection\n\n");
    let mut terminal = String::new();
    let mut rows_md = Vec::new();
    for ((name, base), (s, idx)) in &by_tag {
        let known: Vec<(f64, bool, usize)> = idx
            .iter()
            .filter_map(|&i| {
                let r = &runs.runs[i];
                let v = key_value(runs, r, s.key.name())?;
                let holds = s
                    .criterion
                    .holds(&r.status, r.energy_initial, r.energy_final, |c| {
                        column(runs, r, c)
                    });
                Some((v, holds, i))
            })
            .collect();
        let pairs: Vec<(f64, bool)> = known.iter().map(|k| (k.0, k.1)).collect();
        let at = |v: f64| {
            known
                .iter()
                .find(|k| (k.0 - v).abs() <= 1e-9 * v.abs().max(1e-300))
                .map(|k| k.1)
        };
        let state = s.state(&pairs);
        let (st, holding, failing) = match state {
            SearchState::Found { holding, failing } => ("found", Some(holding), Some(failing)),
            SearchState::NotBracketed(true) => ("holds everywhere", None, None),
            SearchState::NotBracketed(false) => ("fails everywhere", None, None),
            SearchState::Probe(_) => ("unfinished", None, None),
        };
        let boundary = holding.zip(failing).map(|(a, b)| {
            if s.log && a > 0.0 && b > 0.0 {
                (a * b).sqrt()
            } else {
                0.5 * (a + b)
            }
        });
        let width = holding
            .zip(failing)
            .map(|(a, b)| (a - b).abs() / a.abs().max(b.abs()));
        let failing_status = failing.and_then(|f| {
            known
                .iter()
                .find(|k| k.0 == f)
                .map(|k| runs.runs[k.2].status.clone())
        });
        let method = method_text(runs, &runs.runs[idx[0]], s.key.name());
        let threshold = match &s.criterion {
            crate::sweep::Criterion::NoDivergence => None,
            crate::sweep::Criterion::EnergyRatioBelow(t) => Some(*t),
            crate::sweep::Criterion::ErrorBelow { eps, .. } => Some(*eps),
        };
        t.str("search", Some(name));
        t.str("key", Some(s.key.name()));
        t.str("criterion", Some(s.criterion.name()));
        t.f64("threshold", threshold);
        t.str("method", Some(&method));
        t.i64("base", Some(*base as i64));
        t.f64("lo", Some(s.lo));
        t.f64("hi", Some(s.hi));
        t.bool("holds_at_lo", at(s.lo));
        t.bool("holds_at_hi", at(s.hi));
        t.str("state", Some(st));
        t.f64("last_holding", holding);
        t.f64("first_failing", failing);
        t.f64("boundary", boundary);
        t.f64("rel_width", width);
        t.f64("rel_tol", Some(s.rel_tol));
        t.i64("probes", Some(known.len() as i64));
        t.str("failing_status", failing_status.as_deref());
        t.end_row();
        rows_md.push(vec![
            name.clone(),
            method.clone(),
            s.key.name().to_string(),
            s.criterion.name().to_string(),
            format!("[{}, {}]", s.lo, s.hi),
            st.to_string(),
            table::sci(holding),
            table::sci(failing),
            known.len().to_string(),
        ]);
        let _ = writeln!(
            terminal,
            "  {name}: {method}: {} {st}{}",
            s.key.name(),
            match (holding, failing) {
                (Some(a), Some(b)) => format!(
                    ", {} holds at {} and fails at {}",
                    s.criterion.name(),
                    table::sci(Some(a)),
                    table::sci(Some(b))
                ),
                _ => String::new(),
            }
        );
    }
    if rows_md.is_empty() {
        md.push_str("No [search] in this folder.\n");
    } else {
        md.push_str(
            "Per searched method: the criterion at the bracket ends and the adjacent probes \
             between which it changes (bisection to the search's relative tolerance; every \
             probe is a row of runs/ tagged with its search).\n\n",
        );
        let text = TextTable::new(text_columns![
            "search" => Left, "method" => Left, "key" => Left, "criterion" => Left,
            "bracket" => Left, "state" => Left, "last holding" => Right, "first failing" => Right,
            "probes" => Right,
        ]);
        let searched = rows_md.len();
        md.push_str(&text.with_rows(rows_md).markdown());
        terminal.insert_str(0, &format!("boundaries ({searched} searched methods):\n"));
    }
    Section {
        table: t,
        markdown: md,
        terminal,
    }
}
