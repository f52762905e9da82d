#!/bin/sh
# This build's sink against another build's (issues 23 and 35), side by side in one run: the
# 400-run 1D sweep of benches/sweeps/overhead_1d.toml, series kept, no summary, with
# --threads 1 and --threads 2, the two binaries alternating round by round (A B A B …) so both
# see the same machine load. Prints medians (and min–max) of the whole command's wall time, the
# runs' own summed time, the output's CPU — the Parquet writer thread's before issue 35,
# the workers' encoding plus the committer thread's after it — the committer's CPU alone (the
# serial part), the output CPU per stored step, the series bytes per stored step, the process
# CPU (getrusage, user + system, through /usr/bin/time), then the ratios the issues' targets
# are stated in.
#
#   git worktree add /tmp/before aa91c27        # the sink before issue 35 (one writer thread)
#   cargo build --release --manifest-path /tmp/before/Cargo.toml --target-dir /tmp/before/target
#   cargo build --release
#   BIN_B=/tmp/before/target/release/contact-sweep sh benches/sink_ab.sh 5
#
# Needs sh, awk, sed and /usr/bin/time (GNU).
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
      /usr/bin/time -f "%e %U %S" -o "$WORK/rusage" \
        "$bin" run "$SWEEP" --out "$WORK/out" --threads "$threads" --no-summary >/dev/null 2>"$WORK/err"
      wall=$(awk '{ print $1 }' "$WORK/rusage")
      pcpu=$(awk '{ printf "%.3f", $2 + $3 }' "$WORK/rusage")
      runs=$(sed -n 's/^time: runs \([0-9.]*\) s.*/\1/p' "$WORK/err")
      steps=$(sed -n 's/.*series: \([0-9]*\) stored steps.*/\1/p' "$WORK/err")
      bps=$(sed -n 's/.* \([0-9.]*\) bytes\/step.*/\1/p' "$WORK/err")
      # The `time:` line of either version: "Parquet writer W s (own thread, C s CPU)" before
      # issue 35 (the writer's CPU is then the output's and the serial part's), "encoding E s
      # CPU (…), committer K s CPU (…)" after it.
      grep '^time:' "$WORK/err" | sed 's/.*Parquet writer/Parquet writer/; s/^time: runs [0-9.]* s (summed), command [0-9.]* s wall so far, //; s/; series.*//' >"$WORK/line"
      cpus=$(sed -n 's/^Parquet writer [0-9.]* s (own thread, \([0-9.]*\) s CPU).*/\1 \1/p; s/^encoding \([0-9.]*\) s CPU.*committer \([0-9.]*\) s CPU.*/\1 \2/p' "$WORK/line")
      # shellcheck disable=SC2086
      set -- $cpus
      echo "$side t$threads $wall $pcpu $runs $1 $2 $steps $bps" >>"$WORK/times"
    done
  done
  echo "round $round/$ROUNDS done" >&2
done
awk '
function sort(list, a,   n, i, j, t) {
  n = split(list, a, " ")
  for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j-1] + 0 > a[j] + 0; j--) { t = a[j]; a[j] = a[j-1]; a[j-1] = t }
  return n
}
function median(list,   n, a) { n = sort(list, a); return n % 2 ? a[(n+1)/2] : (a[n/2] + a[n/2+1]) / 2 }
function range(list,   n, a) { n = sort(list, a); return sprintf("%.3f–%.3f", a[1], a[n]) }
{ k = $1 " " $2; wall[k] = wall[k] " " $3; pcpu[k] = pcpu[k] " " $4; runs[k] = runs[k] " " $5
  # The encoding side of the output: everything but the committer in the new line; the
  # writer thread (which also committed) in the old one, where $6 == $7.
  out[k] = out[k] " " ($6 == $7 ? $6 : $6 + $7); com[k] = com[k] " " $7; steps[k] = $8; bps[k] = $9 }
END {
  printf "%-6s %-8s %18s %13s %11s %15s %15s %13s %9s\n", "build", "threads", "wall (s) [min–max]", "process CPU", "runs Σ (s)", "output CPU (s)", "serial CPU (s)", "ns CPU/step", "B/step"
  for (s = 0; s < 2; s++) for (t = 1; t <= 2; t++) {
    side = s ? "B" : "A"; k = side " t" t
    w[k] = median(wall[k]); o[k] = median(out[k]); c[k] = median(com[k]); r[k] = median(runs[k])
    printf "%-6s %-8s %7.3f [%s] %13.3f %11.3f %15.3f %15.3f %13.1f %9s\n", side, t, w[k], range(wall[k]), median(pcpu[k]), r[k], o[k], c[k], 1e9 * o[k] / steps[k], bps[k]
  }
  printf "\noutput CPU per stored step, threads 1: A / B = %.2f\n", o["A t1"] / o["B t1"]
  printf "serial output CPU (A: committer; B: writer thread) over the runs Σ, threads 1: A 1/%.0f, B 1/%.1f\n", r["A t1"] / c["A t1"], r["B t1"] / c["B t1"]
  printf "series bytes per stored step: A %s, B %s\n", bps["A t1"], bps["B t1"]
  printf "threads 2 / threads 1 speed-up, whole command, series kept (medians): A %.2fx, B %.2fx\n", w["A t1"] / w["A t2"], w["B t1"] / w["B t2"]
}' "$WORK/times"
