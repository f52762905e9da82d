#!/usr/bin/env python3
"""Stability maps as heat maps.

    python3 analysis/plot_stability_map.py DIR [--out FIGDIR]

Reads DIR/summary/stability_map.parquet (written by `contact-sweep
summarize DIR`): per method and pair of swept axes, the state of every cell
— stable, growing, diverged, solver-failed, timeout, invalid (the worst over
the cell's runs). One figure per method (stability_map_FOLDER_METHOD.png/.pdf, FOLDER the
results folder's name),
one panel per pair of axes; cells are coloured by state, a cell whose runs
disagree is hatched, and axes whose values span more than two decades are
labelled by their values on an evenly spaced grid (a log axis in effect).

Without the table (summarize not run) the script says so and exits 1; a
folder whose methods have fewer than two swept axes has nothing to draw
(exit 0).
"""

from __future__ import annotations

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
import numpy as np  # noqa: E402
import polars as pl  # noqa: E402

import sweepdata as sd  # noqa: E402

# Worst first, as the summary orders them; colours from safe to alarming.
STATES = ["stable", "invalid", "growing", "timeout", "solver-failed", "diverged"]
COLOURS = ["#4daf4a", "#bdbdbd", "#ffd92f", "#80b1d3", "#984ea3", "#e41a1c"]


def ticks(values: list[float]) -> list[str]:
    return [f"{v:.3g}" for v in values]


def panel(ax, cells: pl.DataFrame, x_axis: str, y_axis: str) -> None:
    xs = sorted(set(cells["x"].to_list()))
    ys = sorted(set(cells["y"].to_list()))
    grid = np.full((len(ys), len(xs)), np.nan)
    for row in cells.iter_rows(named=True):
        i, j = ys.index(row["y"]), xs.index(row["x"])
        grid[i, j] = STATES.index(row["state"]) if row["state"] in STATES else np.nan
        if not row["uniform"]:
            ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False,
                                       hatch="//", edgecolor="black", linewidth=0))
    cmap = ListedColormap(COLOURS)
    cmap.set_bad("white")
    ax.imshow(np.ma.masked_invalid(grid), cmap=cmap, vmin=-0.5, vmax=len(STATES) - 0.5,
              origin="lower", aspect="auto", interpolation="nearest")
    ax.set_xticks(range(len(xs)), ticks(xs), rotation=45, ha="right", fontsize=8)
    ax.set_yticks(range(len(ys)), ticks(ys), fontsize=8)
    ax.set_xlabel(x_axis)
    ax.set_ylabel(y_axis)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="results folder (with summary/stability_map.parquet)")
    ap.add_argument("--out", help="figure folder (default DIR/figures)")
    args = ap.parse_args()
    sd.require_dir(args.dir)
    out = sd.default_out(args.dir, args.out)
    path = os.path.join(args.dir, "summary", "stability_map.parquet")
    if not os.path.exists(path):
        print(f"{path}: missing — run `contact-sweep summarize {args.dir}` first", file=sys.stderr)
        return 1
    maps = pl.read_parquet(path)
    pngs = []
    if maps.height == 0:
        print("no method has two swept axes: no stability map to draw")
    for (method,), cells in maps.group_by(["method"], maintain_order=True):
        pairs = cells.select(["x_axis", "y_axis"]).unique(maintain_order=True).rows()
        n = len(pairs)
        cols = min(n, 3)
        rows = (n + cols - 1) // cols
        fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 4.0 * rows + 0.6),
                                 layout="constrained", squeeze=False)
        for ax, (xa, ya) in zip(axes.flat, pairs):
            panel(ax, cells.filter((pl.col("x_axis") == xa) & (pl.col("y_axis") == ya)), xa, ya)
        for ax in list(axes.flat)[n:]:
            ax.set_visible(False)
        present = [s for s in STATES if s in set(cells["state"].to_list())]
        fig.legend(handles=[Patch(color=COLOURS[STATES.index(s)], label=s) for s in present],
                   loc="outside upper center", ncols=len(present), fontsize=9)
        fig.suptitle(f"stability map: {method}", fontsize=11)
        folder = sd.safe_name(os.path.basename(os.path.normpath(args.dir)))
        pngs.append(sd.save_figure(fig, out, f"stability_map_{folder}_{sd.safe_name(method)}"))
    sd.write_manifest(out, "plot_stability_map.py", pngs, args.dir)
    return 0


if __name__ == "__main__":
    sys.exit(main())
