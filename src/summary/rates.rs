//! Observed rates, least-squares slopes and flags of one error column along one refinement
//! path (the maths is in the module header of [`super`]): the numbers every convergence table
//! prints, in one place below the formats that print them ([`super::convergence`]'s Markdown
//! and long table, [`super::latex`]'s LaTeX), so that every format flags and marks the same
//! levels.

/// Pair rates spread over more than this: the errors are not yet in the asymptotic regime.
/// A clean power law gives spread 0; the converging ladders of contract §6 (h = 1/4 … 1/256, ratio
/// 4, l2(τ;H1)) wobble by 0.11 (Nitsche-Hybrid: 0.21, 0.28, 0.32), 0.04 (mod3 + CN) and 0.16
/// (zero-contact + CN), while the non-converging mixed + CN ladder (2.373, 1.470, 3.166,
/// 4.610) spreads by 0.9.
pub const PRE_ASYMPTOTIC_SPREAD: f64 = 0.3;
/// LSQ slope over the finest (up to) three usable levels below this: stagnating (includes
/// negative slopes, i.e. errors growing under refinement). The slowest genuine convergence the
/// papers report is ≈ 0.3 (contract §6), three times this.
pub const STAGNATION_SLOPE: f64 = 0.1;
/// Finest usable error at most this times the coarsest usable error: round-off floor. No
/// discretisation ladder reduces an error by twelve orders of magnitude (order 2 from h = 1/4
/// to 1/1024 gains 6.6e4); only cancellation to machine precision does.
pub const ROUNDOFF_RELATIVE: f64 = 1e-12;
/// Finest usable error below this (absolute): round-off floor. The scenes are O(1) in SI
/// units (bar: L = 1, E = ρ = 1, amplitude 0.5), so 1e-13 is ~1e-13 relative to the
/// solution — a few hundred ulps, where refinement only measures rounding. (Scaled problems
/// with tiny solutions would trip it early; the relative criterion does not depend on units.)
pub const ROUNDOFF_ABSOLUTE: f64 = 1e-13;

/// The observed rate between a coarser level (x_c, e_c) and a finer one (x_f, e_f):
/// log(e_c/e_f) / log(x_c/x_f), from the actual ratio of the refinement values.
pub fn observed_rate(e_coarse: f64, e_fine: f64, x_coarse: f64, x_fine: f64) -> f64 {
    (e_coarse / e_fine).ln() / (x_coarse / x_fine).ln()
}

/// Least-squares slope p of log e = log C + p log x over the given points:
/// p = Σ(ξ_i − ξ̄)(η_i − η̄) / Σ(ξ_i − ξ̄)², ξ = log x, η = log e. `None` with fewer than two
/// points or no spread in x.
pub fn lsq_slope(x: &[f64], e: &[f64]) -> Option<f64> {
    let n = x.len().min(e.len());
    if n < 2 {
        return None;
    }
    let xi: Vec<f64> = x[..n].iter().map(|v| v.ln()).collect();
    let eta: Vec<f64> = e[..n].iter().map(|v| v.ln()).collect();
    let mx = xi.iter().sum::<f64>() / n as f64;
    let me = eta.iter().sum::<f64>() / n as f64;
    let sxx: f64 = xi.iter().map(|a| (a - mx) * (a - mx)).sum();
    let sxe: f64 = xi.iter().zip(&eta).map(|(a, b)| (a - mx) * (b - me)).sum();
    if sxx <= 0.0 || !sxx.is_finite() {
        return None;
    }
    Some(sxe / sxx)
}

/// One level of a path as the fit sees it.
#[derive(Debug, Clone)]
pub(crate) struct LevelIn<'a> {
    pub x: f64,
    pub status: &'a str,
    pub value: Option<f64>,
}

/// The fit's verdict on one level.
#[derive(Debug, Clone, Default)]
pub(crate) struct LevelFit {
    /// Used in the rates and fits.
    pub used: bool,
    /// Why not (status, no value, zero error).
    pub excluded: Option<String>,
    /// Rate of the pair (previous used level, this level); attached to the finer level.
    pub rate: Option<f64>,
    /// Index of the coarser level of that pair (≠ level − 1 when a level was skipped).
    pub rate_from: Option<usize>,
}

/// How a format marks a level's cells: an excluded level's value (in parentheses, then the
/// format's mark) and a rate taken against a level further back than the previous one.
pub(crate) struct LevelMarks {
    pub excluded: &'static str,
    pub skipped: &'static str,
}

/// A level's value and rate cells as a table prints them, and what they mark.
pub(crate) struct LevelCells {
    pub value: String,
    pub rate: String,
    /// The value is shown but excluded from the fits.
    pub excluded: bool,
    /// The rate is against a level further back (a level in between was excluded).
    pub skipped: bool,
}

impl LevelFit {
    /// The cells of level `li` from its formatted value and rate, marked as `marks` says
    /// (one rule for every format, so the Markdown and LaTeX tables mark the same levels).
    pub(crate) fn cells(
        &self,
        li: usize,
        value: String,
        rate: String,
        marks: &LevelMarks,
    ) -> LevelCells {
        let excluded = !(self.used || value.is_empty());
        let skipped = self.rate_from.is_some_and(|from| from + 1 != li);
        LevelCells {
            value: if excluded {
                format!("({value}){}", marks.excluded)
            } else {
                value
            },
            rate: if skipped { rate + marks.skipped } else { rate },
            excluded,
            skipped,
        }
    }
}

/// Rates, slopes and flags of one error column along one path.
#[derive(Debug, Clone, Default)]
pub(crate) struct Fit {
    pub levels: Vec<LevelFit>,
    pub used: usize,
    pub slope_all: Option<f64>,
    pub slope_fine3: Option<f64>,
    pub fine_levels: usize,
    pub spread: Option<f64>,
    pub pre_asymptotic: bool,
    pub stagnating: bool,
    pub roundoff: bool,
    pub failed: usize,
}

impl Fit {
    /// The flags as words ("-" when none).
    pub(crate) fn flags(&self) -> String {
        let mut f = Vec::new();
        if self.used < 2 {
            f.push("no fit (< 2 usable levels)".to_string());
        }
        if self.pre_asymptotic {
            f.push("pre-asymptotic".into());
        }
        if self.stagnating {
            f.push("stagnating".into());
        }
        if self.roundoff {
            f.push("round-off floor".into());
        }
        if self.failed > 0 {
            f.push(format!(
                "{} failed level{}",
                self.failed,
                if self.failed == 1 { "" } else { "s" }
            ));
        }
        if f.is_empty() {
            "-".into()
        } else {
            f.join(", ")
        }
    }
}

/// Fit one error column along one path, levels ordered coarse → fine.
pub(crate) fn fit(levels: &[LevelIn]) -> Fit {
    let mut out = Fit {
        levels: vec![LevelFit::default(); levels.len()],
        ..Fit::default()
    };
    let mut xs = Vec::new();
    let mut es = Vec::new();
    let mut prev: Option<usize> = None;
    let mut zero = false;
    for (i, l) in levels.iter().enumerate() {
        let lf = &mut out.levels[i];
        if l.status != "ok" {
            out.failed += 1;
            lf.excluded = Some(format!("status {}", l.status));
            continue;
        }
        match l.value {
            None => lf.excluded = Some("no value".into()),
            Some(v) if !v.is_finite() => lf.excluded = Some("non-finite".into()),
            // An exact zero has no logarithm: the error is at (or below) the floor.
            Some(v) if v <= 0.0 => {
                zero = true;
                lf.excluded = Some("zero error".into());
            }
            Some(v) => {
                lf.used = true;
                if let Some(p) = prev {
                    let (xp, ep) = (levels[p].x, levels[p].value.expect("used"));
                    lf.rate = Some(observed_rate(ep, v, xp, l.x));
                    lf.rate_from = Some(p);
                }
                prev = Some(i);
                xs.push(l.x);
                es.push(v);
            }
        }
    }
    out.used = xs.len();
    out.slope_all = lsq_slope(&xs, &es);
    let k = xs.len().min(3);
    out.fine_levels = k;
    out.slope_fine3 = lsq_slope(&xs[xs.len() - k..], &es[es.len() - k..]);
    let rates: Vec<f64> = out.levels.iter().filter_map(|l| l.rate).collect();
    if rates.len() >= 2 {
        let max = rates.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = rates.iter().copied().fold(f64::INFINITY, f64::min);
        out.spread = Some(max - min);
        out.pre_asymptotic = max - min > PRE_ASYMPTOTIC_SPREAD;
    }
    out.stagnating = out.slope_fine3.is_some_and(|s| s < STAGNATION_SLOPE);
    if let (Some(&coarse), Some(&finest)) = (es.first(), es.last()) {
        out.roundoff = finest <= ROUNDOFF_RELATIVE * coarse || finest < ROUNDOFF_ABSOLUTE;
    }
    out.roundoff |= zero;
    out
}
