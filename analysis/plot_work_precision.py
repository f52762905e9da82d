#!/usr/bin/env python3
"""Work-precision diagrams: error against cost, with the Pareto front.

    python3 analysis/plot_work_precision.py DIR [--out FIGDIR] [--error COL]

For every sweep in DIR one figure (work_precision_SWEEP_COL.png/.pdf) with
the error COL (default err_u_l2h1) against two measures of cost: wall_time_s
(what the user pays, but noisy and machine dependent) and steps*dofs (a
machine-independent proxy for the work of a time-stepping method). One
marker series per method group (runs sharing all parameters except h,
elements, dt and courant), joined in order of cost. The Pareto front, the
runs that no other run beats in both error and cost, is drawn as a black
step line and its runs are printed. Only runs with status ok count.

A cost panel whose column is missing or null is left out; when no run has
both the error and a cost, the script says so and exits 0.
"""

from __future__ import annotations

import argparse
import sys

import matplotlib.pyplot as plt
import numpy as np
import polars as pl

import sweepdata as sd

COSTS = [
    ("wall_time_s", "wall time [s]"),
    ("work", "steps × dofs"),
]


def pareto_front(cost: np.ndarray, err: np.ndarray) -> np.ndarray:
    """Indices of the points not dominated in (cost, error), by increasing cost.

    After sorting by cost (ties: smaller error first), a point is on the front
    exactly when its error is strictly below every error seen so far.
    """
    order = np.lexsort((err, cost))
    front, best = [], np.inf
    for i in order:
        if err[i] < best:
            front.append(i)
            best = err[i]
    return np.array(front, dtype=int)


def plot_sweep(sweep: str, runs: pl.DataFrame, col: str, costs: list[tuple[str, str]]):
    groups = sd.method_groups(runs)
    names = sd.describe_groups(groups)
    fig, axes = plt.subplots(1, len(costs), figsize=(6.2 * len(costs), 5.4),
                             layout="constrained", squeeze=False)
    handles = {}
    fronts = []
    for ax, (cost_col, cost_label) in zip(axes.flat, costs):
        pts = []  # (cost, err, group index, row) of every usable run
        for i, (g, name) in enumerate(zip(groups, names)):
            d = g.filter(pl.col(cost_col).is_not_null() & pl.col(col).is_not_null())
            d = d.filter(pl.col(cost_col).is_finite() & (pl.col(cost_col) > 0)
                         & pl.col(col).is_finite() & (pl.col(col) > 0)).sort(cost_col)
            if d.height == 0:
                continue
            st = sd.style(i)
            c, e = d[cost_col].to_numpy(), d[col].to_numpy()
            # Thin joining line: shows the refinement path of one method.
            line = ax.loglog(c, e, color=st["color"], marker=st["marker"], ms=6, lw=0.8, alpha=0.85)[0]
            handles.setdefault(i, (line, name))
            pts += [(float(ci), float(ei), i, row) for ci, ei, row in zip(c, e, d.iter_rows(named=True))]
        if not pts:
            ax.set_visible(False)
            continue
        c = np.array([p[0] for p in pts])
        e = np.array([p[1] for p in pts])
        idx = pareto_front(c, e)
        # Extend the last step to the right edge of the data: beyond the
        # cheapest run reaching the smallest error nothing improves.
        xs = np.append(c[idx], c.max()) if c[idx][-1] < c.max() else c[idx]
        ys = np.append(e[idx], e[idx][-1]) if len(xs) > len(idx) else e[idx]
        front_line = ax.step(xs, ys, where="post", color="black", lw=2.2, alpha=0.55, zorder=1)[0]
        ax.scatter(c[idx], e[idx], s=110, facecolors="none", edgecolors="black", lw=1.2, zorder=4)
        handles.setdefault("front", (front_line, "Pareto front (not dominated in error and cost)"))
        fronts.append((cost_col, [pts[k] for k in idx]))
        ax.set_xlabel(cost_label)
        ax.set_ylabel(col)
        ax.set_title(f"{col} vs {cost_label}")
        ax.grid(True, which="both", alpha=0.3)
    if not fronts:
        plt.close(fig)
        return None, []
    fig.suptitle(f"sweep {sweep}: work-precision (status ok)")
    keys = sorted(k for k in handles if k != "front") + (["front"] if "front" in handles else [])
    labels = [handles[k][1] for k in keys]
    fig.legend([handles[k][0] for k in keys], labels, loc="outside lower center",
               ncols=1 if max(len(x) for x in labels) > 50 else 2, fontsize="small")
    return fig, fronts


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("dir", help="sweep output folder (with runs/)")
    ap.add_argument("--out", help="figure folder (default DIR/figures)")
    ap.add_argument("--error", default="err_u_l2h1", metavar="COL", help="error column (default err_u_l2h1)")
    args = ap.parse_args()
    sd.require_dir(args.dir)
    out = sd.default_out(args.dir, args.out)

    runs = sd.load_runs(args.dir)
    col = args.error
    if col not in runs.columns:
        # Unknown to the schema and absent from the data: most likely a typo.
        known = ", ".join(c for c in runs.columns if c.startswith("err_"))
        print(f"error: no column {col!r}; error columns are: {known}", file=sys.stderr)
        return 2
    if not runs.schema[col].is_numeric():
        print(f"error: column {col!r} is not numeric ({runs.schema[col]})", file=sys.stderr)
        return 2
    ok = sd.ok_runs(runs).with_columns(
        pl.when(pl.col("steps").is_not_null() & pl.col("dofs").is_not_null())
        .then(pl.col("steps").cast(pl.Float64) * pl.col("dofs").cast(pl.Float64))
        .alias("work"))
    costs = [(c, lab) for c, lab in COSTS if sd.has_values(ok, c)]
    for c in {c for c, _ in COSTS} - {c for c, _ in costs}:
        print(f"note: cost column {c} has no values, panel left out")

    pngs: list[str] = []
    if sd.has_values(ok, col) and costs:
        for sweep in sorted(ok["sweep"].unique().to_list()):
            fig, fronts = plot_sweep(sweep, ok.filter(pl.col("sweep") == sweep), col, costs)
            if fig is None:
                print(f"sweep {sweep}: no ok run has both {col} and a cost, skipped")
                continue
            for cost_col, front in fronts:
                print(f"sweep {sweep}: Pareto front in ({cost_col}, {col}):")
                for cost, err, _, row in front:
                    print(f"  {cost_col}={cost:<10.4g} {col}={err:<10.4g} {row['run_id']}  {row['label']}")
            pngs.append(sd.save_figure(fig, out, f"work_precision_{sd.safe_name(sweep)}_{col}"))

    sd.write_manifest(out, f"plot_work_precision.py:{col}", pngs, args.dir)
    if not pngs:
        print(f"nothing to plot: no ok run has both a value of {col} and a cost "
              f"(wall_time_s or steps*dofs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
