#!/bin/sh
# How many cores a sweep's output lets it use (issue 35), without a big machine. The one serial
# part of a sweep's output is the committer thread (fsync, rename, folder sync); the runs and
# the Parquet encoding run on the workers. Its serial fraction
#     s = committer CPU / (runs CPU + encoding CPU)
# bounds the speed-up of any number of workers by 1/s (Amdahl). Measured from the end-of-run
# `time:` line of `--threads 1` and `--threads 2` commands, interleaved round by round so both
# see the same machine load, on two sweeps with series kept and no summary:
#   - benches/sweeps/overhead_1d.toml: 400 short 1D runs, every step stored — the worst case
#     (the most output per second of computing);
#   - benches/sweeps/scaling_bar2d.toml: the 2D bar, 32 runs of 120 to 5 440 dofs.
# Runs CPU is the process's CPU (getrusage, through /usr/bin/time) less the encoding and the
# committer: CPU clocks, so a loaded machine's waits do not count.
# Prints, per sweep, medians of s and 1/s (from the 1-thread runs), and the measured
# `--threads 2` ÷ `--threads 1` ratio of the whole command's wall time (median, min, max over
# rounds) beside the ceiling 2 cores allow, min(2, 1/s).
#
#   cargo build --release && sh benches/scaling.sh [ROUNDS]      (default 5 rounds)
#
# Needs sh, awk, sed and /usr/bin/time (GNU).
set -eu
ROUNDS=${1:-5}
BIN=${BIN:-target/release/contact-sweep}
SWEEPS=${SWEEPS:-benches/sweeps/overhead_1d.toml benches/sweeps/scaling_bar2d.toml}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/scaling.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
for round in $(seq "$ROUNDS"); do
  for sweep in $SWEEPS; do
    for threads in 1 2; do
      rm -rf "$WORK/out"
      /usr/bin/time -f "%e %U %S" -o "$WORK/rusage" \
        "$BIN" run "$sweep" --out "$WORK/out" --threads "$threads" --no-summary >/dev/null 2>"$WORK/err"
      enc=$(sed -n 's/.* encoding \([0-9.]*\) s CPU.*/\1/p' "$WORK/err")
      com=$(sed -n 's/.* committer \([0-9.]*\) s CPU.*/\1/p' "$WORK/err")
      # The runs' CPU: the process's (getrusage: user + system) less the output's. It keeps
      # the few ms of planning and opening the folder; the runs' own summed wall time (the
      # `time:` line) would count the waits of a loaded machine.
      awk -v n="$(basename "$sweep" .toml)" -v t="$threads" -v r="$round" -v e="$enc" -v c="$com" \
        '{ printf "%s %s %s %.3f %.3f %s %s\n", n, t, r, $1, $2 + $3 - e - c, e, c }' "$WORK/rusage" >>"$WORK/times"
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
function lo(list,   a) { sort(list, a); return a[1] }
function hi(list,   n, a) { n = sort(list, a); return a[n] }
{ k = $1 " " $2; wall[k] = wall[k] " " $4; runs[k] = runs[k] " " $5; enc[k] = enc[k] " " $6; com[k] = com[k] " " $7
  s[k] = s[k] " " $7 / ($5 + $6); w[$1 " " $2 " " $3] = $4
  if (!($1 in seen)) { seen[$1] = 1; names[++n] = $1 } }
END {
  printf "%-20s %10s %10s %11s %9s %8s %11s %22s\n", "sweep", "runs CPU", "enc. CPU", "commit CPU", "s", "1/s", "ceiling 2c", "t2/t1 med [min–max]"
  for (i = 1; i <= n; i++) {
    c = names[i]; k = c " 1"
    # Per round, the 1-thread wall over the 2-thread wall.
    ratios = ""
    for (r = 1; (c " 1 " r) in w; r++) ratios = ratios " " w[c " 1 " r] / w[c " 2 " r]
    sf = median(s[k]); ceil = 1 / sf < 2 ? 1 / sf : 2
    printf "%-20s %10.3f %10.3f %11.4f %9.5f %8.0f %11.2f %8.2fx [%.2f–%.2f]\n", c, median(runs[k]), median(enc[k]), median(com[k]), sf, 1 / sf, ceil, median(wall[c " 1"]) / median(wall[c " 2"]), lo(ratios), hi(ratios)
  }
  print "\n(s and 1/s from the --threads 1 runs, CPU seconds: runs = process CPU − encoding − committer, medians; t2/t1 = median 1-thread wall over median 2-thread wall, [min–max] of the per-round ratios)"
}' "$WORK/times"
