#!/usr/bin/env bash
# Firmware check: build the Cortex-M4F example, run it under QEMU (the measuring run, then the
# same search as a 1 kHz control loop), run the same search on the host, and fail unless all
# print the same digest, no poll overran its tick and no poll at RECOMMENDED_BUDGET took over
# 100 000 instructions (a 1 kHz tick at 168 MHz). Prints the measured figures and the ELF
# size. Then the same firmware built with `--features defmt`: run, its log decoded with
# defmt-print, and checked for the symmetries and the digest.
#
#   bash ci/firmware.sh            (from anywhere; installs what is missing)
#
# Environment: FIRMWARE_TIMEOUT (seconds per QEMU run, default 900).
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=thumbv7em-none-eabihf
ELF=target/$TARGET/release/examples/firmware
TIMEOUT=${FIRMWARE_TIMEOUT:-900}
OUT=target/firmware-ci
# The defmt decoder, a host tool from crates.io (built from source: about 2 minutes on 2 cores).
DEFMT_PRINT_VERSION=1.2.0
mkdir -p "$OUT"

step() { printf '\n== %s\n' "$*"; }
as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

step "tools"
need=()
command -v qemu-system-arm >/dev/null || need+=(qemu-system-arm)
command -v arm-none-eabi-size >/dev/null || need+=(binutils-arm-none-eabi)
if [ ${#need[@]} -gt 0 ]; then
    # Debian's qemu-system-arm (7.2) replaces the preinstalled qemu-utils; nothing here needs it.
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "${need[@]}" >/dev/null
fi
rustup target list --installed | grep -qx "$TARGET" || rustup target add "$TARGET"
if ! defmt-print -V 2>/dev/null | grep -x "defmt-print $DEFMT_PRINT_VERSION" >/dev/null; then
    cargo install defmt-print --version "$DEFMT_PRINT_VERSION" --locked
fi
qemu-system-arm --version | sed -n 1p
arm-none-eabi-size --version | sed -n 1p
defmt-print -V | sed -n 1p  # sed reads it all: no broken pipe under pipefail

step "build firmware ($TARGET, release)"
# Linking is itself a check: no #[global_allocator] (nothing may allocate) and memory.x's
# 192 KiB RAM with a 16 KiB stack reserve (the statics must fit).
if ! cargo build --release --example firmware --target "$TARGET"; then
    cat <<'MSG'
FAILED: the firmware does not build for the Cortex-M4F. If the errors are about `std` in a
crate the library itself does not use: examples build with ALL dev-dependencies, so a host-only
dev-dependency must be declared as
    [target.'cfg(not(target_os = "none"))'.dev-dependencies]
in Cargo.toml, not under plain [dev-dependencies].
MSG
    exit 1
fi

step "clippy on the firmware example ($TARGET; default, --features defmt, --features firmware-dense)"
# Scoped to the example's own files: the library is checked by the host clippy run.
for features in "" defmt firmware-dense; do
    set +e
    cargo clippy --release --example firmware --target "$TARGET" ${features:+--features "$features"} \
        --message-format short >"$OUT/clippy.txt" 2>&1
    rc=$?
    set -e
    if [ $rc -ne 0 ] || grep -E '^examples/.*(warning|error)' "$OUT/clippy.txt"; then
        [ $rc -ne 0 ] && cat "$OUT/clippy.txt"
        echo "FAILED: clippy findings in the firmware example${features:+ (--features $features)} (above)"
        exit 1
    fi
done
echo "clean"

run_qemu() {
    # The same invocation as the runner, examples/firmware/qemu-run.sh (which also
    # decodes defmt output; here the defmt variant's raw frames are kept and decoded apart).
    timeout "$TIMEOUT" qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic \
        -monitor none -serial none -semihosting-config enable=on,target=native \
        -icount shift=3 -kernel "${1:-$ELF}" </dev/null
}

step "run firmware under QEMU (mps2-an386, -icount shift=3)"
set +e
run_qemu >"$OUT/target.txt" 2>&1
rc=$?
set -e
cat "$OUT/target.txt"
if [ $rc -ne 0 ]; then
    [ $rc -eq 124 ] && echo "FAILED: QEMU did not finish within ${TIMEOUT}s" || echo "FAILED: firmware exit code $rc"
    exit 1
fi

step "run firmware again: the instruction counts must repeat exactly"
run_qemu >"$OUT/target2.txt" 2>&1
if ! diff "$OUT/target.txt" "$OUT/target2.txt"; then
    echo "FAILED: two QEMU runs of the same ELF differ"
    exit 1
fi
echo "identical"

step "run the same search on the host"
cargo run --release --example firmware | tee "$OUT/host.txt"

step "compare"
target_digest=$(grep -m1 '^digest: 0x' "$OUT/target.txt" || true)
host_digest=$(grep -m1 '^digest: 0x' "$OUT/host.txt" || true)
echo "target  $target_digest"
echo "host    $host_digest"
if [ -z "$target_digest" ] || [ "$target_digest" != "$host_digest" ]; then
    echo "FAILED: the target and host results differ"
    diff <(grep -E '^(object|symmetries|  #|points|work units|digest):?' "$OUT/target.txt") \
        <(grep -E '^(object|symmetries|  #|points|work units|digest):?' "$OUT/host.txt") || true
    exit 1
fi

step "control loop: one poll per 1 kHz SysTick tick, none overran"
# The firmware itself fails unless the loop's digest equals the measuring run's.
grep '^control loop:' "$OUT/target.txt"
if ! grep -q '^control loop: .* polls in .* ticks, 0 overruns' "$OUT/target.txt"; then
    echo "FAILED: a poll did not finish within its 1 ms tick (125 000 instructions under -icount shift=3)"
    exit 1
fi

step "largest poll at RECOMMENDED_BUDGET: at most 100 000 instructions (1 kHz at 168 MHz)"
max_poll=$(sed -n 's/^instructions max poll: \([0-9]*\) .*/\1/p' "$OUT/target.txt")
echo "largest poll: ${max_poll:-not reported} instructions"
if [ -z "$max_poll" ] || [ "$max_poll" -gt 100000 ]; then
    echo "FAILED: a poll at RECOMMENDED_BUDGET took over 100 000 instructions"
    exit 1
fi

step "figures (Cortex-M4F, QEMU instruction counts)"
grep -E '^(clock|instructions [a-z ]+|polls|peak stack|ram|flash):' "$OUT/target.txt"
echo
arm-none-eabi-size -A "$ELF" | grep -E '^(section|\.vector_table|\.text|\.rodata|\.data|\.bss|\.uninit) '
# Berkeley format: flash = text + data (initial values), RAM = data + bss (the stack is the rest
# of the 192 KiB; memory.x demands at least 16 KiB of it).
arm-none-eabi-size -B "$ELF"

step "dense completion: --features firmware-dense (256-point engine, output with room for it)"
# The default firmware's output has no room for the completion's dense pass; this build's has:
# the same checks (host = target digest, no poll at RECOMMENDED_BUDGET over 100 000
# instructions), and the pass must have run (more visible points than sampled ones).
cargo build --release --example firmware --target "$TARGET" --features firmware-dense
DENSE_ELF=$OUT/firmware-dense.elf
cp "$ELF" "$DENSE_ELF"
cargo build --release --example firmware --target "$TARGET" 2>/dev/null
set +e
run_qemu "$DENSE_ELF" >"$OUT/dense.txt" 2>&1
rc=$?
set -e
if [ $rc -ne 0 ]; then
    cat "$OUT/dense.txt"
    [ $rc -eq 124 ] && echo "FAILED: QEMU did not finish within ${TIMEOUT}s" || echo "FAILED: dense firmware exit code $rc"
    exit 1
fi
cargo run --release --example firmware --features firmware-dense >"$OUT/dense-host.txt"
grep -E '^(object|points|digest|instructions max poll|stage completing|ram):' "$OUT/dense.txt" |
    sed 's/^/dense /'
dense_target=$(grep -m1 '^digest: 0x' "$OUT/dense.txt" || true)
dense_host=$(grep -m1 '^digest: 0x' "$OUT/dense-host.txt" || true)
if [ -z "$dense_target" ] || [ "$dense_target" != "$dense_host" ]; then
    echo "FAILED: the dense build's target ($dense_target) and host ($dense_host) results differ"
    exit 1
fi
dense_max=$(sed -n 's/^instructions max poll: \([0-9]*\) .*/\1/p' "$OUT/dense.txt")
if [ -z "$dense_max" ] || [ "$dense_max" -gt 100000 ]; then
    echo "FAILED: a poll of the dense build took ${dense_max:-?} instructions (over 100 000)"
    exit 1
fi
sampled=$(sed -n 's/^object: .* pixels with depth, \([0-9]*\) points sampled$/\1/p' "$OUT/dense.txt")
visible=$(sed -n 's/^points: \([0-9]*\) visible.*/\1/p' "$OUT/dense.txt")
if [ -z "$sampled" ] || [ -z "$visible" ] || [ "$visible" -le "$sampled" ]; then
    echo "FAILED: the dense pass did not run (${visible:-?} visible points, ${sampled:-?} sampled)"
    exit 1
fi
echo "dense pass: $visible visible points of $sampled sampled; host = target, largest poll $dense_max"

step "defmt: build with --features defmt, run under QEMU, decode with defmt-print"
# Everything goes out as defmt frames over semihosting (defmt-semihosting); the output file holds
# the raw frames, decoded here against the ELF's `.defmt` table.
cargo build --release --example firmware --target "$TARGET" --features defmt
DEFMT_ELF=$OUT/firmware-defmt.elf
cp "$ELF" "$DEFMT_ELF"
# Put the default build back in place (already built: nothing is compiled).
cargo build --release --example firmware --target "$TARGET" 2>/dev/null
set +e
run_qemu "$DEFMT_ELF" >"$OUT/defmt.bin" 2>"$OUT/defmt-qemu.txt"
rc=$?
set -e
set +e
defmt-print -e "$DEFMT_ELF" --show-skipped-frames --log-format '{t} {L} {s}' \
    <"$OUT/defmt.bin" >"$OUT/defmt.txt" 2>&1
decode_rc=$?
set -e
cat "$OUT/defmt-qemu.txt" "$OUT/defmt.txt"
if [ $rc -ne 0 ]; then
    [ $rc -eq 124 ] && echo "FAILED: QEMU did not finish within ${TIMEOUT}s" || echo "FAILED: defmt firmware exit code $rc"
    exit 1
fi
if [ $decode_rc -ne 0 ]; then
    echo "FAILED: defmt-print could not decode the log (exit code $decode_rc)"
    exit 1
fi

step "defmt: the decoded log has the symmetries and the host's digest"
defmt_failed=0
check_log() { # what, extended regex over the decoded lines
    if grep -qE "$2" "$OUT/defmt.txt"; then echo "ok: $1"; else echo "MISSING: $1"; defmt_failed=1; fi
}
if grep -E 'malformed|ERROR' "$OUT/defmt.txt"; then
    echo "FAILED: the defmt log has errors or undecodable frames (above)"
    defmt_failed=1
fi
check_log "start" '^[0-9.]+ INFO +shape-from-symmetry firmware: '
check_log "$(grep -m1 '^symmetries: ' "$OUT/host.txt")" \
    "^[0-9.]+ INFO +$(grep -m1 '^symmetries: ' "$OUT/host.txt")\$"
# Every symmetry the host found: the same index, type and domain, and then the symmetry in full
# through its defmt::Format derive (`AxialPlane(Axis { .. }, Plane { .. })` and so on).
while read -r index kind _ _ _ domain _; do
    check_log "$index $kind (domain $domain), with its geometry" \
        "^[0-9.]+ INFO +$index $kind score [0-9.]+ domain $domain points: [A-Z][A-Za-z]*\("
done < <(grep -E '^  #[0-9]+ ' "$OUT/host.txt")
check_log "$host_digest" "^[0-9.]+ INFO +$host_digest\$"
check_log "control loop, no overrun" '^[0-9.]+ INFO +control loop: .* polls in .* ticks, 0 overruns'
check_log "control loop: the same digest" \
    "^[0-9.]+ INFO +control loop: digest ${host_digest#digest: }, the same as the measuring run's\$"
if [ $defmt_failed -ne 0 ]; then
    echo "FAILED: the defmt build's log (above) is not what the host computed"
    exit 1
fi
echo
echo "firmware: 3 passed, 0 failed"
