#!/bin/sh
# This build's sink against another build's (issue 23), side by side in one run: the 400-run
# 1D sweep of benches/sweeps/overhead_1d.toml, series kept, no summary, with --threads 1 and
# --threads 2, the two binaries alternating round by round (A B A B …) so both see the same
# machine load. Prints medians of the whole command's wall time, the runs' own summed time,
# the writer thread's CPU and the series bytes per stored step, then the ratios the issue's
# targets are stated in.
#
#   git worktree add /tmp/before 25b7f8c        # the sink before issue 23
#   cargo build --release --manifest-path /tmp/before/Cargo.toml --target-dir /tmp/before/target
#   cargo build --release
#   BIN_B=/tmp/before/target/release/contact-sweep sh benches/sink_ab.sh 5
#
# Needs only sh, awk, sed and date.
set -eu
ROUNDS=${1:-5}
BIN_A=${BIN_A:-target/release/contact-sweep}
BIN_B=${BIN_B:?set BIN_B to the binary to compare against}
SWEEP=${SWEEP:-benches/sweeps/overhead_1d.toml}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/sink_ab.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
for round in $(seq "$ROUNDS"); do
  for threads in 1 2; do
    for side in A B; do
      if [ "$side" = A ]; then bin=$BIN_A; else bin=$BIN_B; fi
      rm -rf "$WORK/out"
      t0=$(date +%s.%N)
      "$bin" run "$SWEEP" --out "$WORK/out" --threads "$threads" --no-summary >/dev/null 2>"$WORK/err"
      t1=$(date +%s.%N)
      runs=$(sed -n 's/^time: runs \([0-9.]*\) s.*/\1/p' "$WORK/err")
      bps=$(sed -n 's/.* \([0-9.]*\) bytes\/step.*/\1/p' "$WORK/err")
      wcpu=$(sed -n 's/.*, \([0-9.]*\) s CPU).*/\1/p' "$WORK/err")
      echo "$side t$threads $(echo "$t1 $t0" | awk '{printf "%.3f", $1 - $2}') $runs $wcpu $bps" >>"$WORK/times"
    done
  done
  echo "round $round/$ROUNDS done" >&2
done
awk '
function median(list,   n, a, i, j, t) {
  n = split(list, a, " ")
  for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j-1] + 0 > a[j] + 0; j--) { t = a[j]; a[j] = a[j-1]; a[j-1] = t }
  return n % 2 ? a[(n+1)/2] : (a[n/2] + a[n/2+1]) / 2
}
{ k = $1 " " $2; wall[k] = wall[k] " " $3; runs[k] = runs[k] " " $4; cpu[k] = cpu[k] " " $5; bps[k] = $6 }
END {
  printf "%-6s %-8s %9s %11s %14s %14s\n", "build", "threads", "wall (s)", "runs Σ (s)", "writer CPU (s)", "series B/step"
  for (s = 0; s < 2; s++) for (t = 1; t <= 2; t++) {
    side = s ? "B" : "A"; k = side " t" t
    w[k] = median(wall[k]); c[k] = median(cpu[k])
    printf "%-6s %-8s %9.3f %11.3f %14.3f %14s\n", side, t, w[k], median(runs[k]), c[k], bps[k]
  }
  printf "\nwriter CPU, threads 1: A / B = %.2f\n", c["A t1"] / c["B t1"]
  printf "series bytes per stored step: A %s, B %s\n", bps["A t1"], bps["B t1"]
  printf "threads 2 / threads 1 speed-up, whole command, series kept: A %.2fx, B %.2fx\n", w["A t1"] / w["A t2"], w["B t1"] / w["B t2"]
}' "$WORK/times"
