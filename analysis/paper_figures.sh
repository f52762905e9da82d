#!/usr/bin/env bash
# Run every sweep of the papers (sweeps/000_*.toml, sweeps/003_*.toml) and draw their figures:
# time series (displacement, pressure, energy with the exact solution), convergence with slope
# triangles, work-precision with the Pareto front, stability maps, and the energy of the disc and
# ball impacts (003 Figs 11, 12). Then check that no figure is blank.
#
#   bash analysis/paper_figures.sh [OUT]      (default OUT = out)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(dirname "$here")"
out="${1:-out}"
py="${PYTHON:-python3}"
bin="${CONTACT_SWEEP:-$repo/target/release/contact-sweep}"
[ -x "$bin" ] || (cd "$repo" && cargo build --release --quiet)
for sweep in "$repo"/sweeps/000_*.toml "$repo"/sweeps/003_*.toml; do
  name=$(sed -n 's/^name *= *"\(.*\)".*/\1/p' "$sweep" | head -n1)
  dir="$out/$name"
  "$bin" run "$sweep" --out "$dir" >/dev/null
  "$py" "$here/plot_series.py" "$dir" --out "$out/figures" --include-failed
  "$py" "$here/plot_convergence.py" "$dir" --out "$out/figures"
  "$py" "$here/plot_work_precision.py" "$dir" --out "$out/figures"
  "$py" "$here/plot_stability_map.py" "$dir" --out "$out/figures"
  # 003 Figs 11, 12: energy against time of the four impact methods (disc, ball).
  case "$(basename "$sweep")" in
    003_fig11_*|003_fig12_*) "$py" "$here/plot_energy_impacts.py" "$dir" --out "$out/figures" ;;
  esac
done
"$py" "$here/check_figures.py" "$out/figures"
