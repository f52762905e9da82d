//! The report's figures, drawn in Rust with plotters' SVG backend and inlined in the HTML (no
//! Python, no network, no font files: plotters' built-in text metrics lay the text out, the
//! browser draws it with its sans-serif font).
//!
//! - Convergence: error against the refined axis in log-log, one curve per method group (its
//!   main refinement path), each with a slope triangle whose hypotenuse has the group's
//!   least-squares slope p: the fitted line log e = c + p log x is e = exp(c) x^p, and the
//!   triangle sits under it (shifted down by a constant factor, so it never hides the data),
//!   over one interval between levels, a different one per curve so that they do not pile up.
//! - Work-precision: error against wall time in log-log, every ok run coloured by group, the
//!   Pareto front (no run both faster and more accurate) as a black staircase.
//! - Time series: contact displacement, contact pressure and energy in units of `energy_scale`
//!   (E/E⁰ for the bars) against t for one run per group, with the exact (closed-form) solution
//!   dashed in black. Long series are reduced to the minimum and maximum of each of ~1500
//!   buckets, which keeps the envelope of chattering pressures that plain striding would alias
//!   away.
//! - Frictional runs: the energy balance (E, W_f and E + W_f against t in one panel: a scheme
//!   whose E + W_f stays flat while E falls lost only the friction's work) and the slip velocity
//!   v_t of the contact node.

use plotters::prelude::*;

/// A figure that could not be drawn (plotters' message).
#[derive(Debug, thiserror::Error)]
#[error("drawing the figure `{figure}`: {message}")]
pub struct FigureError {
    pub figure: String,
    pub message: String,
}

/// One curve: its name, points and colour (an index into [`color`]: the method group's, so
/// that a group has one colour in every figure and one HTML legend serves them all).
#[derive(Debug, Clone)]
pub struct Curve {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub color: usize,
}

/// The colour of curve `i`: a qualitative palette (Okabe–Ito, readable by colour-blind
/// readers), cycling after eight.
pub fn color(i: usize) -> RGBColor {
    const P: [RGBColor; 8] = [
        RGBColor(0, 114, 178),
        RGBColor(213, 94, 0),
        RGBColor(0, 158, 115),
        RGBColor(204, 121, 167),
        RGBColor(230, 159, 0),
        RGBColor(86, 180, 233),
        RGBColor(120, 94, 240),
        RGBColor(160, 32, 32),
    ];
    P[i % P.len()]
}

const W: u32 = 760;
const H: u32 = 480;

fn err(figure: &str) -> impl Fn(String) -> FigureError + '_ {
    move |message| FigureError {
        figure: figure.to_string(),
        message,
    }
}

/// The positive finite range of values, widened by a factor on each side (log axes).
fn log_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
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
    Some((lo / pad, hi * pad))
}

fn lin_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
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

/// Tick labels: the terminal's engineering format without trailing zeros (`0.1`, `1e-3`).
fn tick(x: &f64) -> String {
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

/// Grid lines: the bold ones at the labelled ticks only (a log axis's minor lines would shade
/// the plot grey).
const MINOR: RGBAColor = RGBAColor(0, 0, 0, 0.0);

/// A convergence figure: `curves[i]` = (x, error) of group i's main path, `slopes[i]` its
/// least-squares (p, c) of log e = c + p log x.
pub fn convergence(
    title: &str,
    x_name: &str,
    y_name: &str,
    curves: &[Curve],
    slopes: &[Option<(f64, f64)>],
) -> Result<String, FigureError> {
    let e = err(title);
    let xr = log_range(curves.iter().flat_map(|c| c.points.iter().map(|p| p.0)));
    let yr = log_range(curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)));
    let (Some((x0, x1)), Some((y0, y1))) = (xr, yr) else {
        return Err(e("no positive values to plot".into()));
    };
    // The triangles sit below the data: extend the y range to hold them.
    let shift = 0.5;
    let y0 = y0 * shift * shift;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_mesh()
            .x_desc(x_name)
            .y_desc(y_name)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .x_labels(8)
            .y_labels(8)
            .light_line_style(MINOR)
            .draw()
            .map_err(|x| e(x.to_string()))?;
        for (i, c) in curves.iter().enumerate() {
            let col = color(c.color);
            chart
                .draw_series(LineSeries::new(c.points.clone(), col.stroke_width(2)))
                .map_err(|x| e(x.to_string()))?;
            chart
                .draw_series(c.points.iter().map(|&p| Circle::new(p, 3, col.filled())))
                .map_err(|x| e(x.to_string()))?;
            // The slope triangle over interval (i mod (levels − 1)), 60 % of its width (in log x).
            if let Some(Some((p, cst))) = slopes.get(i) {
                let mut xs: Vec<f64> = c.points.iter().map(|q| q.0).collect();
                xs.sort_by(f64::total_cmp);
                if xs.len() >= 2 {
                    let k = i % (xs.len() - 1);
                    let (a, b) = (xs[k], xs[k] * (xs[k + 1] / xs[k]).powf(0.6));
                    let f = |x: f64| cst.exp() * x.powf(*p) * shift;
                    let (ya, yb) = (f(a), f(b));
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![(a, ya), (b, ya), (b, yb), (a, ya)],
                            col.stroke_width(1),
                        )))
                        .map_err(|x| e(x.to_string()))?;
                    let label = format!("{p:.2}");
                    chart
                        .draw_series(std::iter::once(Text::new(
                            label,
                            (b, (ya * yb).sqrt()),
                            ("sans-serif", 13).into_font().color(&col),
                        )))
                        .map_err(|x| e(x.to_string()))?;
                }
            }
        }
        root.present().map_err(|x| e(x.to_string()))?;
    }
    Ok(svg)
}

/// A work-precision figure: every ok run as a point (wall time, error) coloured by its group
/// (`groups[i]`), and the Pareto front as a staircase with its points circled.
pub fn work_precision(
    title: &str,
    y_name: &str,
    groups: &[Curve],
    front: &[(f64, f64)],
) -> Result<String, FigureError> {
    let e = err(title);
    let xr = log_range(groups.iter().flat_map(|c| c.points.iter().map(|p| p.0)));
    let yr = log_range(groups.iter().flat_map(|c| c.points.iter().map(|p| p.1)));
    let (Some((x0, x1)), Some((y0, y1))) = (xr, yr) else {
        return Err(e("no positive values to plot".into()));
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(70)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("wall time [s]")
            .y_desc(y_name)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .x_labels(8)
            .y_labels(8)
            .light_line_style(MINOR)
            .draw()
            .map_err(|x| e(x.to_string()))?;
        // The front: from the cheapest point, right then down to each more accurate one.
        let mut f: Vec<(f64, f64)> = front.to_vec();
        f.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut stair = Vec::with_capacity(2 * f.len());
        for (k, &(x, y)) in f.iter().enumerate() {
            if k > 0 {
                stair.push((x, f[k - 1].1));
            }
            stair.push((x, y));
        }
        chart
            .draw_series(LineSeries::new(stair, BLACK.stroke_width(1)))
            .map_err(|x| e(x.to_string()))?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK));
        for c in groups {
            let col = color(c.color);
            chart
                .draw_series(c.points.iter().map(|&p| Circle::new(p, 3, col.filled())))
                .map_err(|x| e(x.to_string()))?;
        }
        chart
            .draw_series(f.iter().map(|&p| Circle::new(p, 5, BLACK.stroke_width(1))))
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(|x| e(x.to_string()))?;
        root.present().map_err(|x| e(x.to_string()))?;
    }
    Ok(svg)
}

/// At most `2 × buckets` points with the same envelope: the minimum and the maximum of each
/// bucket, in time order.
pub fn decimate(points: &[(f64, f64)], buckets: usize) -> Vec<(f64, f64)> {
    if points.len() <= 2 * buckets {
        return points.to_vec();
    }
    let size = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets);
    for chunk in points.chunks(size) {
        let lo = chunk
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let hi = chunk
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .map(|(i, _)| i)
            .unwrap_or(0);
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    out
}

/// A time-series panel: one curve per run, the exact solution (if any) dashed black.
pub fn series(
    title: &str,
    y_name: &str,
    curves: &[Curve],
    exact: Option<&Curve>,
) -> Result<String, FigureError> {
    let e = err(title);
    let all = || {
        curves
            .iter()
            .chain(exact)
            .flat_map(|c| c.points.iter().copied())
    };
    let (Some((x0, x1)), Some((y0, y1))) =
        (lin_range(all().map(|p| p.0)), lin_range(all().map(|p| p.1)))
    else {
        return Err(e("no values to plot".into()));
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, 300)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("t")
            .y_desc(y_name)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(MINOR)
            .draw()
            .map_err(|x| e(x.to_string()))?;
        for c in curves {
            let col = color(c.color);
            chart
                .draw_series(LineSeries::new(c.points.clone(), col.stroke_width(1)))
                .map_err(|x| e(x.to_string()))?;
        }
        if let Some(ex) = exact {
            // Dashes of about 1 % of the time range: drawn as separate segments.
            let dash = (x1 - x0) / 120.0;
            let mut segments: Vec<Vec<(f64, f64)>> = Vec::new();
            let mut cur: Vec<(f64, f64)> = Vec::new();
            let mut on_since = ex.points.first().map(|p| p.0).unwrap_or(0.0);
            for &p in &ex.points {
                if p.0 - on_since > 2.0 * dash {
                    on_since = p.0;
                }
                if p.0 - on_since <= dash {
                    cur.push(p);
                } else if !cur.is_empty() {
                    segments.push(std::mem::take(&mut cur));
                }
            }
            if !cur.is_empty() {
                segments.push(cur);
            }
            let mut first = true;
            for s in segments {
                let drawn = chart
                    .draw_series(LineSeries::new(s, BLACK.stroke_width(2)))
                    .map_err(|x| e(x.to_string()))?;
                if first {
                    drawn.label(ex.name.clone()).legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 7, y)], BLACK.stroke_width(2))
                    });
                    first = false;
                }
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(180, 180, 180))
                .label_font(("sans-serif", 11))
                .draw()
                .map_err(|x| e(x.to_string()))?;
        }
        root.present().map_err(|x| e(x.to_string()))?;
    }
    Ok(svg)
}

/// The energy-balance panel of frictional runs: per run (one colour each, as elsewhere) E thin,
/// W_f faded and E + W_f thick, so that the three quantities of several runs stay apart without
/// a legend per curve (the caption states the line styles).
pub fn balance(
    title: &str,
    energy: &[Curve],
    work: &[Curve],
    total: &[Curve],
) -> Result<String, FigureError> {
    let e = err(title);
    let all = || {
        energy
            .iter()
            .chain(work)
            .chain(total)
            .flat_map(|c| c.points.iter().copied())
    };
    let (Some((x0, x1)), Some((y0, y1))) =
        (lin_range(all().map(|p| p.0)), lin_range(all().map(|p| p.1)))
    else {
        return Err(e("no values to plot".into()));
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, 300)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("t")
            .y_desc("energy / energy_scale")
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(MINOR)
            .draw()
            .map_err(|x| e(x.to_string()))?;
        for (curves, width, faded) in [(work, 1, true), (energy, 1, false), (total, 3, false)] {
            for c in curves {
                let col = color(c.color);
                let style = if faded {
                    col.mix(0.45).stroke_width(width)
                } else {
                    col.stroke_width(width)
                };
                chart
                    .draw_series(LineSeries::new(c.points.clone(), style))
                    .map_err(|x| e(x.to_string()))?;
            }
        }
        root.present().map_err(|x| e(x.to_string()))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_the_envelope() {
        // A chattering signal: +1, −1 alternating; any striding by an even step sees only +1.
        let pts: Vec<(f64, f64)> = (0..10_000)
            .map(|i| (i as f64, if i % 2 == 0 { 1.0 } else { -1.0 }))
            .collect();
        let d = decimate(&pts, 100);
        assert!(d.len() <= 200);
        assert!(d.iter().any(|p| p.1 == -1.0) && d.iter().any(|p| p.1 == 1.0));
        assert!(d.windows(2).all(|w| w[0].0 < w[1].0), "time order kept");
    }

    #[test]
    fn a_convergence_figure_is_svg_with_its_curve() {
        let c = Curve {
            name: "g".into(),
            points: vec![(0.1, 0.01), (0.05, 0.0025), (0.025, 0.000625)],
            color: 0,
        };
        let svg = convergence("t", "h", "e", &[c], &[Some((2.0, 0.0))]).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("<polyline") && svg.contains("2.00"), "{svg}");
    }
}
