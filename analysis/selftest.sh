#!/usr/bin/env bash
# Self-test of the analysis scripts on synthetic data (no engine needed):
# writes a synthetic sweep folder, draws every figure, checks them.
# The last line is check_figures.py's "N passed, M failed".
#
#   bash analysis/selftest.sh [WORKDIR]     (default: a fresh temporary folder)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
work="${1:-$(mktemp -d)}"
py="${PYTHON:-python3}"

"$py" "$here/make_synthetic.py" "$work/synthetic"
"$py" "$here/plot_series.py" "$work/synthetic" --out "$work/figures"
"$py" "$here/plot_convergence.py" "$work/synthetic" --out "$work/figures"
"$py" "$here/plot_work_precision.py" "$work/synthetic" --out "$work/figures"
"$py" "$here/plot_work_precision.py" "$work/synthetic" --out "$work/figures" --error err_sigma_l2
"$py" "$here/plot_energy_impacts.py" "$work/synthetic" --out "$work/figures"
# E + W_f of the frictional synthetic runs, one sweep (--only), in a folder of its own (a
# second call into figures/ would replace the first one's manifest entry).
"$py" "$here/plot_energy_impacts.py" "$work/synthetic" --out "$work/figures_balance" --balance --only sweep=refine
"$py" "$here/check_figures.py" "$work/figures_balance"
"$py" "$here/check_figures.py" "$work/figures"
