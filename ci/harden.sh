#!/usr/bin/env bash
# Hardening CI: Miri on the C API's unit tests, the saved fuzz inputs replayed on stable, and
# each fuzz target (cargo-fuzz, libFuzzer) run briefly. Installs everything it needs (a pinned
# nightly with miri and rust-src, cargo-fuzz) so it works on a fresh machine; exits non-zero if
# any step fails, after running them all. About 6-9 minutes on 2 cores from scratch (toolchain,
# cargo-fuzz and Miri sysroot builds included), 3 minutes when installed.
#
#   bash ci/harden.sh                    # CI: a fixed seed and run count, so a clean clone
#                                        # always runs the same inputs (a gate, reproducible)
#   FUZZ_SECONDS=1200 bash ci/harden.sh  # exploring: random seeds for 20 min per target
#
# Exploring is how new findings are made; save each crash input in fuzz/regressions/<target>/
# with its fix, so the gate (and `cargo test`) replays it from then on.
set -uo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never

# Pinned: nightly-2026-05-20 (rustc 1.97.0-nightly e50aa6fba 2026-05-19) is the newest nightly the
# distribution server here had; cargo-fuzz 0.13.2 builds with --locked on stable 1.95.
NIGHTLY=nightly-2026-05-20
CARGO_FUZZ_VERSION=0.13.2
FUZZ_SECONDS=${FUZZ_SECONDS:-}
FUZZ_SEED=${FUZZ_SEED:-20261123}
# About 100 s each side by side on this machine (measured: 80 runs/s for each target, debug
# assertions on).
declare -A FUZZ_RUNS=([engine]=8000 [c_api]=9000)
TARGETS=(engine c_api)
LOGS=target/harden
mkdir -p "$LOGS"

passed=0
failed=0
failures=()
step() {
    local name=$1
    shift
    printf '\n== %s\n' "$name"
    local start=$SECONDS
    if "$@"; then
        passed=$((passed + 1))
        printf -- '-- ok: %s (%ss)\n' "$name" $((SECONDS - start))
    else
        failed=$((failed + 1))
        failures+=("$name")
        printf -- '-- FAILED: %s (%ss)\n' "$name" $((SECONDS - start))
    fi
}

install_nightly() {
    rustup toolchain install "$NIGHTLY" --profile minimal --component miri,rust-src
}

install_cargo_fuzz() {
    if cargo fuzz --version 2>/dev/null | grep " $CARGO_FUZZ_VERSION\$" >/dev/null; then
        cargo fuzz --version
    else
        cargo install cargo-fuzz --version "$CARGO_FUZZ_VERSION" --locked
    fi
}

# libm/force-soft-floats: libm's x86 square root is inline assembly, which Miri cannot run; the
# portable routine lets the tests poll (output_is_readable_between_polls runs a whole search).
miri_ffi() {
    cargo "+$NIGHTLY" miri setup &&
        cargo "+$NIGHTLY" miri test -p shape-from-symmetry-capi --features libm/force-soft-floats --lib
}

replay() {
    cargo test --test fuzz_regressions &&
        cargo test -p shape-from-symmetry-capi --test fuzz_regressions
}

# The fuzz crate is a workspace of its own: rustfmt and clippy (stable) see it only here.
fuzz_lint() {
    (cd fuzz && cargo fmt --check && cargo clippy --all-targets -- -D warnings)
}

fuzz_build() {
    (cd fuzz && cargo "+$NIGHTLY" fuzz build)
}

# Runs every target side by side (one core each), for FUZZ_RUNS inputs from FUZZ_SEED or, when
# FUZZ_SECONDS is set, for that long from a random seed; a crash, a hang
# (-timeout=30 s per input) or a leak fails the step and leaves its input in fuzz/artifacts/.
# -len_control=0: inputs up to -max_len from the start (the scene header alone is ~40 bytes, and
# libFuzzer's slow length ramp kept the engine target's inputs under 20 bytes, its depth bytes
# unexplored: 1 969 edges after two 60 s runs with the ramp, 2 151 after 3 more minutes without).
fuzz_all() {
    local pids=() t status=0
    for t in "${TARGETS[@]}"; do
        local limit corpus
        if [ -n "$FUZZ_SECONDS" ]; then
            limit=(-max_total_time="$FUZZ_SECONDS")
            corpus=corpus/$t
        else
            # A fresh corpus each time: the inputs run depend on the seed alone.
            limit=(-seed="$FUZZ_SEED" -runs="${FUZZ_RUNS[$t]}")
            corpus=corpus/gate-$t
            rm -rf "fuzz/$corpus"
        fi
        mkdir -p "fuzz/$corpus"
        (cd fuzz && cargo "+$NIGHTLY" fuzz run "$t" "$corpus" "regressions/$t" -- \
            "${limit[@]}" -len_control=0 -max_len=1024 -timeout=30 \
            -print_final_stats=1) \
            >"$LOGS/fuzz-$t.log" 2>&1 &
        pids+=($!)
    done
    for i in "${!TARGETS[@]}"; do
        t=${TARGETS[$i]}
        if wait "${pids[$i]}"; then
            grep -E '^Done [0-9]+ runs' "$LOGS/fuzz-$t.log" | sed "s/^/fuzz $t: /"
            grep -E 'stat::(number_of_executed_units|average_exec_per_sec)' "$LOGS/fuzz-$t.log" |
                sed "s/^/fuzz $t: /"
        else
            status=1
            echo "fuzz $t FAILED (log: $LOGS/fuzz-$t.log):"
            tail -n 40 "$LOGS/fuzz-$t.log"
        fi
    done
    return $status
}

total_start=$SECONDS
step "pinned nightly $NIGHTLY (+ miri, rust-src)" install_nightly
step "cargo-fuzz $CARGO_FUZZ_VERSION" install_cargo_fuzz
step "Miri: the C API's unit tests" miri_ffi
step "saved fuzz inputs replayed (stable, debug assertions)" replay
step "fuzz crate: rustfmt and clippy" fuzz_lint
step "fuzz targets build" fuzz_build
if [ -n "$FUZZ_SECONDS" ]; then
    step "fuzz ${TARGETS[*]} for ${FUZZ_SECONDS} s each (random seeds)" fuzz_all
else
    step "fuzz ${TARGETS[*]} (seed $FUZZ_SEED, ${FUZZ_RUNS[*]} runs)" fuzz_all
fi

printf '\nharden: %ss in all\n' $((SECONDS - total_start))
if [ "$failed" -ne 0 ]; then
    printf 'harden: failed: %s\n' "${failures[*]}"
fi
echo "harden: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
