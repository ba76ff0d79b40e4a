#!/usr/bin/env bash
# Firmware check: build the Cortex-M4F example, run it under QEMU, run the same search on the
# host, and fail unless both print the same digest. Prints the measured figures and the ELF size.
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
qemu-system-arm --version | head -n1
arm-none-eabi-size --version | head -n1

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

step "clippy on the firmware example ($TARGET)"
# Scoped to the example's own files: the library is checked by the host clippy run.
set +e
cargo clippy --release --example firmware --target "$TARGET" --message-format short >"$OUT/clippy.txt" 2>&1
rc=$?
set -e
if [ $rc -ne 0 ] || grep -E '^examples/.*(warning|error)' "$OUT/clippy.txt"; then
    [ $rc -ne 0 ] && cat "$OUT/clippy.txt"
    echo "FAILED: clippy findings in the firmware example (above)"
    exit 1
fi
echo "clean"

run_qemu() {
    # The same invocation as the runner in .cargo/config.toml.
    timeout "$TIMEOUT" qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic \
        -monitor none -serial none -semihosting-config enable=on,target=native \
        -icount shift=3 -kernel "$ELF" </dev/null
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

step "figures (Cortex-M4F, QEMU instruction counts)"
grep -E '^(clock|instructions [a-z ]+|polls|peak stack|ram|flash):' "$OUT/target.txt"
echo
arm-none-eabi-size -A "$ELF" | grep -E '^(section|\.vector_table|\.text|\.rodata|\.data|\.bss|\.uninit) '
# Berkeley format: flash = text + data (initial values), RAM = data + bss (the stack is the rest
# of the 192 KiB; memory.x demands at least 16 KiB of it).
arm-none-eabi-size -B "$ELF"
echo
echo "firmware: 1 passed, 0 failed"
