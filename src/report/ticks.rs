//! The figures' axis ranges and labelled ticks.
//!
//! A log axis is labelled at every decade 10^k inside it: an error or a mesh size is read by
//! its order of magnitude, and a decade between two labels would have to be guessed. A range
//! holding fewer than two decades (the disc's h = 4, 2, 1, or errors within a factor of 5)
//! would then show one label or none, and a single label does not say the scale: there the
//! labels are the ends of the data and the 1-2-5 values between them (kept when at least a
//! factor 1.25 from every other label, so that no two labels overlap). More than 16 decades
//! (errors from 1e-16 to 1) are labelled every second (third, …) decade, so that the labels
//! fit beside each other.

/// Labels on a log axis at the most (see the module's header).
const MAX_DECADES: usize = 16;

/// Two labels closer than this factor would overlap.
const MIN_RATIO: f64 = 1.25;

/// A log axis: the values' range and the (padded) drawn range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogSpan {
    /// The smallest and largest value (widened by 2 on each side when they are equal).
    pub data: (f64, f64),
    /// The drawn range: `data` widened by a factor on each side.
    pub axis: (f64, f64),
}

/// The positive finite range of values, widened by a factor on each side (log axes).
pub fn log_range(values: impl Iterator<Item = f64>) -> Option<LogSpan> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi > 0.0) {
        return None;
    }
    let (lo, hi) = if hi / lo < 1.0001 {
        (lo / 2.0, hi * 2.0)
    } else {
        (lo, hi)
    };
    let pad = (hi / lo).powf(0.06);
    Some(LogSpan {
        data: (lo, hi),
        axis: (lo / pad, hi * pad),
    })
}

/// The finite range of values, widened by 5 % on each side (or by 0.5 when all are equal).
pub fn lin_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 };
    Some((lo - pad, hi + pad))
}

/// The labelled ticks of a log axis drawn over `axis` holding values over `data`, ascending
/// (see the module's header).
pub fn log_ticks(axis: (f64, f64), data: (f64, f64)) -> Vec<f64> {
    let (lo, hi) = axis;
    let inside = |x: f64| x >= lo && x <= hi;
    // 10^k by powi of an integer exponent: 1e-6 is 1e-6, not 0.9999…e-6.
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    let decades: Vec<i32> = (first..=last).filter(|&k| inside(10f64.powi(k))).collect();
    if decades.len() >= 2 {
        let step = decades.len().div_ceil(MAX_DECADES) as i32;
        return decades
            .into_iter()
            .filter(|k| k.rem_euclid(step) == 0)
            .map(|k| 10f64.powi(k))
            .collect();
    }
    let mut ticks = vec![data.0];
    let add = |x: f64, ticks: &mut Vec<f64>| {
        if inside(x)
            && ticks
                .iter()
                .all(|&t| x / t >= MIN_RATIO || t / x >= MIN_RATIO)
        {
            ticks.push(x);
        }
    };
    add(data.1, &mut ticks);
    for m in [1.0, 2.0, 5.0] {
        for k in first..=last {
            add(m * 10f64.powi(k), &mut ticks);
        }
    }
    ticks.sort_by(f64::total_cmp);
    ticks
}

/// Tick labels: the terminal's engineering format without trailing zeros (`0.1`, `1e-3`).
pub fn tick(x: &f64) -> String {
    let s = crate::summary::eng(*x);
    let (mantissa, exp) = match s.split_once('e') {
        Some((m, e)) => (m.to_string(), format!("e{e}")),
        None => (s.clone(), String::new()),
    };
    let mantissa = if mantissa.contains('.') {
        mantissa
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        mantissa
    };
    format!("{mantissa}{exp}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(values: &[f64]) -> Vec<String> {
        let r = log_range(values.iter().copied()).unwrap();
        log_ticks(r.axis, r.data).iter().map(tick).collect()
    }

    #[test]
    fn a_range_within_a_decade_is_labelled_at_its_ends_and_between() {
        // The disc's h = 4, 2, 1: "1" alone before.
        assert_eq!(labels(&[4.0, 2.0, 1.0]), ["1", "2", "4"]);
        // No decade inside: the ends and the 1-2-5 values between.
        assert_eq!(labels(&[0.3, 0.7]), ["0.3", "0.5", "0.7"]);
        // One value alone: two labels still.
        assert!(labels(&[3.0]).len() >= 2);
    }

    #[test]
    fn every_decade_is_labelled() {
        assert_eq!(
            labels(&[1e-6, 3e-4, 1e-2]),
            ["1e-6", "1e-5", "1e-4", "1e-3", "0.01"]
        );
        // The quickstart's h ladder, 1/8 … 1/128: 0.01 and 0.1.
        assert_eq!(labels(&[0.125, 0.0078125]), ["0.01", "0.1"]);
        // Twenty decades: every second one, still at least ten labels.
        let many = labels(&[1e-18, 1.0]);
        assert!(many.len() >= 10 && many.len() <= MAX_DECADES, "{many:?}");
    }
}
