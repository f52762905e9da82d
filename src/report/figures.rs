//! The report's figures, drawn in Rust with plotters' SVG backend and inlined in the HTML (no
//! Python, no network, no font files: plotters' built-in text metrics lay the text out, the
//! browser draws it with its sans-serif font).
//!
//! - Convergence: error against the refined axis in log-log, one curve per method group (its
//!   main refinement path), each with a slope triangle whose hypotenuse has the group's
//!   least-squares slope p: the fitted line log e = c + p log x is e = exp(c) x^p, and the
//!   triangle sits under it (shifted down by a constant factor, so it never hides the data),
//!   over one interval between levels, a different one per curve so that they do not pile up.
//! - Work-precision: error against wall time in log-log, every ok run marked by group, the
//!   Pareto front (no run both faster and more accurate) as a black staircase.
//! - Time series: contact displacement, contact pressure and energy in units of `energy_scale`
//!   (E/E⁰ for the bars) against t for one run per group, with the exact (closed-form) solution
//!   dashed in black. Long series are reduced to the minimum and maximum of each of ~1500
//!   buckets, which keeps the envelope of chattering pressures that plain striding would alias
//!   away.
//! - Frictional runs: the energy balance (E, W_f and E + W_f against t in one panel: a scheme
//!   whose E + W_f stays flat while E falls lost only the friction's work) and the slip velocity
//!   v_t of the contact node.
//! - Two-body runs: both bodies' contact displacements u_C^a, u_C^b in one panel (A solid, B
//!   faded), and the total momentum's departure Pⁿ − P⁰, which is round-off for an exact
//!   scheme with free bodies (contract §2.6).
//!
//! Every curve carries its group's colour and marker ([`super::style`]: distinct for up to 60
//! groups); the time-series curves, too dense for a marker per point, carry a dozen markers
//! along them. Every panel is one [`panel`]: the canvas, caption, axes and labels set up once,
//! the log axes labelled as [`super::ticks`] says.

use plotters::coord::combinators::WithKeyPoints;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

use super::style::{self, Marker};
use super::ticks::{LogSpan, lin_range, log_range, log_ticks, tick};

/// A figure that could not be drawn (plotters' message).
#[derive(Debug, thiserror::Error)]
#[error("drawing the figure `{figure}`: {message}")]
pub struct FigureError {
    pub figure: String,
    pub message: String,
}

/// One curve: its name, points and method group (its colour and marker, [`style`]: the same
/// in every figure, so that one HTML legend serves them all).
#[derive(Debug, Clone)]
pub struct Curve {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub group: usize,
}

const W: u32 = 760;
const H: u32 = 480;

fn err(figure: &str) -> impl Fn(String) -> FigureError + '_ {
    move |message| FigureError {
        figure: figure.to_string(),
        message,
    }
}

/// Grid lines: the bold ones at the labelled ticks only (a log axis's minor lines would shade
/// the plot grey).
const MINOR: RGBAColor = RGBAColor(0, 0, 0, 0.0);

/// The canvas and type sizes of a panel: the log-log figures are large (they are read
/// closely, slopes and all), the time series short (three or five of them side by side).
struct Layout {
    height: u32,
    caption: u32,
    margin: u32,
    x_area: u32,
}

const LOG_LOG: Layout = Layout {
    height: H,
    caption: 18,
    margin: 12,
    x_area: 42,
};

const TIME: Layout = Layout {
    height: 300,
    caption: 16,
    margin: 10,
    x_area: 36,
};

/// The chart a panel's drawing gets.
type Chart<'a, 'b, X, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>;

/// A log axis over `span`, labelled at [`log_ticks`].
fn log_axis(span: LogSpan) -> WithKeyPoints<LogCoord<f64>> {
    (span.axis.0..span.axis.1)
        .log_scale()
        .with_key_points(log_ticks(span.axis, span.data))
}

/// One panel as SVG: the white canvas, the caption `title`, the axes `x` and `y` named
/// `names`, the mesh at the labelled ticks; then `draw` draws the data into the chart, and
/// with `labels` (a font size) the legend box of its labelled series (the Pareto front, the
/// exact solution: the method groups have the HTML legend) goes in the upper right corner.
fn panel<X, Y>(
    title: &str,
    layout: &Layout,
    names: (&str, &str),
    x: X,
    y: Y,
    labels: Option<u32>,
    draw: impl FnOnce(&mut Chart<'_, '_, X::CoordDescType, Y::CoordDescType>) -> Result<(), String>,
) -> Result<String, FigureError>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let e = err(title);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, layout.height)).into_drawing_area();
        root.fill(&WHITE).map_err(|x| e(x.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", layout.caption))
            .margin(layout.margin)
            .x_label_area_size(layout.x_area)
            .y_label_area_size(70)
            .build_cartesian_2d(x, y)
            .map_err(|x| e(x.to_string()))?;
        chart
            .configure_mesh()
            .x_desc(names.0)
            .y_desc(names.1)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(MINOR)
            .draw()
            .map_err(|x| e(x.to_string()))?;
        draw(&mut chart).map_err(&e)?;
        if let Some(font) = labels {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(180, 180, 180))
                .label_font(("sans-serif", font))
                .draw()
                .map_err(|x| e(x.to_string()))?;
        }
        root.present().map_err(|x| e(x.to_string()))?;
    }
    Ok(svg)
}

/// A polyline through `points`.
fn line<X, Y>(
    chart: &mut Chart<'_, '_, X, Y>,
    points: &[(f64, f64)],
    style: ShapeStyle,
) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    chart
        .draw_series(LineSeries::new(points.to_vec(), style))
        .map(|_| ())
        .map_err(|x| x.to_string())
}

/// Group `group`'s marker at each of `points`, filled with `style`'s colour.
fn markers<X, Y>(
    chart: &mut Chart<'_, '_, X, Y>,
    points: &[(f64, f64)],
    group: usize,
    style: ShapeStyle,
) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let style = style.filled();
    match style::marker(group).outline() {
        None => chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| Circle::new(p, Marker::RADIUS, style)),
            )
            .map(|_| ()),
        Some(outline) => chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| EmptyElement::at(p) + Polygon::new(outline.to_vec(), style)),
            )
            .map(|_| ()),
    }
    .map_err(|x| x.to_string())
}

/// Markers along a time series: at a dozen times evenly spread over its span, shifted by a
/// fraction of the spacing that differs between groups, so that curves lying on each other
/// (an exact scheme and the exact solution) do not hide each other's markers.
fn along(points: &[(f64, f64)], group: usize) -> Vec<(f64, f64)> {
    const MARKS: usize = 12;
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return Vec::new();
    };
    // The golden ratio's fractional parts: well spread for any number of groups.
    let phase = (group as f64 * 0.618_033_988_75).fract();
    let mut out: Vec<(f64, f64)> = (0..MARKS)
        .filter_map(|j| {
            let t = first.0 + (j as f64 + phase) / MARKS as f64 * (last.0 - first.0);
            points.get(points.partition_point(|p| p.0 < t)).copied()
        })
        .collect();
    out.dedup_by(|a, b| a.0 == b.0);
    out
}

/// A time-series curve: its line in `style` and its group's markers along it.
fn time_curve<X, Y>(
    chart: &mut Chart<'_, '_, X, Y>,
    c: &Curve,
    style: ShapeStyle,
) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    line(chart, &c.points, style)?;
    markers(chart, &along(&c.points, c.group), c.group, style)
}

/// A convergence figure: `curves[i]` = (x, error) of group i's main path, `slopes[i]` its
/// least-squares (p, c) of log e = c + p log x.
pub fn convergence(
    title: &str,
    x_name: &str,
    y_name: &str,
    curves: &[Curve],
    slopes: &[Option<(f64, f64)>],
) -> Result<String, FigureError> {
    let xr = log_range(curves.iter().flat_map(|c| c.points.iter().map(|p| p.0)));
    let yr = log_range(curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)));
    let (Some(xr), Some(mut yr)) = (xr, yr) else {
        return Err(err(title)("no positive values to plot".into()));
    };
    // The triangles sit below the data: extend the y range to hold them.
    let shift = 0.5;
    yr.axis.0 *= shift * shift;
    let (x, y) = (log_axis(xr), log_axis(yr));
    panel(title, &LOG_LOG, (x_name, y_name), x, y, None, |chart| {
        for (i, c) in curves.iter().enumerate() {
            let col = style::color(c.group);
            line(chart, &c.points, col.stroke_width(2))?;
            markers(chart, &c.points, c.group, col.into())?;
            // The slope triangle over interval (i mod (levels − 1)), 60 % of its width (in log x).
            if let Some(Some((p, cst))) = slopes.get(i) {
                let mut xs: Vec<f64> = c.points.iter().map(|q| q.0).collect();
                xs.sort_by(f64::total_cmp);
                if xs.len() >= 2 {
                    let k = i % (xs.len() - 1);
                    let (a, b) = (xs[k], xs[k] * (xs[k + 1] / xs[k]).powf(0.6));
                    let f = |x: f64| cst.exp() * x.powf(*p) * shift;
                    let (ya, yb) = (f(a), f(b));
                    line(
                        chart,
                        &[(a, ya), (b, ya), (b, yb), (a, ya)],
                        col.stroke_width(1),
                    )?;
                    let label = format!("{p:.2}");
                    chart
                        .draw_series(std::iter::once(Text::new(
                            label,
                            (b, (ya * yb).sqrt()),
                            ("sans-serif", 13).into_font().color(&col),
                        )))
                        .map_err(|x| x.to_string())?;
                }
            }
        }
        Ok(())
    })
}

/// A work-precision figure: every ok run as a point (wall time, error) marked by its group
/// (`groups[i]`), and the Pareto front as a staircase with its points circled.
pub fn work_precision(
    title: &str,
    y_name: &str,
    groups: &[Curve],
    front: &[(f64, f64)],
) -> Result<String, FigureError> {
    let xr = log_range(groups.iter().flat_map(|c| c.points.iter().map(|p| p.0)));
    let yr = log_range(groups.iter().flat_map(|c| c.points.iter().map(|p| p.1)));
    let (Some(xr), Some(yr)) = (xr, yr) else {
        return Err(err(title)("no positive values to plot".into()));
    };
    let (x, y) = (log_axis(xr), log_axis(yr));
    let names = ("wall time [s]", y_name);
    panel(title, &LOG_LOG, names, x, y, Some(12), |chart| {
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
            .map_err(|x| x.to_string())?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK));
        for c in groups {
            markers(chart, &c.points, c.group, style::color(c.group).into())?;
        }
        chart
            .draw_series(f.iter().map(|&p| Circle::new(p, 5, BLACK.stroke_width(1))))
            .map_err(|x| x.to_string())
            .map(|_| ())
    })
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
        let (lo, hi) = extremes(chunk);
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    out
}

/// The indices of a chunk's first minimum and last maximum, in the order of `f64::total_cmp`
/// (those `Iterator::min_by` and `max_by` pick).
fn extremes(chunk: &[(f64, f64)]) -> (usize, usize) {
    let (mut lo, mut hi) = (0, 0);
    for (i, p) in chunk.iter().enumerate().skip(1) {
        if p.1.total_cmp(&chunk[lo].1).is_lt() {
            lo = i;
        }
        if p.1.total_cmp(&chunk[hi].1).is_ge() {
            hi = i;
        }
    }
    (lo, hi)
}

/// The linear (t, y) axes of a time-series panel holding `curves`.
fn time_axes<'a>(
    curves: impl Iterator<Item = &'a Curve> + Clone,
) -> Option<((f64, f64), (f64, f64))> {
    let all = || curves.clone().flat_map(|c| c.points.iter().copied());
    Some((
        lin_range(all().map(|p| p.0))?,
        lin_range(all().map(|p| p.1))?,
    ))
}

/// The exact solution dashed in black, labelled for the panel's legend box: dashes of about 1 % of the
/// time range `t`, drawn as separate segments.
fn dashed_exact<X, Y>(
    chart: &mut Chart<'_, '_, X, Y>,
    ex: &Curve,
    t: (f64, f64),
) -> Result<(), String>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let dash = (t.1 - t.0) / 120.0;
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
            .map_err(|x| x.to_string())?;
        if first {
            drawn
                .label(ex.name.clone())
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 7, y)], BLACK.stroke_width(2)));
            first = false;
        }
    }
    Ok(())
}

/// A time-series panel: one curve per run, the exact solution (if any) dashed black.
pub fn series(
    title: &str,
    y_name: &str,
    curves: &[Curve],
    exact: Option<&Curve>,
) -> Result<String, FigureError> {
    let Some((t, y)) = time_axes(curves.iter().chain(exact)) else {
        return Err(err(title)("no values to plot".into()));
    };
    let labels = exact.map(|_| 11);
    panel(
        title,
        &TIME,
        ("t", y_name),
        t.0..t.1,
        y.0..y.1,
        labels,
        |chart| {
            for c in curves {
                time_curve(chart, c, style::color(c.group).stroke_width(1))?;
            }
            match exact {
                Some(ex) => dashed_exact(chart, ex, t),
                None => Ok(()),
            }
        },
    )
}

/// The energy-balance panel of frictional runs: per run (its group's colour and marker, as
/// elsewhere) E thin, W_f faded and E + W_f thick, so that the three quantities of several
/// runs stay apart without a legend per curve (the caption states the line styles).
pub fn balance(
    title: &str,
    energy: &[Curve],
    work: &[Curve],
    total: &[Curve],
) -> Result<String, FigureError> {
    layered(
        title,
        "energy / energy_scale",
        &[(work, 1, true), (energy, 1, false), (total, 3, false)],
    )
}

/// Several quantities of the same runs in one time panel, told apart by line style rather than
/// by a legend per curve: each layer is (curves, stroke width, faded), drawn in that order, a
/// curve in its group's colour.
pub fn layered(
    title: &str,
    y_name: &str,
    layers: &[(&[Curve], u32, bool)],
) -> Result<String, FigureError> {
    let all = layers.iter().flat_map(|(c, _, _)| c.iter());
    let Some((t, y)) = time_axes(all) else {
        return Err(err(title)("no values to plot".into()));
    };
    panel(
        title,
        &TIME,
        ("t", y_name),
        t.0..t.1,
        y.0..y.1,
        None,
        |chart| {
            for &(curves, width, faded) in layers {
                for c in curves {
                    let col = style::color(c.group);
                    let style = if faded {
                        col.mix(0.45).stroke_width(width)
                    } else {
                        col.stroke_width(width)
                    };
                    time_curve(chart, c, style)?;
                }
            }
            Ok(())
        },
    )
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
    fn the_extremes_are_those_min_by_and_max_by_pick() {
        let chunk = [
            (0.0, 1.0),
            (1.0, -0.0),
            (2.0, 3.0),
            (3.0, 0.0),
            (4.0, 3.0),
            (5.0, -0.0),
        ];
        type Pick = fn(std::slice::Iter<'_, (f64, f64)>) -> Option<&(f64, f64)>;
        let by = |f: Pick| {
            let p = f(chunk.iter()).unwrap();
            chunk.iter().position(|q| std::ptr::eq(q, p)).unwrap()
        };
        let min = by(|i| i.min_by(|a, b| a.1.total_cmp(&b.1)));
        let max = by(|i| i.max_by(|a, b| a.1.total_cmp(&b.1)));
        assert_eq!(extremes(&chunk), (min, max));
        assert_eq!((min, max), (1, 4), "the first −0, the last 3");
    }

    #[test]
    fn a_convergence_figure_is_svg_with_its_curve() {
        let c = Curve {
            name: "g".into(),
            points: vec![(0.1, 0.01), (0.05, 0.0025), (0.025, 0.000625)],
            group: 0,
        };
        let svg = convergence("t", "h", "e", &[c], &[Some((2.0, 0.0))]).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("<polyline") && svg.contains("2.00"), "{svg}");
    }

    /// The text of the SVG's `<text>` elements.
    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|s| {
                Some(
                    s.split_once('>')?
                        .1
                        .split_once("</text>")?
                        .0
                        .trim()
                        .to_string(),
                )
            })
            .collect()
    }

    #[test]
    fn log_axes_are_labelled_at_every_decade_and_at_the_ends_within_one() {
        // x = h over [1, 4] (the disc's h = 4, 2, 1), y = errors over [1e-6, 1e-2].
        let c = Curve {
            name: "g".into(),
            points: vec![(4.0, 1e-2), (2.0, 1e-4), (1.0, 1e-6)],
            group: 0,
        };
        let svg = work_precision("t", "e", &[c], &[]).unwrap();
        let t = texts(&svg);
        for label in ["1", "2", "4", "1e-6", "1e-5", "1e-4", "1e-3", "0.01"] {
            assert!(t.iter().any(|x| x == label), "no tick `{label}` in {t:?}");
        }
    }

    #[test]
    fn a_time_series_carries_markers_along_it() {
        let pts: Vec<(f64, f64)> = (0..1000).map(|i| (i as f64 * 1e-3, 1.0)).collect();
        let c = Curve {
            name: "g".into(),
            points: pts,
            group: 1,
        };
        assert_eq!(along(&c.points, 1).len(), 12);
        let svg = series("t", "y", &[c], None).unwrap();
        // Group 1's marker is the square: a four-point polygon.
        assert!(svg.matches("<polygon").count() >= 12, "{svg}");
    }
}
