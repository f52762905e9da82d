//! The time series the report draws, read from `DIR/series`: for one run per method group,
//! the contact displacement and pressure, the energy, their exact values, for frictional
//! runs the frictional work and the slip velocity, and for two-body runs B's contact
//! displacement and the total momentum — only those runs' rows and those columns.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use crate::summary::runs;

/// One time series of a run: (t, u_C), (t, σ_C), (t, E), exact (t, u_C), (t, σ_C).
#[derive(Default)]
pub(super) struct RunSeries {
    pub u: Vec<(f64, f64)>,
    pub sigma: Vec<(f64, f64)>,
    pub energy: Vec<(f64, f64)>,
    pub u_exact: Vec<(f64, f64)>,
    pub sigma_exact: Vec<(f64, f64)>,
    /// Frictional runs (null columns otherwise): (t, E, W_f) where both are recorded, and
    /// (t, v_t) the contact node's slip velocity.
    pub balance: Vec<(f64, f64, f64)>,
    pub v_t: Vec<(f64, f64)>,
    /// Two-body runs (null columns otherwise): (t, u_C^b) B's contact displacement and
    /// (t, P) the total momentum.
    pub u_b: Vec<(f64, f64)>,
    pub momentum: Vec<(f64, f64)>,
}

/// The series of the runs `chosen`, in time order. Only the series parts that hold them are
/// read (the sink names a batch's series part like its runs part, which `runs::load` records
/// per run); of a part, first its `run_id` column (dictionary-encoded: a few bytes a run), then
/// only the rows of the chosen runs and only the columns drawn, the page index skipping the
/// pages of the other runs (`sink::parquet::read_rows_f64`).
pub(super) fn read_series(
    dir: &Path,
    chosen: &[&runs::Run],
) -> anyhow::Result<HashMap<String, RunSeries>> {
    use crate::sink::parquet as pq;
    let mut out: HashMap<String, RunSeries> = HashMap::new();
    let folder = dir.join("series");
    if !folder.exists() || chosen.is_empty() {
        return Ok(out);
    }
    // A run without its part's name (not known to the loader) means: read every part.
    let parts: Option<HashSet<String>> = chosen.iter().map(|r| r.part.clone()).collect();
    let wanted: HashSet<&str> = chosen.iter().map(|r| r.run_id.as_str()).collect();
    // The friction and two-body columns are absent from the parts of runs without them: read
    // as nulls, nothing drawn.
    const DRAWN: [&str; 10] = [
        "t",
        "u_contact",
        "sigma_contact",
        "energy",
        "u_contact_exact",
        "sigma_contact_exact",
        "friction_work",
        "v_t_contact",
        "u_contact_b",
        "momentum",
    ];
    for part in crate::sink::parquet_parts(&folder)? {
        let name = part
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if parts.as_ref().is_some_and(|p| !p.contains(&name)) {
            continue;
        }
        // An unreadable part is skipped: `summarize` warns about it (sink::unreadable_parts).
        let Ok(ranges) = pq::run_ranges(&part, &wanted) else {
            continue;
        };
        if ranges.is_empty() {
            continue;
        }
        let rows: Vec<_> = ranges.iter().map(|(_, r)| r.clone()).collect();
        let Ok(cols) = pq::read_rows_f64(&part, &rows, &DRAWN) else {
            continue;
        };
        let [t, u, s, en, ue, se, wf, vt, ub, p] = &cols[..] else {
            unreachable!("one vector per drawn column")
        };
        let mut k = 0;
        for (id, r) in ranges {
            let rs = out.entry(id).or_default();
            for _ in r {
                if let Some(t) = t[k] {
                    let push = |v: &mut Vec<(f64, f64)>, y: Option<f64>| {
                        if let Some(y) = y.filter(|y| y.is_finite()) {
                            v.push((t, y));
                        }
                    };
                    push(&mut rs.u, u[k]);
                    push(&mut rs.sigma, s[k]);
                    push(&mut rs.energy, en[k]);
                    push(&mut rs.u_exact, ue[k]);
                    push(&mut rs.sigma_exact, se[k]);
                    push(&mut rs.v_t, vt[k]);
                    push(&mut rs.u_b, ub[k]);
                    push(&mut rs.momentum, p[k]);
                    if let (Some(e), Some(w)) = (en[k], wf[k])
                        && e.is_finite()
                        && w.is_finite()
                    {
                        rs.balance.push((t, e, w));
                    }
                }
                k += 1;
            }
        }
    }
    // A run's rows are in step order within its part; a run resumed across sessions is not
    // split, but sorting keeps the figures right whatever the order.
    for rs in out.values_mut() {
        for v in [
            &mut rs.u,
            &mut rs.sigma,
            &mut rs.energy,
            &mut rs.u_exact,
            &mut rs.sigma_exact,
            &mut rs.v_t,
            &mut rs.u_b,
            &mut rs.momentum,
        ] {
            if !v.is_sorted_by(|a, b| a.0 <= b.0) {
                v.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
        }
        if !rs.balance.is_sorted_by(|a, b| a.0 <= b.0) {
            rs.balance.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
    }
    Ok(out)
}
