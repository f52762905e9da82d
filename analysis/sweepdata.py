"""Shared helpers for the contact-sweep analysis scripts.

Everything that knows about the engine's output layout lives here, so the
plotting scripts only deal with "a runs table" and "a series table":

* reading ``DIR/runs/*.parquet`` and ``DIR/series/*.parquet`` while ignoring
  temporary files (names starting with ``.``) and surviving unreadable files,
  files with different column sets and columns that are entirely null;
* the column vocabulary (which columns are parameters, which are results,
  which define a "method group");
* legend text, figure saving (PNG + PDF) and the figure manifest that
  ``check_figures.py`` reads.
"""

from __future__ import annotations

import glob
import json
import math
import os
import re
import sys
from collections import Counter
from typing import Iterable, Sequence

import matplotlib

# Headless on purpose: the scripts run on CI and over SSH where no display
# exists. Must be set before pyplot is imported anywhere.
matplotlib.use("Agg")

import polars as pl  # noqa: E402

# --------------------------------------------------------------------------
# Column vocabulary
# --------------------------------------------------------------------------

ID_COLUMNS = {
    "run_id": pl.String,
    "sweep": pl.String,
    "scene": pl.String,
    "label": pl.String,
    "status": pl.String,
    "message": pl.String,
}

# Discretisation / physics parameters (inputs of a run).
PARAM_COLUMNS = {
    "T": pl.Float64,
    "h": pl.Float64,
    "dt": pl.Float64,
    "courant": pl.Float64,
    "elements": pl.Int64,
    "space": pl.String,
    "mass": pl.String,
    "scheme": pl.String,
    "scheme_label": pl.String,
    "nitsche_theta": pl.Float64,
    "nitsche_gamma0": pl.Float64,
    "penalty_gamma0": pl.Float64,
    "newmark_beta": pl.Float64,
    "newmark_gamma": pl.Float64,
    "theta_scheme": pl.Float64,
    "restitution": pl.Float64,
    "length": pl.Float64,
    "young": pl.Float64,
    "density": pl.Float64,
    "amplitude": pl.Float64,
    "gap": pl.Float64,
}

ERROR_COLUMNS = [
    "err_u_l2l2",
    "err_u_l2h1",
    "err_u_linfl2",
    "err_sigma_l2",
    "err_sigma_mid_l2",
    "err_energy_l2",
    "err_u_contact_max",
    "err_sigma_t_l2",
    "err_vt_final",
]

RESULT_COLUMNS = {
    "wall_time_s": pl.Float64,
    "steps": pl.Int64,
    "dofs": pl.Int64,
    "iterations": pl.Int64,
    "mass_total": pl.Float64,
    "energy_initial": pl.Float64,
    "energy_final": pl.Float64,
    "energy_drift": pl.Float64,
    "energy_max_dev": pl.Float64,
    "energy_max_increase": pl.Float64,
    "energy_theta_max_increase": pl.Float64,
    **{c: pl.Float64 for c in ERROR_COLUMNS},
}

RUN_COLUMNS = {**ID_COLUMNS, **PARAM_COLUMNS, **RESULT_COLUMNS}

SERIES_COLUMNS = {
    "run_id": pl.String,
    "step": pl.Int64,
    "t": pl.Float64,
    "u_contact": pl.Float64,
    "v_contact": pl.Float64,
    "sigma_contact": pl.Float64,
    "energy": pl.Float64,
    "energy_theta": pl.Float64,
    "u_contact_exact": pl.Float64,
    "sigma_contact_exact": pl.Float64,
}

# Columns that change along a refinement path. A "method group" is the set of
# runs that agree on every other parameter, so that one group = one curve in a
# convergence or work-precision plot.
REFINEMENT_COLUMNS = ["h", "elements", "dt", "courant"]
GROUP_COLUMNS = ["scene"] + [c for c in PARAM_COLUMNS if c not in REFINEMENT_COLUMNS]

# Parameters that define the continuous problem (and hence its exact solution),
# as opposed to the discretisation.
PHYSICS_COLUMNS = ["scene", "T", "length", "young", "density", "amplitude", "gap"]

# Priority of the columns a legend may add to a label: discretisation first
# (h before elements, dt before courant), then the remaining method columns.
LEGEND_COLUMNS = ["h", "dt", "courant", "elements"] + GROUP_COLUMNS


def warn(msg: str) -> None:
    print(f"warning: {msg}", file=sys.stderr)


# --------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------


def parquet_files(folder: str) -> list[str]:
    """Sorted ``*.parquet`` files in ``folder``, skipping temporary dot-files.

    ``glob`` already skips names starting with "." for a ``*`` pattern; the
    explicit check documents the contract and guards against glob changes.
    """
    files = glob.glob(os.path.join(glob.escape(folder), "*.parquet"))
    return sorted(f for f in files if not os.path.basename(f).startswith("."))


def _normalise(df: pl.DataFrame, schema: dict) -> pl.DataFrame:
    """Give every known column its canonical dtype and add the missing ones as nulls.

    Downstream code can then use every known column unconditionally; "absent"
    and "all null" become the same case. Non-strict casts turn unparsable
    values into nulls instead of aborting a whole analysis.
    """
    exprs = []
    for name, dtype in schema.items():
        if name in df.columns:
            if df.schema[name] != dtype:
                exprs.append(pl.col(name).cast(dtype, strict=False))
        else:
            exprs.append(pl.lit(None, dtype=dtype).alias(name))
    return df.with_columns(exprs) if exprs else df


def _read_many(files: Sequence[str], schema: dict, columns: Iterable[str] | None = None,
               run_ids: Iterable[str] | None = None) -> pl.DataFrame:
    frames = []
    wanted = None if columns is None else list(dict.fromkeys(columns))
    ids = None if run_ids is None else list(run_ids)
    for f in files:
        try:
            lf = pl.scan_parquet(f)
            present = lf.collect_schema().names()
            if wanted is not None:
                lf = lf.select([c for c in wanted if c in present])
            if ids is not None and "run_id" in present:
                lf = lf.filter(pl.col("run_id").cast(pl.String).is_in(ids))
            df = lf.collect()
        except Exception as exc:  # a truncated or foreign file must not kill the analysis
            warn(f"skipping unreadable file {f}: {exc}")
            continue
        frames.append(_normalise(df, schema))
    if not frames:
        return _normalise(pl.DataFrame(), schema)
    # "diagonal_relaxed": files may carry different extra columns (unknown to
    # this module); the union is kept and missing cells become null.
    return pl.concat(frames, how="diagonal_relaxed")


def load_runs(run_dir: str) -> pl.DataFrame:
    """The runs table of a sweep output folder (one row per run)."""
    files = parquet_files(os.path.join(run_dir, "runs"))
    runs = _read_many(files, RUN_COLUMNS)
    # Fallbacks so that legends and grouping always have something to show.
    runs = runs.with_columns(
        pl.col("sweep").fill_null("(no sweep)"),
        pl.coalesce(
            pl.col("label"),
            # Without a label, the method columns are the next best description.
            pl.when(pl.any_horizontal(pl.col("space", "mass", "scheme_label").is_not_null()))
            .then(pl.concat_str([pl.col("space"), pl.col("mass"), pl.col("scheme_label")],
                                separator=" ", ignore_nulls=True)),
            pl.col("run_id"),
        ).alias("label"),
    )
    return runs


def load_series(run_dir: str, run_ids: Iterable[str] | None = None,
                columns: Iterable[str] | None = None) -> pl.DataFrame:
    """Per-step series, optionally restricted to some runs and columns."""
    files = parquet_files(os.path.join(run_dir, "series"))
    cols = None if columns is None else ["run_id", "step", "t", *columns]
    schema = SERIES_COLUMNS if cols is None else {c: SERIES_COLUMNS.get(c, pl.Float64) for c in cols}
    series = _read_many(files, schema, columns=cols, run_ids=run_ids)
    return series.sort(["run_id", "step", "t"], nulls_last=True)


def require_dir(run_dir: str) -> None:
    """Exit with a clear message when DIR is not a sweep output folder."""
    if not os.path.isdir(run_dir):
        sys.exit(f"error: {run_dir} is not a directory")
    if not parquet_files(os.path.join(run_dir, "runs")):
        sys.exit(f"error: no runs/*.parquet in {run_dir} (is this a sweep output folder?)")


def ok_runs(runs: pl.DataFrame) -> pl.DataFrame:
    """Runs whose status is ok. A missing status column is read as "all ok"."""
    if runs["status"].null_count() == runs.height:
        return runs
    return runs.filter(pl.col("status") == "ok")


def has_values(df: pl.DataFrame, col: str) -> bool:
    """True when ``col`` exists and holds at least one finite, non-null value."""
    if col not in df.columns or df.height == 0:
        return False
    s = df[col]
    if s.dtype.is_float():
        s = s.filter(s.is_finite())
    return s.drop_nulls().len() > 0


# --------------------------------------------------------------------------
# Grouping and labels
# --------------------------------------------------------------------------


def fmt_value(v) -> str:
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        return f"{v:.3g}"
    return str(v)


def _key_str(v) -> str:
    # Sort key that works for None / mixed types and keeps numbers in order.
    if v is None:
        return "~"  # nulls last
    if isinstance(v, (int, float)):
        return f"{v:+.12e}"
    return str(v)


def method_groups(df: pl.DataFrame, by: Sequence[str] = GROUP_COLUMNS) -> list[pl.DataFrame]:
    """Split runs into method groups, in a deterministic order (label, then keys)."""
    if df.height == 0:
        return []
    by = [c for c in by if c in df.columns]
    if not by:
        return [df]
    parts = df.partition_by(by, maintain_order=True)

    def order(part: pl.DataFrame):
        return (_key_str(part["label"][0]), [_key_str(part[c][0]) for c in by])

    return sorted(parts, key=order)


def _determined_by(df: pl.DataFrame, col: str, by: Sequence[str]) -> bool:
    """True when ``col`` takes a single value for each combination of ``by``."""
    if not by:
        return df[col].n_unique() <= 1
    per_key = df.group_by(list(by)).agg(pl.col(col).n_unique().alias("n"))
    return per_key["n"].max() <= 1


def distinguishing_columns(df: pl.DataFrame, candidates: Sequence[str]) -> list[str]:
    """Columns worth showing next to ``label`` to tell the rows of ``df`` apart.

    A column is shown when it varies, is not already implied by the label
    (which spells out the method, e.g. "nitsche(Θ=1, γ0=1e-06)"), and is not a
    function of the columns chosen before it (elements follows from h; in a
    time-step study courant follows from dt). Candidates are considered in
    the order given, so the caller sets the priority.
    """
    out: list[str] = []
    for c in candidates:
        if c not in df.columns or c == "label" or c in out:
            continue
        if _determined_by(df, c, ["label"]) or _determined_by(df, c, out):
            continue
        out.append(c)
    return out


def legend_text(row: dict, cols: Sequence[str]) -> str:
    extras = [f"{c}={fmt_value(row[c])}" for c in cols if row.get(c) is not None]
    return ", ".join([str(row.get("label") or row.get("run_id"))] + extras)


def describe_groups(groups: Sequence[pl.DataFrame]) -> list[str]:
    """One legend entry per method group: label plus what sets the groups apart."""
    if not groups:
        return []
    firsts = pl.concat([g.head(1) for g in groups], how="diagonal_relaxed")
    cols = distinguishing_columns(firsts, GROUP_COLUMNS)
    names = [legend_text(r, cols) for r in firsts.iter_rows(named=True)]
    # Two groups whose first labels coincide but still differ somewhere the
    # rule above did not catch: disambiguate rather than print twins.
    counts = Counter(names)
    seen: Counter = Counter()
    for i, n in enumerate(names):
        if counts[n] > 1:
            seen[n] += 1
            names[i] = f"{n} [{seen[n]}]"
    return names


def style(i: int) -> dict:
    """Colour + marker for the i-th curve; markers cycle slower than colours so
    that more than 10 curves stay distinguishable."""
    colors = matplotlib.colormaps["tab10"].colors
    markers = ["o", "s", "^", "D", "v", "P", "X", "*"]
    return {"color": colors[i % len(colors)], "marker": markers[(i // len(colors)) % len(markers)]}


def safe_name(s: str) -> str:
    """File-name-safe version of a sweep name."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", str(s)).strip("._")
    return s or "sweep"


# --------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------

MANIFEST = "figures.json"


def save_figure(fig, out_dir: str, stem: str) -> str:
    """Save ``fig`` as STEM.png and STEM.pdf in ``out_dir``; return the PNG name."""
    os.makedirs(out_dir, exist_ok=True)
    png = f"{stem}.png"
    fig.savefig(os.path.join(out_dir, png), dpi=150)
    fig.savefig(os.path.join(out_dir, f"{stem}.pdf"))
    import matplotlib.pyplot as plt

    plt.close(fig)
    print(f"wrote {os.path.join(out_dir, png)} (+ .pdf)")
    return png


def write_manifest(out_dir: str, script: str, pngs: Sequence[str], source: str) -> None:
    """Record which PNGs ``script`` produced from the results folder ``source``.

    Each (script, source folder) pair owns its own entry and rewrites it on
    every run; figures it recorded last time but did not produce now (e.g. a
    sweep that was renamed) are deleted so that a stale picture cannot pass
    for a fresh one. Figures drawn from other folders into the same FIGDIR are
    never touched.
    """
    script = f"{script} {os.path.abspath(source)}"
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, MANIFEST)
    manifest: dict = {}
    if os.path.exists(path):
        try:
            with open(path, encoding="utf-8") as fh:
                manifest = json.load(fh)
        except (OSError, ValueError):
            manifest = {}
    for old in set(manifest.get(script, [])) - set(pngs):
        for ext in (".png", ".pdf"):
            p = os.path.join(out_dir, os.path.splitext(old)[0] + ext)
            if os.path.exists(p):
                os.remove(p)
    manifest[script] = sorted(pngs)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as fh:
        json.dump(manifest, fh, indent=2, sort_keys=True)
        fh.write("\n")
    os.replace(tmp, path)  # atomic: a reader never sees half a manifest


def default_out(run_dir: str, out: str | None) -> str:
    return out if out else os.path.join(run_dir, "figures")
