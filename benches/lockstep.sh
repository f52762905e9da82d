#!/bin/sh
# Lockstep groups (issue 24, done-when 1): an 8-member ensemble whose members share their step
# matrix, run with `--threads 1` in one group (`--lockstep 8`) and each alone (`--lockstep 1`),
# against ONE member (the same sweep with `samples = 1`). Whole commands, interleaved round by
# round so that all three see the same machine load; medians of the wall time and the ratios
# the issue states its targets in (8 members ≤ 3 × one member).
#
#   cargo build --release && sh benches/lockstep.sh [ROUNDS] [SWEEP]
#   (default 5 rounds, benches/sweeps/lockstep_bar2d.toml; also lockstep_sphere3d.toml)
#
# Needs only sh, awk, sed and date. Each command starts from an empty output folder.
set -eu
ROUNDS=${1:-5}
SWEEP=${2:-benches/sweeps/lockstep_bar2d.toml}
BIN=${BIN:-target/release/contact-sweep}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/lockstep.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
sed 's/samples = 8/samples = 1/' "$SWEEP" >"$WORK/one.toml"
for round in $(seq "$ROUNDS"); do
  for c in group:8:"$SWEEP" alone:1:"$SWEEP" one:8:"$WORK/one.toml"; do
    name=$(echo "$c" | cut -d: -f1)
    size=$(echo "$c" | cut -d: -f2)
    file=$(echo "$c" | cut -d: -f3-)
    rm -rf "$WORK/out"
    t0=$(date +%s.%N)
    "$BIN" run "$file" --out "$WORK/out" --threads 1 --lockstep "$size" --series-every 0 \
      --no-summary >/dev/null 2>&1
    t1=$(date +%s.%N)
    echo "$name $(echo "$t1 $t0" | awk '{printf "%.3f", $1 - $2}')" >>"$WORK/times"
  done
  echo "round $round/$ROUNDS done" >&2
done
awk '
function median(list,   n, a, i, j, t) {
  n = split(list, a, " ")
  for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j-1] + 0 > a[j] + 0; j--) { t = a[j]; a[j] = a[j-1]; a[j-1] = t }
  return n % 2 ? a[(n+1)/2] : (a[n/2] + a[n/2+1]) / 2
}
{ t[$1] = t[$1] " " $2 }
END {
  g = median(t["group"]); a = median(t["alone"]); o = median(t["one"])
  printf "one member                 %8.2f s\n", o
  printf "8 members, --lockstep 8    %8.2f s  = %.2f x one member, %.3f s per run\n", g, g / o, g / 8
  printf "8 members, --lockstep 1    %8.2f s  = %.2f x one member, %.3f s per run\n", a, a / o, a / 8
  printf "lockstep speed-up          %8.2f x\n", a / g
}' "$WORK/times"
