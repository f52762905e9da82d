#!/usr/bin/env bash
# Bit-for-bit guard: do this working tree's engines compute exactly what BASE's did?
#
#   scripts/engine_bits.sh BASE [SWEEP.toml …]
#
# Run it from inside the worktree to test (its working tree, uncommitted changes included, is
# "HEAD"); BASE is any commit (e.g. `main`, `39405fb`). It builds BASE once into a cached copy
# (a `git archive` under $ENGINE_BITS_CACHE, default /tmp/engine-bits, with its own target dir),
# builds HEAD with your CARGO_TARGET_DIR (default target/), runs the same sweeps with both
# binaries (`--threads 1`, once with `--lockstep 1` and once with lockstep groups of 8), and
# compares a digest of each output folder: every column of every run's row as exact bits
# (floats as f64::to_bits), a SHA-256 of each run's series and of each reference file — all but
# the timing columns (examples/runs_digest.rs). It prints "bit-identical: N runs" and exits 0,
# or prints the differing lines and exits 1.
#
# The sweeps default to sweeps/bits/*.toml (every scene × contact treatment × mass × scheme ×
# friction × solver, coarse; ~2 min per binary and pass on one core); give files to run only
# those (e.g. the 1D ones: sweeps/bits/{bar1d,flying_bar,layer1d,oscillator}.toml). BASE's
# digests are cached per sweep file, so a second call only reruns HEAD. Several callers may run
# at once: BASE's build and runs are done under a lock, each call has its own output folders.
#
# Environment: ENGINE_BITS_CACHE (cache folder), ENGINE_BITS_BASE_TARGET (BASE's target dir,
# default $ENGINE_BITS_CACHE/target-base), ENGINE_BITS_SEED_TARGET (a target dir to copy as
# BASE's first target dir, so the dependencies are not compiled again), ENGINE_BITS_KEEP=1 (keep
# this call's output folders), ENGINE_BITS_DIFF_LINES (lines of diff shown, default 200).
set -euo pipefail

if [[ $# -lt 1 || $1 == -h || $1 == --help ]]; then
    sed -n '2,28p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
base_arg=$1
shift

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# The helper files (the digest program, the default sweeps) come from the script's own tree;
# the tree under test is the caller's.
helpers=$(cd "$script_dir/.." && pwd)
head_tree=$(git rev-parse --show-toplevel)
cache=${ENGINE_BITS_CACHE:-/tmp/engine-bits}
base_target=${ENGINE_BITS_BASE_TARGET:-$cache/target-base}
digest_src=$helpers/examples/runs_digest.rs

sweeps=()
if [[ $# -gt 0 ]]; then
    for s in "$@"; do sweeps+=("$(cd "$(dirname "$s")" && pwd)/$(basename "$s")"); done
else
    for s in "$helpers"/sweeps/bits/*.toml; do sweeps+=("$s"); done
fi
[[ ${#sweeps[@]} -gt 0 ]] || { echo "engine_bits: no sweep files" >&2; exit 2; }

base_rev=$(git -C "$head_tree" rev-parse --verify "$base_arg^{commit}")
base_dir=$cache/base-${base_rev:0:12}
mkdir -p "$cache"
work=$(mktemp -d "$cache/call.XXXXXX")
cleanup() { [[ ${ENGINE_BITS_KEEP:-0} == 1 || -f $work/.failed ]] || rm -rf "$work"; }
trap cleanup EXIT

sha() { sha256sum "$@" | cut -c1-64; }
t0=$SECONDS

# Run one sweep with binary $1 into $3 with lockstep $4, and digest the folder into $5.
run_and_digest() {
    local bin=$1 sweep=$2 out=$3 lockstep=$4 digest_to=$5 digest_bin=$6
    if ! "$bin" run "$sweep" --out "$out" --threads 1 --lockstep "$lockstep" --no-summary \
        --table runs >"$out.log" 2>&1; then
        echo "engine_bits: $bin run $sweep failed:" >&2
        tail -n 20 "$out.log" >&2
        touch "$work/.failed"
        exit 1
    fi
    "$digest_bin" "$out" >"$digest_to.tmp"
    mv "$digest_to.tmp" "$digest_to"
}

lockstep_passes() { # the lockstep values to run with the binary $1
    if "$1" run --help 2>/dev/null | grep -q -- '--lockstep'; then echo "1 8"; else echo "1"; fi
}

# --- BASE: build (once per revision) and run (once per sweep file), under a lock ------------
exec 9>"$cache/base-${base_rev:0:12}.lock"
flock 9
if [[ ! -f $base_dir/.extracted ]]; then
    rm -rf "$base_dir"
    mkdir -p "$base_dir/tree"
    git -C "$head_tree" archive "$base_rev" | tar -x -C "$base_dir/tree"
    touch "$base_dir/.extracted"
fi
if [[ ! -d $base_target && -n ${ENGINE_BITS_SEED_TARGET:-} && -d $ENGINE_BITS_SEED_TARGET ]]; then
    echo "engine_bits: seeding $base_target from $ENGINE_BITS_SEED_TARGET" >&2
    cp -a "$ENGINE_BITS_SEED_TARGET" "$base_target"
fi
mkdir -p "$base_dir/tree/examples" "$base_dir/bin"
cmp -s "$digest_src" "$base_dir/tree/examples/runs_digest.rs" ||
    cp "$digest_src" "$base_dir/tree/examples/runs_digest.rs"
echo "engine_bits: building BASE ${base_rev:0:12}" >&2
(cd "$base_dir/tree" && CARGO_TARGET_DIR=$base_target \
    cargo build --release --quiet --bin contact-sweep --example runs_digest)
# The target dir may be shared by other revisions: keep this one's binaries beside its tree,
# and the digest program per call (another caller may rebuild it from another source).
cp "$base_target/release/contact-sweep" "$base_dir/bin/contact-sweep"
cp "$base_target/release/examples/runs_digest" "$work/runs_digest"
base_bin=$base_dir/bin/contact-sweep
passes=$(lockstep_passes "$base_bin")
key_common=$(cat "$base_dir/bin/contact-sweep" "$digest_src" | sha)
mkdir -p "$base_dir/digests"
for sweep in "${sweeps[@]}"; do
    for l in $passes; do
        key=$( (cat "$sweep"; echo "$key_common lockstep=$l") | sha)
        d=$base_dir/digests/$(basename "$sweep" .toml)-l$l-${key:0:16}.txt
        if [[ ! -f $d ]]; then
            echo "engine_bits: BASE $(basename "$sweep") lockstep $l" >&2
            rm -rf "$work/base-out"
            run_and_digest "$base_bin" "$sweep" "$work/base-out" "$l" "$d" "$work/runs_digest"
            rm -rf "$work/base-out" "$work/base-out.log"
        fi
        cp "$d" "$work/$(basename "$sweep" .toml)-l$l.base"
    done
done
flock -u 9
exec 9>&-

# --- HEAD: the caller's working tree, with the caller's target dir ----------------------------
echo "engine_bits: building HEAD ($head_tree)" >&2
(cd "$head_tree" && cargo build --release --quiet --bin contact-sweep)
head_target=${CARGO_TARGET_DIR:-$head_tree/target}
[[ $head_target == /* ]] || head_target=$head_tree/$head_target
cp "$head_target/release/contact-sweep" "$work/contact-sweep-head"
head_passes=$(lockstep_passes "$work/contact-sweep-head")
[[ $head_passes == "$passes" ]] || passes=1

runs=0
failed=0
for sweep in "${sweeps[@]}"; do
    name=$(basename "$sweep" .toml)
    for l in $passes; do
        echo "engine_bits: HEAD $name lockstep $l" >&2
        run_and_digest "$work/contact-sweep-head" "$sweep" "$work/$name-l$l" "$l" \
            "$work/$name-l$l.head" "$work/runs_digest"
        if diff -u --label "BASE ${base_rev:0:12} $name lockstep $l" \
            --label "HEAD $name lockstep $l" "$work/$name-l$l.base" "$work/$name-l$l.head" \
            >"$work/$name-l$l.diff"; then
            runs=$((runs + $(head -n 1 "$work/$name-l$l.head" | cut -d' ' -f2)))
            rm -rf "$work/$name-l$l"
        else
            failed=1
            head -n "${ENGINE_BITS_DIFF_LINES:-200}" "$work/$name-l$l.diff"
            echo "engine_bits: $name lockstep $l differs: $(grep -c '^[-+][^-+]' "$work/$name-l$l.diff") lines, full diff $work/$name-l$l.diff"
        fi
    done
done
if [[ $failed == 1 ]]; then
    touch "$work/.failed"
    echo "NOT bit-identical (outputs kept in $work)"
    exit 1
fi
echo "bit-identical: $runs runs ($(( SECONDS - t0 )) s)"
