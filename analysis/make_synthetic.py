#!/usr/bin/env python3
"""Write a small, synthetic sweep output folder with the engine's schema.

    python3 analysis/make_synthetic.py out/synthetic

The values are *plausible*, not computed: the exact solution is the classic
1D bar that leaves its initial position, hits a rigid obstacle, stays in
contact for two wave transits and releases; the "numerical" series are the
exact ones plus h-dependent defects of the kind each method shows
(oscillating contact pressure, energy loss of dissipative schemes, ...), and
the error columns follow C*h^p. This lets the plotting scripts be developed
and tested without running the engine.

On purpose the folder also contains the awkward cases the scripts must
survive: one file per run with *different* column sets (method-specific
columns missing or all-null), a diverged and a solver-failed run, a second
sweep without reference solution (error and exact columns absent/null), and
temporary "."-files that must be ignored.
"""

from __future__ import annotations

import argparse
import math
import os

import numpy as np
import polars as pl

LENGTH, YOUNG, DENSITY, AMPLITUDE, GAP = 1.0, 1.0, 1.0, 0.1, 0.0
WAVE_SPEED = math.sqrt(YOUNG / DENSITY)
TAU = LENGTH / WAVE_SPEED  # one wave transit through the bar
T_FINAL = 4.0 * TAU  # one full contact period
E_EXACT = YOUNG * AMPLITUDE**2 / (2.0 * LENGTH)
SIGMA_CONTACT = -YOUNG * AMPLITUDE / LENGTH

# Method descriptions: parameters, the defects shown in the series, and the
# (constant, order) of each error norm. Orders follow what low-regularity
# contact problems typically give (O(h) in L2, O(h^1/2) in H1 / pressure).
METHODS = [
    dict(
        label="mixed consistent crank-nicolson",
        params=dict(space="mixed", mass="consistent", scheme="newmark", scheme_label="crank-nicolson",
                    newmark_beta=0.25, newmark_gamma=0.5),
        courant=1.0, cost=1.0, energy="oscillate", sigma_noise=0.8,
        errors=dict(err_u_l2l2=(0.30, 1.0), err_u_l2h1=(0.9, 0.5), err_u_linfl2=(0.40, 1.0),
                    err_sigma_l2=(1.1, 0.5), err_energy_l2=(0.05, 1.0), err_u_contact_max=(0.2, 1.0)),
    ),
    dict(
        label="nitsche(Θ=1, γ0=1e-06) consistent hybrid",
        params=dict(space="nitsche", mass="consistent", scheme="hybrid", scheme_label="hybrid",
                    nitsche_theta=1.0, nitsche_gamma0=1e-6),
        courant=1.0, cost=2.2, energy="conserve", sigma_noise=0.3,
        errors=dict(err_u_l2l2=(0.12, 1.5), err_u_l2h1=(0.5, 0.75), err_u_linfl2=(0.15, 1.4),
                    err_sigma_l2=(0.6, 0.7), err_energy_l2=(0.01, 1.6), err_u_contact_max=(0.1, 1.3)),
    ),
    dict(
        label="penalty(γ0=10) lumped backward-euler",
        params=dict(space="penalty", mass="lumped", scheme="theta", scheme_label="backward-euler",
                    theta_scheme=1.0, penalty_gamma0=10.0),
        courant=0.5, cost=0.6, energy="dissipate", sigma_noise=0.2,
        errors=dict(err_u_l2l2=(0.6, 0.9), err_u_l2h1=(1.5, 0.45), err_u_linfl2=(0.8, 0.9),
                    err_sigma_l2=(1.4, 0.4), err_energy_l2=(0.4, 0.95), err_u_contact_max=(0.5, 0.9)),
    ),
    dict(
        label="mixed mod1 paoli-schatzman(e=0)",
        params=dict(space="mixed", mass="mod1", scheme="paoli-schatzman", scheme_label="paoli-schatzman",
                    restitution=0.0),
        courant=1.0, cost=1.3, energy="impact-loss", sigma_noise=0.5,
        errors=dict(err_u_l2l2=(0.25, 1.1), err_u_l2h1=(0.8, 0.55), err_u_linfl2=(0.3, 1.0),
                    err_sigma_l2=(0.9, 0.55), err_energy_l2=(0.08, 1.0), err_u_contact_max=(0.15, 1.0)),
    ),
]
LEVELS = [10, 20, 40, 80]


def exact_contact(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contact displacement and pressure of the reference bar problem."""
    phase = np.mod(t, 4.0 * TAU)
    u = np.where(phase < TAU, AMPLITUDE * (1.0 - phase / TAU),
                 np.where(phase < 3.0 * TAU, 0.0, AMPLITUDE * (phase - 3.0 * TAU) / TAU))
    in_contact = (phase >= TAU) & (phase < 3.0 * TAU)
    sigma = np.where(in_contact, SIGMA_CONTACT, 0.0)
    return u, sigma


def synth_series(method: dict, h: float, dt: float, steps: int, rng, with_exact: bool) -> dict:
    t = np.arange(steps + 1) * dt
    u_ex, s_ex = exact_contact(t)
    phase = np.mod(t, 4.0 * TAU)
    contact = ((phase >= TAU) & (phase < 3.0 * TAU)).astype(float)
    # Displacement: a small lag plus an O(h) wiggle while in contact.
    u_lag, _ = exact_contact(np.maximum(t - 0.3 * h, 0.0))
    u = u_lag + 0.2 * AMPLITUDE * h * np.sin(math.pi * t / h) * contact
    if method["params"]["space"] == "penalty":
        u = u + SIGMA_CONTACT / (method["params"]["penalty_gamma0"] * YOUNG / h) * contact  # penetration
    # Pressure: the well-known spurious oscillations, amplitude ~ sqrt(h).
    sigma = s_ex * (1.0 + method["sigma_noise"] * math.sqrt(h) * np.cos(math.pi * t / (2 * h))) * contact
    sigma = sigma + 0.01 * SIGMA_CONTACT * rng.standard_normal(t.size) * contact
    # Energy: the discrete initial energy is not the exact one (interpolated data).
    e0 = E_EXACT * (1.0 - 0.5 * h**2)
    kind = method["energy"]
    if kind == "oscillate":
        energy = e0 * (1.0 + 0.2 * h * np.sin(math.pi * t / (4 * h)) ** 2 * contact)
    elif kind == "conserve":
        energy = e0 * (1.0 - 1e-3 * h * contact)
    elif kind == "dissipate":
        energy = e0 * np.exp(-0.6 * h * t / TAU)
    else:  # impact-loss: restitution 0 loses the energy of the impacting layer
        energy = e0 * (1.0 - 2.0 * h * (t >= TAU))
    energy[0] = e0
    out = dict(
        step=np.arange(steps + 1, dtype=np.int64), t=t, u_contact=u,
        v_contact=np.gradient(u, dt), sigma_contact=sigma, energy=energy,
    )
    if kind == "dissipate":
        # A frictional run's W_f^n (contract §2.5): here friction takes 90 % of what is lost, so
        # E + W_f falls by a tenth of the loss (plot_energy_impacts.py --balance draws it).
        out["friction_work"] = 0.9 * (e0 - energy)
    if method["params"]["space"] == "nitsche":
        # The Nitsche-modified energy that the analysis proves non-increasing.
        out["energy_theta"] = energy - 0.5 * h * sigma**2 / YOUNG * 1e-2
    if with_exact:
        out["u_contact_exact"] = u_ex
        out["sigma_contact_exact"] = s_ex
    return out


def run_row(run_id, sweep, scene, method, elements, courant, steps, dofs, series, errors,
            status="ok", message=None, wall=None):
    h = LENGTH / elements
    dt = courant * h / WAVE_SPEED
    row = dict(
        run_id=run_id, sweep=sweep, scene=scene, label=method["label"], status=status, message=message,
        T=T_FINAL, h=h, dt=dt, courant=courant, elements=elements,
        length=LENGTH, young=YOUNG, density=DENSITY, amplitude=AMPLITUDE, gap=GAP,
        **method["params"],
        wall_time_s=wall if wall is not None else method["cost"] * steps * dofs * 2e-6,
        steps=steps, dofs=dofs, iterations=steps * (3 if method["params"]["scheme"] == "hybrid" else 1),
        mass_total=DENSITY * LENGTH,
    )
    if series is not None:
        e = series["energy"]
        row.update(
            energy_initial=float(e[0]), energy_final=float(e[-1]), energy_drift=float(e[-1] - e[0]),
            energy_max_dev=float(np.max(np.abs(e - e[0]))),
            energy_max_increase=float(max(0.0, np.max(np.diff(e)))),
        )
        if "energy_theta" in series:
            row["energy_theta_max_increase"] = float(max(0.0, np.max(np.diff(series["energy_theta"]))))
    row.update(errors)
    return row


def write(out_dir: str, rows: list[dict], series: dict[str, dict]) -> None:
    runs_dir, series_dir = os.path.join(out_dir, "runs"), os.path.join(out_dir, "series")
    os.makedirs(runs_dir, exist_ok=True)
    os.makedirs(series_dir, exist_ok=True)
    for row in rows:
        # One file per run, each with only the columns that run has: the
        # readers must cope with differing column sets, like a real engine
        # that writes method-specific columns only where they apply.
        pl.DataFrame([row]).write_parquet(os.path.join(runs_dir, f"{row['run_id']}.parquet"))
    for run_id, data in series.items():
        df = pl.DataFrame({"run_id": [run_id] * len(data["t"]), **data})
        df.write_parquet(os.path.join(series_dir, f"{run_id}.parquet"))
    # Temporary files of an engine still writing: must be ignored, and they
    # are not even valid parquet.
    for d in (runs_dir, series_dir):
        with open(os.path.join(d, ".inflight-000.parquet"), "wb") as fh:
            fh.write(b"PAR1 half written")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir", help="output folder (created; existing runs/ and series/ files are overwritten)")
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)

    rows: list[dict] = []
    series: dict[str, dict] = {}
    n = 0

    # Sweep 1: refinement study of four methods, with a reference solution.
    for method in METHODS:
        for elements in LEVELS:
            n += 1
            run_id = f"refine-{n:03d}"
            h = LENGTH / elements
            dt = method["courant"] * h / WAVE_SPEED
            steps = int(round(T_FINAL / dt))
            dofs = elements + (2 if method["params"]["space"] == "mixed" else 1)
            s = synth_series(method, h, dt, steps, rng, with_exact=True)
            errors = {
                col: c * h**p * math.exp(0.05 * rng.standard_normal())
                for col, (c, p) in method["errors"].items()
            }
            rows.append(run_row(run_id, "refine", "bar1d", method, elements, method["courant"],
                                steps, dofs, s, errors))
            series[run_id] = s

    # A diverged run (its series stops early and blows up) and a solver
    # failure without any series: both must be left out of the plots.
    bad = dict(label="nitsche(Θ=-1, γ0=1e-06) lumped newmark(β=0,γ=0.5)",
               params=dict(space="nitsche", mass="lumped", scheme="newmark", scheme_label="newmark(β=0,γ=0.5)",
                           nitsche_theta=-1.0, nitsche_gamma0=1e-6, newmark_beta=0.0, newmark_gamma=0.5),
               courant=1.5, cost=0.5, energy="oscillate", sigma_noise=1.0, errors={})
    n += 1
    h = LENGTH / 40
    s = synth_series(bad, h, 1.5 * h, 17, rng, with_exact=True)
    s["energy"] = s["energy"] * np.exp(np.arange(18))  # blow-up
    rows.append(run_row(f"refine-{n:03d}", "refine", "bar1d", bad, 40, 1.5, 17, 41, s, {},
                        status="diverged", message="energy grew by 1e7 at step 17"))
    series[f"refine-{n:03d}"] = s
    n += 1
    stiff = dict(METHODS[2], params=dict(METHODS[2]["params"], penalty_gamma0=1e12),
                 label="penalty(γ0=1e+12) lumped backward-euler")
    rows.append(run_row(f"refine-{n:03d}", "refine", "bar1d", stiff, 80, 0.5, 0, 81, None, {},
                        status="solver-failed", message="Newton did not converge in 50 iterations",
                        wall=0.01))

    # Sweep 2: a time-step study of a scene without closed-form solution:
    # no error columns and no exact series at all, a single mesh.
    for i, courant in enumerate([0.25, 0.5, 1.0]):
        method = METHODS[0]
        run_id = f"dtstudy-{i + 1:03d}"
        elements = 40
        h = LENGTH / elements
        dt = courant * h / WAVE_SPEED
        steps = int(round(T_FINAL / dt))
        s = synth_series(method, h, dt, steps, rng, with_exact=False)
        rows.append(run_row(run_id, "dt-study", "impact2d", method, elements, courant, steps,
                            elements + 2, s, {}))
        series[run_id] = s

    write(args.dir, rows, series)
    print(f"wrote {len(rows)} runs and {len(series)} series to {args.dir}")


if __name__ == "__main__":
    main()
