#!/usr/bin/env bash
# Compares what two versions of crr write: every bundled model simulated, `crr check --json` of
# all of them, Poincaré sections and sweeps of each kind, a study run in two shards and merged,
# and the overturning map study. A refactor that should change nothing must print "identical".
#
#   tools/compare_outputs.sh BASE_COMMIT [OTHER_COMMIT]
#
# OTHER_COMMIT defaults to the working tree. Each version is built in release mode in its own
# worktree and target folder under ${TMPDIR:-/tmp}/crr-compare (kept between runs: a second
# comparison only rebuilds what changed). Output folders' paths and the study's wall time are
# normalised before the comparison; everything else must match byte for byte.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
work="${TMPDIR:-/tmp}/crr-compare"
mkdir -p "$work"

build() { # build REV NAME → prints the binary's path
    local rev="$1" name="$2" src
    if [ "$rev" = "worktree" ]; then
        src="$root"
    else
        src="$work/src-$name"
        git -C "$root" worktree remove --force "$src" 2>/dev/null || rm -rf "$src"
        git -C "$root" worktree add --detach "$src" "$rev" >/dev/null
    fi
    (cd "$src" && CARGO_TARGET_DIR="$work/target-$name" cargo build --release --quiet --bin crr)
    echo "$work/target-$name/release/crr"
}

run_all() { # run_all BIN OUT
    local bin="$1" out="$2" m n
    rm -rf "$out" && mkdir -p "$out"
    cd "$root"
    for m in examples/models/*.toml; do
        n=$(basename "$m" .toml)
        "$bin" simulate "$m" --out "$out/$n" --quiet >"$out/$n.stdout" 2>"$out/$n.stderr" || true
    done
    "$bin" check examples/models/*.toml --json >"$out/check.json" 2>&1 || true
    local p=examples/models/single_block.toml
    "$bin" poincare $p --amplitude 2 --frequency 1.5 --periods 5 --transient 2 --out "$out/p1" >"$out/p1.out" 2>&1 || true
    "$bin" poincare $p --amplitudes 1:3:3 --frequency 1.5 --periods 3 --transient 1 --out "$out/p2" >"$out/p2.out" 2>&1 || true
    "$bin" poincare $p --frequencies 1:2:3 --amplitude 2 --periods 3 --transient 1 --out "$out/p3" >"$out/p3.out" 2>&1 || true
    "$bin" poincare $p --grid=-0.1:0.1:3,-0.2:0.2:2 --periods 3 --transient 1 --out "$out/p4" >"$out/p4.out" 2>&1 || true
    "$bin" poincare $p --section base --periods 3 --transient 0 --out "$out/p5" >"$out/p5.out" 2>&1 || true
    local s=examples/studies/housner_map.toml
    "$bin" study $s --out "$out/s1" --shard 1/2 --quiet >"$out/s1.out" 2>&1 || true
    "$bin" study $s --out "$out/s2" --shard 2/2 --quiet >"$out/s2.out" 2>&1 || true
    "$bin" study merge "$out/s1" "$out/s2" --out "$out/m" >"$out/m.out" 2>&1 || true
    "$bin" study $s --out "$out/s" --quiet >"$out/s.out" 2>&1 || true
    # Normalise what differs by construction: the output folders' paths and wall times.
    grep -rlF "$out" "$out" | xargs -r sed -i "s#$out#OUT#g"
    find "$out" -name study.json -exec sed -i 's/"wall_time_s": .*/"wall_time_s": X/' {} +
}

base_bin=$(build "$1" base)
other_bin=$(build "${2:-worktree}" other)
run_all "$base_bin" "$work/out-base"
run_all "$other_bin" "$work/out-other"
if diff -r "$work/out-base" "$work/out-other"; then
    echo "identical: $(find "$work/out-base" -type f | wc -l) files"
else
    exit 1
fi
