"""Read a results folder with every reader contract §8 promises, as a user would (issue 23).

    python3 analysis/readers_check.py check DIR --runs N
        one read with each reader; exits 1 unless every reader sees exactly N runs, each once
        (`--same-types`: and every part's columns read with the same types in polars and pandas).
    python3 analysis/readers_check.py watch DIR --stop FILE
        reads the folder again and again while a sweep writes it, until FILE exists, then once
        more; exits 1 on any reader error or on a read that saw a run twice.

Both print one JSON line: reads made, errors (reader: message), the runs seen by the last read.

The readers, with the calls docs/guide.md prints: polars' glob `DIR/runs/*.parquet` (which
expands to dot-files too: a temporary or damaged part beside the parts breaks it) and a
filtered lazy scan of one run's series; pandas' `read_parquet(DIR/runs)`; pyarrow's dataset of
the folder; DuckDB's `read_parquet('DIR/runs/*.parquet')`.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time


def read_all(d: str) -> dict:
    """One read by every reader; returns {reader: (rows, distinct run ids)}; raises on error."""
    import duckdb
    import pandas as pd
    import polars as pl
    import pyarrow.dataset as ds

    out = {}
    runs = pl.read_parquet(f"{d}/runs/*.parquet")
    out["polars runs"] = (runs.height, runs["run_id"].n_unique())
    series = pl.read_parquet(f"{d}/series/*.parquet", columns=["run_id", "step", "t"])
    out["polars series"] = (series.height, series["run_id"].n_unique())
    if runs.height:
        one = runs["run_id"][0]
        s = pl.scan_parquet(f"{d}/series/*.parquet").filter(pl.col("run_id") == one).collect()
        out["polars scan one run"] = (s.height, s["run_id"].n_unique())
    pdf = pd.read_parquet(f"{d}/runs")
    out["pandas runs"] = (len(pdf), pdf["run_id"].nunique())
    t = ds.dataset(f"{d}/runs", format="parquet").to_table(columns=["run_id"])
    out["pyarrow dataset runs"] = (t.num_rows, len(set(t.column("run_id").to_pylist())))
    n, k = duckdb.sql(
        f"SELECT count(*), count(DISTINCT run_id) FROM read_parquet('{d}/runs/*.parquet')"
    ).fetchall()[0]
    out["duckdb runs"] = (n, k)
    n, k = duckdb.sql(
        f"SELECT count(*), count(DISTINCT run_id) FROM read_parquet('{d}/series/*.parquet')"
    ).fetchall()[0]
    out["duckdb series"] = (n, k)
    return out


def type_differences(d: str) -> list[str]:
    """Columns whose type differs between two parts of a folder, as polars and pandas read
    each part on its own (a folder written by an older version and resumed by this one)."""
    import glob

    import pandas as pd
    import polars as pl

    bad = []
    for sub in ["runs", "series"]:
        parts = sorted(glob.glob(f"{d}/{sub}/*.parquet"))
        first_pl = dict(pl.read_parquet_schema(parts[0]))
        first_pd = pd.read_parquet(parts[0]).dtypes.to_dict()
        for p in parts[1:]:
            for name, t in pl.read_parquet_schema(p).items():
                if name in first_pl and first_pl[name] != t:
                    bad.append(f"polars {sub}.{name}: {first_pl[name]} vs {t} ({p})")
            schema = pl.read_parquet_schema(p)
            for name, t in pd.read_parquet(p).dtypes.items():
                # pandas reads an integer column holding nulls (one an older version left
                # empty, e.g. bar1d's contact_phases before issue 34) as float64 and the same
                # column without nulls as int64: its null promotion, not a difference of the
                # parts' types, which the polars check above compares (equal here).
                promoted = {str(first_pd.get(name)), str(t)} == {"int64", "float64"}
                if promoted and first_pl.get(name) == schema.get(name):
                    continue
                if name in first_pd and first_pd[name] != t:
                    bad.append(f"pandas {sub}.{name}: {first_pd[name]} vs {t} ({p})")
    return bad


def problems(seen: dict, runs: int | None) -> list[str]:
    """What is wrong with one read: a run twice, or (check) not the runs expected."""
    bad = []
    for reader, (rows, distinct) in seen.items():
        if "runs" in reader and rows != distinct:
            bad.append(f"{reader}: {rows} rows for {distinct} distinct runs")
        if runs is not None and reader.endswith(" runs") and rows != runs:
            bad.append(f"{reader}: {rows} runs, expected {runs}")
    counts = {r: seen[r][0] for r in seen if r.endswith(" runs")}
    if len(set(counts.values())) > 1 and runs is not None:
        bad.append(f"readers disagree: {counts}")
    return bad


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["check", "watch"])
    p.add_argument("dir")
    p.add_argument("--runs", type=int)
    p.add_argument("--stop")
    p.add_argument(
        "--same-types", action="store_true", help="check: every part's columns read alike"
    )
    a = p.parse_args()
    errors: list[str] = []
    reads = 0
    last: dict = {}

    def once(expect: int | None) -> None:
        nonlocal reads, last
        parts = os.path.join(a.dir, "runs")
        if expect is None and not any(
            n.endswith(".parquet") and not n.startswith(".")
            for n in (os.listdir(parts) if os.path.isdir(parts) else [])
        ):
            time.sleep(0.05)  # nothing committed yet: a glob matching no file is no finding
            return
        try:
            last = read_all(a.dir)
        except Exception as e:  # every reader's failure is a finding, reported by name
            errors.append(f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
            return
        reads += 1
        errors.extend(problems(last, expect))

    if a.mode == "check":
        once(a.runs)
        if a.same_types:
            errors.extend(type_differences(a.dir))
    else:
        deadline = time.time() + 600
        while not os.path.exists(a.stop) and time.time() < deadline:
            once(None)
        once(a.runs)
    print(json.dumps({"reads": reads, "errors": errors, "last": last}))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
