#!/usr/bin/env python3
"""Time series of each sweep: contact displacement, contact pressure and energy.

    python3 analysis/plot_series.py DIR [--out FIGDIR] [--max-curves 8] [--include-failed]

For every sweep in DIR one figure with three stacked panels against time t:
u_contact, sigma_contact and energy / E0 (E0 = the run's first energy; for a
run starting at E0 = 0, the disc and ball under gravity, energy / energy_scale
of the runs table), one curve per run. Where the engine wrote a closed-form solution
(u_contact_exact, sigma_contact_exact) it is drawn dashed in black. The exact
energy is known for the bar1d scene, E = young*amplitude^2/(2*length), and is
conserved: it is drawn as the dashed line E/E0 = 1, and the mismatch of the
discrete initial energy, E0/E_exact, is written in the panel (energy_initial
of a run is *not* the exact energy: it carries the interpolation error of the
initial data). Nitsche runs that report energy_theta get it dotted in the
run's colour, normalised by its own first value.

A sweep with more than --max-curves runs is split into several figures
(series_SWEEP_partK.png), keeping the runs of one method together, and the
split is printed. Only runs with status ok are drawn unless --include-failed:
a diverged run's blow-up would otherwise flatten every other curve.
"""

from __future__ import annotations

import argparse
import sys

import matplotlib.pyplot as plt
import numpy as np
import polars as pl
from matplotlib.lines import Line2D

import sweepdata as sd

SERIES_VALUES = ["u_contact", "sigma_contact", "energy", "energy_theta", "u_contact_exact", "sigma_contact_exact"]


def ordered_runs(runs: pl.DataFrame) -> list[pl.DataFrame]:
    """Method groups, each sorted coarse to fine, so a figure reads as a refinement."""
    return [g.sort(["h", "dt", "run_id"], descending=[True, True, False], nulls_last=True)
            for g in sd.method_groups(runs)]


def chunk_groups(groups: list[pl.DataFrame], max_curves: int) -> list[pl.DataFrame]:
    """Pack whole method groups into figures of at most ``max_curves`` runs.

    Keeping a method's runs together matters more than filling every figure:
    the reader compares refinement levels of one method within a figure. A
    group larger than ``max_curves`` is itself cut into consecutive slices.
    """
    pieces: list[pl.DataFrame] = []
    for g in groups:
        for start in range(0, g.height, max_curves):
            pieces.append(g.slice(start, max_curves))
    chunks: list[list[pl.DataFrame]] = []
    for p in pieces:
        if chunks and sum(x.height for x in chunks[-1]) + p.height <= max_curves:
            chunks[-1].append(p)
        else:
            chunks.append([p])
    return [pl.concat(c, how="diagonal_relaxed") for c in chunks]


def exact_energy(row: dict) -> float | None:
    """Closed-form (conserved) energy where the scene has one."""
    if row.get("scene") == "bar1d":
        e, a, length = row.get("young"), row.get("amplitude"), row.get("length")
        if None not in (e, a, length) and length > 0:
            return e * a * a / (2.0 * length)
    return None


def zero_start_scale(row: dict, e: np.ndarray) -> float | None:
    """The run's `energy_scale` when its initial energy is zero (disc2d/sphere3d: E⁰ = 0
    under gravity, contract §1.3), else None. Dividing by the first non-zero value would divide
    by the rounding of the first steps (~1e-17) there."""
    scale = row.get("energy_scale")
    if scale is None or not np.isfinite(scale) or scale <= 0 or e.size == 0 or not np.isfinite(e[0]):
        return None
    return float(scale) if abs(e[0]) <= 1e-12 * scale else None


def first_value(x: np.ndarray) -> float | None:
    """First finite, non-zero value: the normalisation of a relative energy."""
    ok = np.isfinite(x) & (x != 0)
    return float(x[ok][0]) if ok.any() else None


def plot_exact(axes, chunk: pl.DataFrame, series: dict[str, pl.DataFrame]) -> list[tuple]:
    """Draw the exact u and sigma once per distinct physical problem in the chunk."""
    handles = []
    phys = [c for c in sd.PHYSICS_COLUMNS if c in chunk.columns]
    problems = chunk.partition_by(phys, maintain_order=True) if phys else [chunk]
    # Several problems in one figure: name each exact curve by what differs
    # (the label is no help here, so plain variation is the criterion).
    varying = [c for c in phys if chunk[c].n_unique() > 1] if len(problems) > 1 else []
    linestyles = ["--", "-.", (0, (5, 1, 1, 1)), ":"]
    for k, prob in enumerate(problems):
        # The run with the most exact samples gives the best-resolved curve.
        best, best_n = None, 0
        for rid in prob["run_id"]:
            s = series.get(rid)
            if s is None:
                continue
            n = max(s["u_contact_exact"].drop_nulls().len(), s["sigma_contact_exact"].drop_nulls().len())
            if n > best_n:
                best, best_n = s, n
        if best is None:
            continue
        ls = linestyles[k % len(linestyles)]
        for ax, col in zip(axes[:2], ["u_contact_exact", "sigma_contact_exact"]):
            d = best.filter(pl.col(col).is_not_null() & pl.col(col).is_finite())
            if d.height:
                ax.plot(d["t"].to_numpy(), d[col].to_numpy(), color="black", ls=ls, lw=1.2, zorder=5)
        row = prob.row(0, named=True)
        extra = ", ".join(f"{c}={sd.fmt_value(row[c])}" for c in varying if row[c] is not None)
        handles.append((Line2D([], [], color="black", ls=ls, lw=1.2), "exact" + (f" ({extra})" if extra else "")))
    return handles


def plot_chunk(sweep: str, chunk: pl.DataFrame, series: dict[str, pl.DataFrame],
               legend_cols: list[str], part: int, nparts: int, args) -> plt.Figure:
    fig, axes = plt.subplots(3, 1, figsize=(9, 10.5), sharex=True, layout="constrained")
    handles: list[tuple] = []
    any_theta = False
    ratios = []  # E0 / E_exact per run
    e_exact_any = False
    rel_max, rel_min = 0.0, np.inf  # range of E/E0, to switch to a log axis for blow-ups
    any_scaled = False  # a run with E⁰ = 0 drawn as E / energy_scale
    for i, row in enumerate(chunk.iter_rows(named=True)):
        s = series.get(row["run_id"])
        if s is None:
            continue
        st = sd.style(i)
        t = s["t"].to_numpy()
        kw = dict(color=st["color"], lw=1.0)
        # Markers only when a curve is short enough for them to be readable.
        if s.height <= 60:
            kw.update(marker=st["marker"], ms=3)
        line = None
        for ax, col in zip(axes[:2], ["u_contact", "sigma_contact"]):
            y = s[col].to_numpy()
            if np.isfinite(y).any():
                line = ax.plot(t, y, **kw)[0]
        e = s["energy"].to_numpy()
        e0 = first_value(e)
        scale = zero_start_scale(row, e)
        norm = scale if scale is not None else e0
        any_scaled |= scale is not None
        if norm is not None:
            line = axes[2].plot(t, e / norm, **kw)[0]
            rel = e[np.isfinite(e)] / norm
            if rel.size:
                rel_max = max(rel_max, float(np.abs(rel).max()))
                rel_min = min(rel_min, float(rel.min()))
            ex = exact_energy(row)
            if ex and e0 is not None:
                e_exact_any = True
                ratios.append(e0 / ex)
        et = s["energy_theta"].to_numpy()
        et0 = first_value(et) if scale is None else scale
        if et0 is not None:
            any_theta = True
            axes[2].plot(t, et / et0, color=st["color"], lw=1.0, ls=":")
        if line is not None:
            label = sd.legend_text(row, legend_cols)
            if row.get("status") not in (None, "ok"):
                label += f" [{row['status']}]"
            handles.append((Line2D([], [], **kw), label))

    exact_handles = plot_exact(axes, chunk, series)
    if e_exact_any:
        axes[2].axhline(1.0, color="black", ls="--", lw=1.2, zorder=5)
        if len(exact_handles) == 1 and exact_handles[0][1] == "exact":
            # Same line style for both: one legend entry says it all.
            exact_handles = [(exact_handles[0][0], "exact (energy conserved: E/E0 = 1)")]
        else:
            exact_handles.append((Line2D([], [], color="black", ls="--", lw=1.2), "exact energy (conserved)"))
        # Above the panel, where no curve can hide it.
        axes[2].set_title(f"E0/E_exact ∈ [{min(ratios):.6g}, {max(ratios):.6g}]", loc="right", fontsize="small")
    handles += exact_handles
    if any_theta:
        handles.append((Line2D([], [], color="gray", ls=":"), "dotted: energy_theta / its first value (Nitsche)" + (" or energy_scale" if any_scaled else "")))

    axes[0].set_ylabel("contact displacement u")
    axes[1].set_ylabel("contact pressure σ")
    axes[2].set_ylabel("energy E / E0" + (" (E⁰ = 0: E / energy_scale)" if any_scaled else ""))
    axes[2].set_xlabel("time t")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    if rel_max > 100:
        # A diverged run (--include-failed) would squash every other curve
        # onto E/E0 = 1 on a linear axis.
        if rel_min > 0:
            axes[2].set_yscale("log")
        else:
            axes[2].set_yscale("symlog", linthresh=1.0)
    else:
        # Avoid matplotlib's "1e-6 + 1" offset notation, unreadable for E/E0 ≈ 1.
        axes[2].ticklabel_format(axis="y", useOffset=False)
    title = f"sweep {sweep}: contact displacement, pressure and energy"
    if nparts > 1:
        title += f" (part {part}/{nparts}, ≤ {args.max_curves} runs per figure)"
    fig.suptitle(title)
    if handles:
        labels = [h[1] for h in handles]
        ncols = 1 if max(len(x) for x in labels) > 50 else 2
        fig.legend([h[0] for h in handles], labels, loc="outside lower center", ncols=ncols, fontsize="small")
    return fig


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("dir", help="sweep output folder (with runs/ and series/)")
    ap.add_argument("--out", help="figure folder (default DIR/figures)")
    ap.add_argument("--max-curves", type=int, default=8, help="runs per figure before splitting (default 8)")
    ap.add_argument("--include-failed", action="store_true", help="also draw runs whose status is not ok")
    args = ap.parse_args()
    args.max_curves = max(1, args.max_curves)
    sd.require_dir(args.dir)
    out = sd.default_out(args.dir, args.out)

    runs = sd.load_runs(args.dir)
    if not args.include_failed:
        kept = sd.ok_runs(runs)
        if kept.height < runs.height:
            print(f"note: leaving out {runs.height - kept.height} run(s) whose status is not ok "
                  f"(use --include-failed to draw them)")
        runs = kept

    pngs: list[str] = []
    for sweep in sorted(runs["sweep"].unique().to_list()):
        sweep_runs = runs.filter(pl.col("sweep") == sweep)
        raw = sd.load_series(args.dir, run_ids=sweep_runs["run_id"].to_list(), columns=SERIES_VALUES)
        series = {str(k[0]): g for k, g in raw.group_by(["run_id"])} if raw.height else {}
        with_series = sweep_runs.filter(pl.col("run_id").is_in(list(series)))
        if with_series.height == 0:
            print(f"sweep {sweep}: no series rows for its runs, skipped")
            continue
        if with_series.height < sweep_runs.height:
            print(f"sweep {sweep}: {sweep_runs.height - with_series.height} run(s) without series rows left out")
        chunks = chunk_groups(ordered_runs(with_series), args.max_curves)
        if len(chunks) > 1:
            print(f"sweep {sweep}: {with_series.height} runs > {args.max_curves}, split into "
                  f"{len(chunks)} figures (runs of one method kept together)")
        # Legend columns are decided on the whole sweep so that every part
        # of a split sweep names its runs the same way.
        legend_cols = sd.distinguishing_columns(with_series, sd.LEGEND_COLUMNS)
        stem = f"series_{sd.safe_name(sweep)}"
        for k, chunk in enumerate(chunks, start=1):
            fig = plot_chunk(sweep, chunk, series, legend_cols, k, len(chunks), args)
            pngs.append(sd.save_figure(fig, out, stem if len(chunks) == 1 else f"{stem}_part{k}"))

    sd.write_manifest(out, "plot_series.py", pngs, args.dir)
    if not pngs:
        print("nothing to plot: no run has series rows")
    return 0


if __name__ == "__main__":
    sys.exit(main())
