#!/usr/bin/env python3
"""Build docs/methods.md's method table from sweep outputs.

For every method of the 1D bar (contact treatment · mass · scheme) it prints what the papers
report and what contact-sweep measures: E(T)/E0 at the 003 setting (h = 0.01, τ = 0.015,
T = 12) and the l2(τ;H1) error on the h = τ ladder with its least-squares rate.

    python3 analysis/method_table.py out/003-fig2 out/003-fig3 out/003-fig9 out/003-figs4-8 \
        --ladder out/003-fig10

Paper statements are quoted from 003 §4.1.2 and contract §6; nothing here is tuned to them.
"""
import argparse
import math
import sys
from pathlib import Path

import polars as pl

# What the papers say, keyed by the engine's label (003 §4.1.2a–e, contract §6).
PAPER = {
    "nitsche(Θ=1, γ0=1e-6) · consistent · backward-euler": "≈ 20 % of E0 left (strongly damped)",
    "nitsche(Θ=1, γ0=1e-6) · consistent · newmark-dissipative": "≈ 40 % of E0 left",
    "nitsche(Θ=1, γ0=1e-6) · consistent · newmark(β=0.5,γ=0.5)": "energy practically conserved",
    "nitsche(Θ=1, γ0=1e-6) · consistent · crank-nicolson": "energy increases strongly; no H1 convergence",
    "mixed · consistent · crank-nicolson": "energy increases strongly; no H1 convergence",
    "nitsche(Θ=1, γ0=1e-6) · consistent · hybrid": "≈ −1 %; converges (slowly) in H1",
    "mixed · zero-contact · crank-nicolson": "1–2 % dissipation; converges in H1",
    "nitsche(Θ=1, γ0=1e-6) · zero-contact · crank-nicolson": "1–2 % dissipation",
    # contact_init = interpolant (contract §2.2): the start 003's Fig 9 appears to use
    "mixed · zero-contact (interpolant start) · crank-nicolson": "1–2 % dissipation (reproduced by this start)",
    "nitsche(Θ=1, γ0=1e-6) · zero-contact (interpolant start) · crank-nicolson": "1–2 % dissipation (reproduced by this start)",
    "mixed · mod3 · crank-nicolson": "best of the redistributions (000)",
    "nitsche(Θ=1, γ0=1e-1) · consistent · crank-nicolson": "+2 to 4 %",
    "nitsche(Θ=-1, γ0=1e-1) · consistent · crank-nicolson": "≈ +30 % (not reproduced, contract §6)",
    "nitsche(Θ=0, γ0=1e-1) · consistent · crank-nicolson": "+2 to 4 %",
    "nitsche(Θ=1, γ0=1e0) · consistent · crank-nicolson": "unphysical, E^h very large",
    "nitsche(Θ=1, γ0=3e0) · consistent · crank-nicolson": "Newton fails (γ0 > 1)",
}


def read_runs(d: Path) -> pl.DataFrame:
    files = sorted(p for p in (d / "runs").glob("*.parquet") if not p.name.startswith("."))
    if not files:
        sys.exit(f"{d}: no runs/*.parquet")
    return pl.concat([pl.read_parquet(f) for f in files], how="diagonal_relaxed")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+", type=Path, help="outputs at h = 0.01, τ = 0.015")
    ap.add_argument("--ladder", type=Path, required=True, help="output of sweeps/003_fig10_ladder.toml")
    a = ap.parse_args()
    fixed = pl.concat([read_runs(d) for d in a.dirs], how="diagonal_relaxed")
    fixed = fixed.filter((pl.col("h") == 0.01) & (pl.col("dt") == 0.015) & pl.col("ensemble_sample").fill_null(0).eq(0))
    ladder = read_runs(a.ladder).filter(pl.col("status") == "ok")
    rows = []
    for label in sorted(set(fixed["label"].to_list()) | set(ladder["label"].to_list())):
        f = fixed.filter(pl.col("label") == label)
        if f.height:
            r = f.row(0, named=True)
            if r["status"] == "ok":
                drift = f"{r['energy_final'] / r['energy_initial']:.4f}"
            else:
                drift = r["status"]
        else:
            drift = "—"
        lad = ladder.filter(pl.col("label") == label).sort("h", descending=True)
        if lad.height >= 2:
            hs, es = lad["h"].to_list(), lad["err_u_l2h1"].to_list()
            n = len(hs)
            x = [math.log(h) for h in hs]
            y = [math.log(e) for e in es]
            mx, my = sum(x) / n, sum(y) / n
            slope = sum((xi - mx) * (yi - my) for xi, yi in zip(x, y)) / sum((xi - mx) ** 2 for xi in x)
            errs = " → ".join(f"{e:.3g}" for e in es)
            conv = f"{errs} (rate {slope:.2f})"
        else:
            conv = "—"
        if label not in PAPER and conv == "—":
            continue  # a parameter study point the papers do not single out
        if label.endswith("consistent · crank-nicolson") and ("γ0=1e-6" in label or label.startswith("mixed")):
            drift += " (ill-posed: round-off moves it in ≈ 1.07–3.9)"
        rows.append((label, PAPER.get(label, ""), drift, conv))
    print("| method · mass · scheme | papers report | E(T)/E⁰ at h = 0.01, τ = 0.015 | l2(τ;H1) on h = τ = 1/4 … 1/4096 (LSQ rate) |")
    print("|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
