#!/usr/bin/env python3
"""Energy against time of the impact methods of 003 §4.2 (Figs 11 and 12).

    python3 analysis/plot_energy_impacts.py DIR [DIR ...] [--out FIGDIR] [--stem NAME] [--no-theta]
                                            [--balance] [--only COL=VALUE ...]

One figure per results folder DIR (e.g. out/003_fig11 from
sweeps/003_fig11_disc.toml): the discrete energy E^h of every run divided by
its `energy_scale` (disc2d/sphere3d: m|f|·gap, the kinetic energy of a rigid
body reaching the plane; E⁰ = 0 there, contract §1.3), against time t, one curve
per run, named as the paper names the methods (mixed + CN, Nitsche + CN,
Nitsche-Hybrid, modified mass + CN; other runs by their label). The runs table
is joined to the series on run_id for the labels and the scale.

Two panels: the whole range (the mixed method's spurious growth reaches tens
to hundreds of energy scales) and a zoom on the runs that stay within one
energy scale of E⁰, where the few-percent behaviour of the others shows.
Nitsche runs also get their augmented energy E_Θ (energy_theta), dashed in the
run's colour: during the contact E^h departs from E_Θ by the Nitsche terms,
E^h − E_Θ = (Θ/2)(‖γ^½ σ_n‖² − ‖γ^−½ [P_γ]_+‖²) over Γ_C (contract §2.3), and
comes back after the release (--no-theta leaves E_Θ out). Curves drawn
earlier are drawn wider, so one that coincides with a later one (Nitsche + CN
under Nitsche-Hybrid during the contact) still shows as its outline. The first contact time of the runs (the
earliest) is marked by a dotted vertical line.

With --balance, frictional runs (series column friction_work, W_f^n, contract
§2.5) also get E^h + W_f, dash-dotted in the run's colour: the energy plus the
work friction took, which changes only by the normal contact's work (kane and
moreau-jean θ = ½ never raise it). Runs without friction_work are drawn as
before. --only COL=VALUE (repeatable) keeps the runs whose runs-table column
equals VALUE (numbers compared as numbers), e.g. --only h=1 for one level of a
refinement sweep.

The file is energy_impacts_SWEEP.png (+ .pdf), or NAME.png with --stem (one
DIR only). Per run the script prints the drift (E^N − E⁰)/scale and the
largest deviation max_n |E^n − E⁰|/scale it drew. Only runs with status ok
are drawn unless --include-failed. Exit 0 also when nothing could be drawn
(no series rows), with the reason.
"""

from __future__ import annotations

import argparse
import os
import sys

import matplotlib.pyplot as plt
import numpy as np
import polars as pl

import sweepdata as sd

# Runs-table columns beyond sweepdata's vocabulary (present on the 2D/3D scenes).
EXTRA_RUN_COLUMNS = ["energy_scale", "first_contact_time", "contact_phases"]

# A run whose energy stays within this many energy scales of E⁰ is drawn in the zoom
# panel's limits; the others (the mixed method's growth) leave that window.
ZOOM_WITHIN = 1.0


def paper_name(row: dict) -> str:
    """The name 003 §4.2 gives a method, or the run's own label."""
    space, mass, scheme = row.get("space"), row.get("mass"), row.get("scheme_label")
    cn = scheme == "crank-nicolson"
    if space == "nitsche" and scheme == "hybrid" and mass == "consistent":
        name = "Nitsche-Hybrid"
    elif space == "nitsche" and cn and mass == "consistent":
        name = "Nitsche + CN"
    elif space == "mixed" and cn and mass == "consistent":
        name = "mixed + CN"
    elif cn and mass == "zero-contact":
        # 003 §4.1.2d: the contact nodes' entries of M set to 0, nothing redistributed.
        name = "modified mass + CN" + ("" if space == "mixed" else f" ({space})")
    else:
        return str(row.get("label") or row.get("run_id"))
    if space == "nitsche":
        theta, gamma0 = row.get("nitsche_theta"), row.get("nitsche_gamma0")
        if theta is not None and gamma0 is not None:
            name += f" (Θ = {sd.fmt_value(theta)}, γ0 = {sd.fmt_value(gamma0)})"
    return name


# Paper order (003 §4.2: "mixed and Nitsche's semi-discretization combined with
# Crank-Nicolson, the Nitsche-Hybrid method and the modified mass method").
ORDER = ["mixed + CN", "Nitsche + CN", "Nitsche-Hybrid", "modified mass + CN"]


def order_key(name: str) -> tuple:
    for i, prefix in enumerate(ORDER):
        if name.startswith(prefix):
            return (i, name)
    return (len(ORDER), name)


def scale_of(row: dict, energy: np.ndarray) -> tuple[float | None, str]:
    """The run's energy scale, or |E⁰| when the runs table has none (older folders)."""
    s = row.get("energy_scale")
    if s is not None and np.isfinite(s) and s > 0:
        return float(s), "energy_scale"
    finite = energy[np.isfinite(energy)]
    if finite.size and finite[0] != 0:
        return abs(float(finite[0])), "|E⁰|"
    return None, ""


def only_mask(column: pl.Series, value: str) -> pl.Series:
    """Rows of `column` equal to `value`: as numbers for a numeric column, else as text."""
    if column.dtype.is_numeric():
        try:
            x = float(value)
        except ValueError:
            return pl.Series([False] * column.len())
        return (column.cast(pl.Float64) == x).fill_null(False)
    return (column.cast(pl.String) == value).fill_null(False)


def parse_only(text: str) -> tuple[str, str]:
    col, sep, value = text.partition("=")
    if not sep or not col or not value:
        raise argparse.ArgumentTypeError(f"--only takes COL=VALUE, not {text!r}")
    return col.strip(), value.strip()


def draw_folder(run_dir: str, out: str, stem: str | None, args) -> str | None:
    runs = sd.load_runs(run_dir)
    if not args.include_failed:
        kept = sd.ok_runs(runs)
        if kept.height < runs.height:
            print(f"{run_dir}: leaving out {runs.height - kept.height} run(s) whose status is not ok")
        runs = kept
    for c in EXTRA_RUN_COLUMNS:
        if c not in runs.columns:
            runs = runs.with_columns(pl.lit(None, dtype=pl.Float64).alias(c))
    for col, value in args.only or []:
        if col not in runs.columns:
            print(f"{run_dir}: no column {col} in the runs table, --only {col}={value} keeps nothing")
            runs = runs.head(0)
            continue
        runs = runs.filter(only_mask(runs[col], value))
    columns = ["energy", "energy_theta"] + (["friction_work"] if args.balance else [])
    series = sd.load_series(run_dir, run_ids=runs["run_id"].to_list(), columns=columns)
    # The join on run_id: every series row gets its run's label and scale.
    joined = series.join(runs.select(["run_id"] + [c for c in runs.columns if c not in series.columns]),
                         on="run_id", how="inner")
    if joined.height == 0:
        print(f"{run_dir}: no series rows for its runs, nothing to draw")
        return None

    rows = []
    for (rid,), s in joined.group_by(["run_id"], maintain_order=True):
        s = s.sort("step")
        row = s.row(0, named=True)
        t = s["t"].to_numpy()
        e = s["energy"].to_numpy().astype(float)
        scale, scale_name = scale_of(row, e)
        if scale is None:
            print(f"{run_dir}: run {rid} has no energy scale and E⁰ = 0, left out")
            continue
        et = s["energy_theta"].to_numpy().astype(float) if s["energy_theta"].null_count() < s.height else None
        bal = None
        if args.balance and s["friction_work"].null_count() < s.height:
            # E^h + W_f: W_f^n is J, like the energy (0 before the first contact step).
            bal = (e + s["friction_work"].fill_null(0.0).to_numpy().astype(float)) / scale
        rows.append((paper_name(row), row, t, e / scale, None if et is None else et / scale, scale_name, bal))
    if not rows:
        print(f"{run_dir}: no run could be normalised, nothing to draw")
        return None
    # Runs the method name does not tell apart (a refinement, two sweeps) get the parameters
    # that differ, as plot_series.py's legends do.
    drawn = runs.filter(pl.col("run_id").is_in([r[1]["run_id"] for r in rows]))
    extra = sd.distinguishing_columns(drawn, sd.LEGEND_COLUMNS)
    if extra:
        rows = [(sd.legend_text({**r[1], "label": r[0]}, extra), *r[1:]) for r in rows]
    rows.sort(key=lambda r: order_key(r[0]))
    scale_names = sorted({r[5] for r in rows})
    sweeps = sorted({str(r[1].get("sweep")) for r in rows})
    scenes = sorted({str(r[1].get("scene")) for r in rows})

    fig, (ax_all, ax_zoom) = plt.subplots(2, 1, figsize=(9, 8.5), sharex=True, layout="constrained")
    zoom_lo, zoom_hi = np.inf, -np.inf
    left_window = []
    for i, (name, row, t, rel, rel_theta, _, rel_bal) in enumerate(rows):
        st = sd.style(i)
        lw = max(2.6 - 0.5 * i, 1.0)
        e0 = rel[np.isfinite(rel)][0] if np.isfinite(rel).any() else 0.0
        dev = np.abs(rel - e0)
        drift = rel[-1] - e0
        max_dev = float(np.nanmax(dev)) if dev.size else float("nan")
        phases = row.get("contact_phases")
        label = f"{name}: drift {drift:+.2e}, max dev {max_dev:.2e}"
        if phases is not None:
            label += f", {phases} contact phase{'s' if phases != 1 else ''}"
        bal_text = ""
        if rel_bal is not None:
            bal_drift = rel_bal[-1] - e0
            label += f"; E + W_f drift {bal_drift:+.2e}"
            bal_text = f", E(T)+W_f−E⁰ = {bal_drift:+.3e}"
        print(f"{row.get('sweep')} {name}: E(T)−E⁰ = {drift:+.3e}, max |E−E⁰| = {max_dev:.3e} (× {scale_names[0]})"
              + bal_text + (f", contact phases {phases}" if phases is not None else ""))
        for ax in (ax_all, ax_zoom):
            ax.plot(t, rel, color=st["color"], lw=lw, label=label if ax is ax_all else None)
            if rel_theta is not None and not args.no_theta:
                ax.plot(t, rel_theta, color=st["color"], lw=max(lw - 0.8, 0.8), ls="--",
                        label=f"{name}: E_Θ" if ax is ax_all else None)
            if rel_bal is not None:
                ax.plot(t, rel_bal, color=st["color"], lw=max(lw - 0.8, 0.8), ls="-.",
                        label=f"{name}: E + W_f" if ax is ax_all else None)
        if max_dev <= ZOOM_WITHIN:
            zoom_lo = min(zoom_lo, float(np.nanmin(rel)))
            zoom_hi = max(zoom_hi, float(np.nanmax(rel)))
            if rel_bal is not None:
                zoom_lo = min(zoom_lo, float(np.nanmin(rel_bal)))
                zoom_hi = max(zoom_hi, float(np.nanmax(rel_bal)))
            if rel_theta is not None and not args.no_theta:
                zoom_lo = min(zoom_lo, float(np.nanmin(rel_theta)))
                zoom_hi = max(zoom_hi, float(np.nanmax(rel_theta)))
        else:
            left_window.append(name)

    t_fc = [r[1]["first_contact_time"] for r in rows if r[1].get("first_contact_time") is not None]
    if t_fc:
        for ax in (ax_all, ax_zoom):
            ax.axvline(min(t_fc), color="gray", ls=":", lw=1.0)
        ax_all.text(min(t_fc), 1.0, " first contact", transform=ax_all.get_xaxis_transform(),
                    va="top", ha="left", fontsize="small", color="gray")
    unit = " / ".join(scale_names)
    ax_all.set_ylabel(f"E^h / {unit}")
    ax_all.set_title("whole range", loc="left", fontsize="medium")
    if np.isfinite(zoom_lo):
        pad = max(0.1 * (zoom_hi - zoom_lo), 1e-3)
        ax_zoom.set_ylim(zoom_lo - pad, zoom_hi + pad)
    note = f" ({', '.join(left_window)} outside)" if left_window else ""
    ax_zoom.set_title(f"zoom on the runs within {ZOOM_WITHIN:g} {unit} of E⁰{note}", loc="left", fontsize="medium")
    ax_zoom.set_ylabel(f"E^h / {unit}")
    ax_zoom.set_xlabel("time t")
    for ax in (ax_all, ax_zoom):
        ax.grid(True, alpha=0.3)
        ax.ticklabel_format(axis="y", useOffset=False)
    fig.suptitle(f"sweep {', '.join(sweeps)} ({', '.join(scenes)}): energy against time"
                 + ("; dashed: E_Θ" if any(r[4] is not None for r in rows) and not args.no_theta else "")
                 + ("; dash-dot: E + W_f" if any(r[6] is not None for r in rows) else "")
                 + "".join(f"; {c} = {v}" for c, v in args.only or []))
    fig.legend(loc="outside lower center", ncols=1, fontsize="small")
    name = stem or f"energy_impacts_{sd.safe_name(sweeps[0] if len(sweeps) == 1 else os.path.basename(run_dir))}"
    return sd.save_figure(fig, out, name)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("dirs", nargs="+", metavar="DIR", help="sweep output folder(s) (with runs/ and series/)")
    ap.add_argument("--out", help="figure folder (default DIR/figures of each DIR)")
    ap.add_argument("--stem", help="file name without extension (only with one DIR)")
    ap.add_argument("--no-theta", action="store_true", help="leave out E_Θ of the Nitsche runs")
    ap.add_argument("--include-failed", action="store_true", help="also draw runs whose status is not ok")
    ap.add_argument("--balance", action="store_true",
                    help="also draw E + W_f (series friction_work) for the frictional runs, dash-dotted")
    ap.add_argument("--only", action="append", type=parse_only, metavar="COL=VALUE",
                    help="keep the runs whose runs-table column equals VALUE (repeatable), e.g. h=1")
    args = ap.parse_args()
    if args.stem and len(args.dirs) > 1:
        ap.error("--stem names one figure: give one DIR")
    for d in args.dirs:
        sd.require_dir(d)
    for d in args.dirs:
        out = sd.default_out(d, args.out)
        png = draw_folder(d, out, args.stem, args)
        sd.write_manifest(out, "plot_energy_impacts.py", [png] if png else [], d)
    return 0


if __name__ == "__main__":
    sys.exit(main())
