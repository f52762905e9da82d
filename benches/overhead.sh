#!/bin/sh
# Whole-command overhead of a sweep (issue 12): the 400-run 1D sweep of
# benches/sweeps/overhead_1d.toml run with --threads 1 and --threads 2, with and without the
# summary, interleaved round by round so that every configuration sees the same machine load;
# reports medians of the wall time, of the runs' own summed time (from the command's
# end-of-sweep `time:` line) and their ratios.
#
#   cargo build --release && sh benches/overhead.sh [ROUNDS]      (default 5 rounds)
#
# Needs only sh, awk, sort and date. Each command starts from an empty output folder (a
# folder holding the sweep would be resumed, i.e. skipped).
set -eu
ROUNDS=${1:-5}
BIN=${BIN:-target/release/contact-sweep}
SWEEP=${SWEEP:-benches/sweeps/overhead_1d.toml}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/overhead.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
CONFIGS="t1:--threads=1 t1-nosum:--threads=1,--no-summary t2:--threads=2 t2-nosum:--threads=2,--no-summary t1-noseries:--threads=1,--no-summary,--series-every=0 t2-noseries:--threads=2,--no-summary,--series-every=0"
for round in $(seq "$ROUNDS"); do
  for c in $CONFIGS; do
    name=${c%%:*}
    args=$(echo "${c#*:}" | tr ',' ' ')
    rm -rf "$WORK/out"
    t0=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$BIN" run "$SWEEP" --out "$WORK/out" $args >/dev/null 2>"$WORK/err"
    t1=$(date +%s.%N)
    runs=$(sed -n 's/^time: runs \([0-9.]*\) s.*/\1/p' "$WORK/err")
    bps=$(sed -n 's/.* \([0-9.]*\) bytes\/step.*/\1/p' "$WORK/err")
    # The output's CPU: the workers' encoding and the committer thread (issue 35).
    enc=$(sed -n 's/.* encoding \([0-9.]*\) s CPU.*/\1/p' "$WORK/err")
    com=$(sed -n 's/.* committer \([0-9.]*\) s CPU.*/\1/p' "$WORK/err")
    echo "$name $(echo "$t1 - $t0" | awk '{printf "%.3f", $1 - $3}') $runs ${bps:--} ${enc:-0} ${com:-0}" >>"$WORK/times"
  done
  echo "round $round/$ROUNDS done" >&2
done
# Medians per configuration, then the ratios the issue's targets are stated in.
awk '
function median(list,   n, a, i, j, t) {
  n = split(list, a, " ")
  for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j-1] + 0 > a[j] + 0; j--) { t = a[j]; a[j] = a[j-1]; a[j-1] = t }
  return n % 2 ? a[(n+1)/2] : (a[n/2] + a[n/2+1]) / 2
}
{ wall[$1] = wall[$1] " " $2; runs[$1] = runs[$1] " " $3; bps[$1] = $4; enc[$1] = enc[$1] " " $5; com[$1] = com[$1] " " $6; order[$1] = order[$1] ? order[$1] : ++k; name[k] = $1 }
END {
  printf "%-12s %10s %12s %14s %14s\n", "config", "wall (s)", "runs Σ (s)", "wall − Σ/N", "series B/step"
  for (i = 1; i <= k; i++) {
    c = name[i]; w[c] = median(wall[c]); r[c] = median(runs[c])
    n = (c ~ /^t2/) ? 2 : 1   # N threads share the runs Σ
    printf "%-12s %10.3f %12.3f %13.1f%% %14s\n", c, w[c], r[c], 100 * (w[c] - r[c] / n) / (r[c] / n), bps[c]
  }
  printf "\noverhead, threads 1, series kept, no summary: %.1f %% of the runs Σ\n", 100 * (w["t1-nosum"] - r["t1-nosum"]) / r["t1-nosum"]
  printf "summary cost, threads 1: %.1f %% of the runs Σ\n", 100 * (w["t1"] - w["t1-nosum"]) / r["t1-nosum"]
  printf "speed-up threads 2 / threads 1: %.2fx without summary, %.2fx with, %.2fx without series and summary\n", w["t1-nosum"] / w["t2-nosum"], w["t1"] / w["t2"], w["t1-noseries"] / w["t2-noseries"]
  printf "runs Σ threads 2 / threads 1 (per-run slow-down when both cores work): %.2f\n", r["t2-nosum"] / r["t1-nosum"]
  # On 2 cores the output takes its CPU from the two workers: the encoding runs on them (inline
  # in the 1-thread run loop), the committer on its own thread. What is neither a run nor
  # encoding (planning, the summary) is serial: the best whole-command time with 2 threads is
  # (runs Σ + encoding + committer)/2 + serial, the serial part read off the threads-1 command.
  e = median(enc["t1"]); c = median(com["t1"]); serial = w["t1"] - r["t1"] - e
  printf "output CPU (threads 1, medians): encoding %.3f s = %.1f %% of the runs Σ, committer %.3f s = 1/%.0f of it\n", e, 100 * e / r["t1"], c, r["t1"] / c
  printf "best speed-up 2 cores can give, whole command: %.2fx (= %.3f / ((%.3f + %.3f + %.3f)/2 + %.3f))\n", w["t1"] / ((r["t1"] + e + c) / 2 + serial), w["t1"], r["t1"], e, c, serial
}' "$WORK/times"
