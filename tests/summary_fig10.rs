//! 003 §4.1.2e, Fig 10 through the whole pipeline: `sweeps/003_fig10_ladder.toml` (h = τ,
//! ν = 1, h = 1/4 … 1/4096) → Parquet → `summarize` → `summary/convergence.parquet`, and the
//! paper's conclusion read off the summary table.
//!
//! contract §6: mixed+CN and Nitsche+CN do not converge in l2(τ;H1); Nitsche-Hybrid and the
//! modified masses do, with rates ≈ 0.3 in l2(τ;H1) and ≈ 0.7–0.9 in l2(τ;L2). The LSQ slope
//! over six levels includes the pre-asymptotic coarse ones, hence bands of ±0.1 around those
//! figures.

mod common;

use std::path::Path;

use common::cli;
use polars::prelude::*;

/// (slope over all levels, slope over the finest three, stagnating flag) of a method and error.
fn fit(df: &DataFrame, label: &str, error: &str) -> (f64, f64, bool) {
    let rows = df
        .clone()
        .lazy()
        .filter(col("label").eq(lit(label)).and(col("error").eq(lit(error))))
        .select([col("slope_all"), col("slope_finest3"), col("stagnating")])
        .collect()
        .unwrap();
    assert!(rows.height() > 0, "no rows for {label} / {error}");
    let a = rows
        .column("slope_all")
        .unwrap()
        .f64()
        .unwrap()
        .get(0)
        .unwrap();
    let f = rows
        .column("slope_finest3")
        .unwrap()
        .f64()
        .unwrap()
        .get(0)
        .unwrap();
    let s = rows
        .column("stagnating")
        .unwrap()
        .bool()
        .unwrap()
        .get(0)
        .unwrap();
    (a, f, s)
}

#[test]
fn fig10_ladder_summary_reproduces_the_papers_conclusion() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("fig10");
    let o = cli(
        repo,
        &[
            "run",
            "sweeps/003_fig10_ladder.toml",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let file = std::fs::File::open(out.join("summary/convergence.parquet")).unwrap();
    let df = ParquetReader::new(file).finish().unwrap();

    for label in [
        "mixed · consistent · crank-nicolson",
        "nitsche(Θ=1, γ0=1e-6) · consistent · crank-nicolson",
    ] {
        let (all, _, stagnating) = fit(&df, label, "err_u_l2h1");
        assert!(
            all < 0.0 && stagnating,
            "{label}: H1 slope {all}, stagnating {stagnating}"
        );
        // the energy error grows as the mesh is refined (the energy blows up, 003 Fig 10)
        let (e, _, _) = fit(&df, label, "err_energy_l2");
        assert!(e < 0.0, "{label}: energy slope {e}");
    }
    for label in [
        "nitsche(Θ=1, γ0=1e-6) · consistent · hybrid",
        "mixed · mod3 · crank-nicolson",
        "mixed · zero-contact · crank-nicolson",
    ] {
        let (h1, h1_fine, stagnating) = fit(&df, label, "err_u_l2h1");
        assert!(!stagnating, "{label}");
        assert!(
            (0.2..=0.45).contains(&h1) && (0.2..=0.4).contains(&h1_fine),
            "{label}: H1 slopes {h1}, {h1_fine}"
        );
        let (l2, _, _) = fit(&df, label, "err_u_l2l2");
        assert!((0.6..=1.0).contains(&l2), "{label}: L2 slope {l2}");
        // energy: almost conserved, better as h, τ shrink — the error converges at order ≈ 1
        let (e, _, _) = fit(&df, label, "err_energy_l2");
        assert!((0.85..=1.15).contains(&e), "{label}: energy slope {e}");
    }
    // Contact pressure at midpoint: the modified masses converge (≈ 0.3); mixed/Nitsche + CN
    // stagnate. Nitsche-Hybrid decreases, slowly (measured LSQ slope 0.11; the paper says it
    // converges, slower than the modified mass — docs/methods.md reports the figures).
    for label in [
        "mixed · mod3 · crank-nicolson",
        "mixed · zero-contact · crank-nicolson",
    ] {
        let (s, _, _) = fit(&df, label, "err_sigma_mid_l2");
        assert!((0.2..=0.45).contains(&s), "{label}: σ slope {s}");
    }
    let (s, _, _) = fit(
        &df,
        "mixed · consistent · crank-nicolson",
        "err_sigma_mid_l2",
    );
    assert!(s.abs() < 0.1, "mixed+CN σ slope {s}");
    let (s, _, _) = fit(
        &df,
        "nitsche(Θ=1, γ0=1e-6) · consistent · hybrid",
        "err_sigma_mid_l2",
    );
    assert!(s > 0.0 && s < 0.2, "Nitsche-Hybrid σ slope {s}");
}
