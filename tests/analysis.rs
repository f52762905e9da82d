//! The analysis/ scripts on a real sweep: every figure is drawn and none is blank.
//!
//! Needs python3 with analysis/requirements.txt installed (the README's test command installs
//! it); a missing interpreter or package fails the test with that instruction.

mod common;

use std::path::Path;
use std::process::Command;

use common::cli;

#[test]
fn analysis_scripts_draw_every_figure_of_a_small_sweep() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("qs");
    let o = cli(
        repo,
        &[
            "run",
            "sweeps/quickstart.toml",
            "--out",
            out.to_str().unwrap(),
            "--no-summary",
        ],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The stability maps are drawn from the summary's table.
    let o = cli(repo, &["summarize", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let figs = out.join("figures");
    for script in [
        "plot_series.py",
        "plot_convergence.py",
        "plot_work_precision.py",
        "plot_stability_map.py",
    ] {
        let o = Command::new("python3")
            .arg(repo.join("analysis").join(script))
            .arg(&out)
            .arg("--out")
            .arg(&figs)
            .output()
            .expect("python3 runs (pip install -r analysis/requirements.txt)");
        assert!(
            o.status.success(),
            "{script} failed — is analysis/requirements.txt installed?\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = Command::new("python3")
        .arg(repo.join("analysis/check_figures.py"))
        .arg(&figs)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // series (12 parts for 60 runs), convergence, work-precision
    let last = stdout.lines().last().unwrap_or("");
    let passed: usize = last
        .split_whitespace()
        .next()
        .unwrap_or("0")
        .parse()
        .unwrap_or(0);
    assert!(passed >= 3 && last.ends_with("0 failed"), "{last}");
    for f in [
        "convergence_quickstart.png",
        "convergence_quickstart.pdf",
        "work_precision_quickstart_err_u_l2h1.png",
        "stability_map_qs_mixed_mod3_crank-nicolson.png",
    ] {
        assert!(figs.join(f).exists(), "{f} missing");
    }
}
