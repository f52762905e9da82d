#!/usr/bin/env python3
"""Convergence plots: error against mesh size h, log-log, one curve per method.

    python3 analysis/plot_convergence.py DIR [--out FIGDIR] [--errors COL ...]

For every sweep in DIR one figure (convergence_SWEEP.png/.pdf) with one panel
per error column (default err_u_l2l2, err_u_l2h1, err_sigma_mid_l2,
err_energy_l2) that has values. Each curve is a method group: the runs that
share every parameter except h, elements, dt and courant (the refinement
path). Only runs with status ok count. Every curve gets a slope triangle
labelled with its least-squares slope in log-log, which is also printed.

If a group holds several runs at the same h (e.g. a grid over h x Courant
number), it is split by Courant number, so a curve is a refinement at fixed
Courant number; remaining duplicates are averaged geometrically, with a
warning naming the columns that differ.

When no group has errors on at least two refinement levels there is nothing
to fit: the script says so and exits 0 (e.g. a scene without reference
solution, or a single-mesh sweep).
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np
import polars as pl
from matplotlib.colors import to_rgba
from matplotlib.ticker import NullFormatter

import sweepdata as sd

DEFAULT_ERRORS = ["err_u_l2l2", "err_u_l2h1", "err_sigma_mid_l2", "err_energy_l2"]


@dataclass
class Path:
    """One refinement path: a method group (possibly at one Courant number)."""
    runs: pl.DataFrame
    name: str


def refinement_paths(group: pl.DataFrame, name: str) -> list[Path]:
    """Split a method group into paths with one run per h where needed."""
    group = group.filter(pl.col("h").is_not_null())
    if group["h"].n_unique() == group.height:
        return [Path(group, name)]
    # Round the Courant number so that 0.5 and 0.49999999 (dt computed from h)
    # are one path.
    keyed = group.with_columns(pl.col("courant").round_sig_figs(6).alias("_courant_key"))
    if keyed["_courant_key"].n_unique() > 1:
        return [Path(p.drop("_courant_key"), f"{name}, courant={sd.fmt_value(p['_courant_key'][0])}")
                for p in keyed.partition_by("_courant_key", maintain_order=True)]
    return [Path(group, name)]


_warned: set[str] = set()  # paths already warned about, to warn once per curve


def curve_points(path: Path, col: str) -> tuple[np.ndarray, np.ndarray]:
    """(h, error) of one path, one point per h, only values usable on log axes."""
    d = path.runs.select("h", col).filter(
        pl.col(col).is_not_null() & pl.col(col).is_finite() & (pl.col(col) > 0) & (pl.col("h") > 0))
    if d.height == 0:
        return np.array([]), np.array([])
    if d["h"].n_unique() < d.height and path.name not in _warned:
        _warned.add(path.name)
        # Name what differs between runs at the same h: that is the parameter
        # the grouping does not know about (or a repeated run, if nothing).
        ignore = {"run_id", "message", *sd.RESULT_COLUMNS}
        cols = [c for c in path.runs.columns if c not in ignore and not c.startswith("_")]
        differing = sorted({c for part in path.runs.partition_by("h") for c in cols if part[c].n_unique() > 1})
        sd.warn(f"'{path.name}': several runs at the same h, errors averaged geometrically "
                f"(differing: {', '.join(differing) or 'nothing but run_id: repeated runs?'})")
    d = d.group_by("h").agg(pl.col(col).log().mean().exp()).sort("h")
    return d["h"].to_numpy(), d[col].to_numpy()


def fit_slope(h: np.ndarray, e: np.ndarray) -> tuple[float, float]:
    """Least-squares line in log-log: log e = p log h + c. Returns (p, c)."""
    p, c = np.polyfit(np.log(h), np.log(e), 1)
    return float(p), float(c)


def slope_triangle(ax, h: np.ndarray, p: float, c: float, color, slot: int) -> None:
    """Draw a triangle whose hypotenuse has the fitted slope, labelled with it.

    It sits under the fitted line (shifted down by a constant factor) so that
    it never hides the data it summarises, and curve number ``slot`` uses the
    (slot mod n-1)-th interval between refinement levels, so that the
    triangles of neighbouring curves do not pile up at the same h.
    """
    levels = np.sort(h)
    k = slot % (len(levels) - 1)
    x0 = float(levels[k])
    x1 = x0 * (float(levels[k + 1]) / x0) ** 0.6
    shift = 0.6
    y0 = math.exp(c) * x0**p * shift
    y1 = math.exp(c) * x1**p * shift
    # Right angle under the hypotenuse for p > 0, above it for p < 0.
    xs = [x0, x1, x1, x0]
    ys = [y0, y0, y1, y0]
    # Transparent face but opaque edge: the outline must stay readable.
    ax.fill(xs, ys, facecolor=to_rgba(color, 0.12), edgecolor=color, lw=1.0)
    ax.text(x1 * 1.03, math.sqrt(y0 * y1), f"{p:.2f}", color=color, fontsize="small",
            va="center", ha="left")


def plot_sweep(sweep: str, paths: list[Path], cols: list[str]):
    """One figure for a sweep, or None when no curve has two levels."""
    panels = []
    for col in cols:
        curves = []
        for i, path in enumerate(paths):
            h, e = curve_points(path, col)
            if len(h) >= 2:
                curves.append((i, path, h, e))
        if curves:
            panels.append((col, curves))
    if not panels:
        return None, []

    ncols = min(2, len(panels))
    nrows = math.ceil(len(panels) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(5.6 * ncols, 4.3 * nrows + 1.2),
                             layout="constrained", squeeze=False)
    handles = {}
    slopes = []
    for ax, (col, curves) in zip(axes.flat, panels):
        for slot, (i, path, h, e) in enumerate(curves):
            st = sd.style(i)
            line = ax.loglog(h, e, color=st["color"], marker=st["marker"], ms=5, lw=1.3)[0]
            p, c = fit_slope(h, e)
            slope_triangle(ax, h, p, c, st["color"], slot)
            handles.setdefault(i, (line, path.name))
            slopes.append((col, path.name, len(h), p))
        # Ticks at the refinement levels themselves read better than
        # "2x10^-2"-style minor labels, as long as there are few of them.
        levels = np.unique(np.concatenate([h for _, _, h, _ in curves]))
        if len(levels) <= 8:
            ax.set_xticks(levels, [sd.fmt_value(float(x)) for x in levels])
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("mesh size h")
        ax.set_ylabel(col)
        ax.set_title(col)
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(panels):]:
        ax.set_visible(False)
    fig.suptitle(f"sweep {sweep}: convergence in h (status ok; triangles: least-squares slope)")
    ordered = [handles[k] for k in sorted(handles)]
    labels = [x[1] for x in ordered]
    fig.legend([x[0] for x in ordered], labels, loc="outside lower center",
               ncols=1 if max(len(x) for x in labels) > 50 else 2, fontsize="small")
    return fig, slopes


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("dir", help="sweep output folder (with runs/)")
    ap.add_argument("--out", help="figure folder (default DIR/figures)")
    ap.add_argument("--errors", nargs="+", default=DEFAULT_ERRORS, metavar="COL",
                    help=f"error columns, one panel each (default: {' '.join(DEFAULT_ERRORS)})")
    args = ap.parse_args()
    sd.require_dir(args.dir)
    out = sd.default_out(args.dir, args.out)

    runs = sd.load_runs(args.dir)
    ok = sd.ok_runs(runs)
    cols = [c for c in args.errors if sd.has_values(ok, c)]
    missing = [c for c in args.errors if c not in cols]
    if missing:
        print(f"note: no values (column absent or all null among ok runs) for: {', '.join(missing)}")

    pngs: list[str] = []
    if cols:
        for sweep in sorted(ok["sweep"].unique().to_list()):
            groups = sd.method_groups(ok.filter(pl.col("sweep") == sweep))
            names = sd.describe_groups(groups)
            paths = [p for g, n in zip(groups, names) for p in refinement_paths(g, n)]
            fig, slopes = plot_sweep(sweep, paths, cols)
            if fig is None:
                print(f"sweep {sweep}: no method group has errors on >= 2 refinement levels, skipped")
                continue
            print(f"sweep {sweep}: fitted slopes")
            for col, name, n, p in slopes:
                print(f"  {col:<14} {p:6.2f}  ({n} levels)  {name}")
            pngs.append(sd.save_figure(fig, out, f"convergence_{sd.safe_name(sweep)}"))

    sd.write_manifest(out, "plot_convergence.py", pngs, args.dir)
    if not pngs:
        print("nothing to plot: no method group has errors on at least 2 refinement levels "
              "(status ok, finite positive error, h set). Convergence plots need a scene with a "
              "reference solution and a sweep over h.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
