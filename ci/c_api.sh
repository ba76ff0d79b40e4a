#!/usr/bin/env bash
# C API check: the committed header is what cbindgen generates from capi/src; the C test
# program (capi/tests/c/test_api.c) passes against the host static library; the same C file links
# against the Cortex-M4F static library with arm-none-eabi-gcc and passes under QEMU; and both
# searches print the digest of the Rust firmware example (bit-identical results through the
# C API, on the host and on the target).
#
#   bash ci/c_api.sh            (from anywhere; installs what is missing)
#
# Environment: C_API_TIMEOUT (seconds for the QEMU run, default 600).
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=thumbv7em-none-eabihf
CBINDGEN_VERSION=0.29.4
TIMEOUT=${C_API_TIMEOUT:-600}
OUT=target/c_api
SCENE="$PWD/testkit/data/builtin_scene.bin"
CAPI=capi
mkdir -p "$OUT"

passed=0
step() { printf '\n== %s\n' "$*"; }
ok() { passed=$((passed + 1)); echo "ok: $*"; }
fail() { echo "FAILED: $*"; echo "c_api: $passed passed, 1 failed"; exit 1; }
as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

# The "checks: N passed, M failed" line of a test_api run: N, if M is 0.
checks_passed() {
    local line
    line=$(grep -E '^checks: [0-9]+ passed, [0-9]+ failed$' "$1" | tail -n1)
    [ -n "$line" ] || return 1
    [ "$(echo "$line" | awk '{print $4}')" = 0 ] || return 1
    echo "$line" | awk '{print $2}'
}

step "tools"
need=()
command -v cc >/dev/null || need+=(gcc)
command -v arm-none-eabi-gcc >/dev/null || need+=(gcc-arm-none-eabi)
# newlib: the C library (printf through semihosting, rdimon) of the Cortex-M4F test program.
[ -d /usr/lib/arm-none-eabi/newlib ] || need+=(libnewlib-arm-none-eabi)
command -v qemu-system-arm >/dev/null || need+=(qemu-system-arm)
if [ ${#need[@]} -gt 0 ]; then
    # Debian's qemu-system-arm (7.2) replaces the preinstalled qemu-utils; nothing here needs it.
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "${need[@]}" >/dev/null
fi
if ! cbindgen --version 2>/dev/null | grep -x "cbindgen $CBINDGEN_VERSION" >/dev/null; then
    cargo install cbindgen --version "$CBINDGEN_VERSION" --locked
fi
rustup target list --installed | grep -qx "$TARGET" || rustup target add "$TARGET"
cc --version | sed -n 1p
arm-none-eabi-gcc --version | sed -n 1p
cbindgen --version

step "header: capi/include/shape_from_symmetry.h is what cbindgen generates from capi/src"
cbindgen --quiet --config $CAPI/cbindgen.toml --output "$OUT/header.h" $CAPI/src/lib.rs
if ! diff -u $CAPI/include/shape_from_symmetry.h "$OUT/header.h"; then
    fail "the committed header is stale: run
    cbindgen --config capi/cbindgen.toml --output capi/include/shape_from_symmetry.h capi/src/lib.rs
and commit it"
fi
ok "header in sync"

step "host: static library and the C test with cc"
# The linker arguments the staticlib needs on this host (std's system libraries).
libs=$(cargo rustc --release -p shape-from-symmetry-capi --lib --crate-type staticlib \
    -- --print native-static-libs 2>&1 | tee "$OUT/host-build.txt" |
    sed -n 's/.*native-static-libs: //p' | tail -n1)
LIB=target/release/libshape_from_symmetry_capi.a
[ -f $LIB ] || { cat "$OUT/host-build.txt"; fail "no host staticlib"; }
echo "native libraries: $libs"
# shellcheck disable=SC2086 # $libs is a list of linker flags
cc -std=c11 -Wall -Wextra -Wpedantic -Werror -O2 -I$CAPI/include -DSCENE_FILE="\"$SCENE\"" \
    $CAPI/tests/c/test_api.c $LIB $libs -o "$OUT/test_api"
set +e
"$OUT/test_api" >"$OUT/host.txt" 2>&1
rc=$?
set -e
cat "$OUT/host.txt"
n=$(checks_passed "$OUT/host.txt") && [ $rc -eq 0 ] || fail "the C test on the host (exit code $rc)"
passed=$((passed + n))
ok "C test on the host: $n checks"

step "reference: the Rust firmware example's digest on the host"
cargo run --release --example firmware >"$OUT/rust.txt"
reference=$(grep -m1 '^digest: 0x' "$OUT/rust.txt" || true)
host_digest=$(grep -m1 '^digest: 0x' "$OUT/host.txt" || true)
echo "rust (examples/firmware)  $reference"
echo "C API, host               $host_digest"
[ -n "$reference" ] && [ "$reference" = "$host_digest" ] || fail "the C API's result on the host differs from the Rust API's"
ok "host digest equals the Rust firmware example's"

step "Cortex-M4F: static library (--features panic-handler) and the C test with arm-none-eabi-gcc"
cargo build --release -p shape-from-symmetry-capi --lib --features panic-handler --target "$TARGET"
# Link: the library, newlib with semihosting (rdimon), a minimal start-up and memory map for
# QEMU's mps2-an386. -nostartfiles: startup_m4.c is the start-up code.
arm-none-eabi-gcc -std=c11 -Wall -Wextra -Wpedantic -Werror -O2 \
    -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 \
    -I$CAPI/include -DSCENE_FILE="\"$SCENE\"" \
    --specs=rdimon.specs -nostartfiles -T $CAPI/tests/c/m4.ld \
    $CAPI/tests/c/test_api.c $CAPI/tests/c/startup_m4.c "target/$TARGET/release/libshape_from_symmetry_capi.a" \
    -lm -Wl,--gc-sections -Wl,--no-warn-execstack -o "$OUT/test_api_m4.elf"
arm-none-eabi-size "$OUT/test_api_m4.elf"
ok "links for the Cortex-M4F"

step "Cortex-M4F: run under QEMU (mps2-an386, semihosting)"
set +e
timeout "$TIMEOUT" qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic \
    -monitor none -serial none -semihosting-config enable=on,target=native \
    -kernel "$OUT/test_api_m4.elf" </dev/null >"$OUT/m4.txt" 2>&1
rc=$?
set -e
cat "$OUT/m4.txt"
case $rc in
    0) ;;
    3) fail "a fault on the Cortex-M4F" ;;
    4) fail "the library panicked on the Cortex-M4F" ;;
    124) fail "QEMU did not finish within ${TIMEOUT}s" ;;
    *) fail "the C test on the Cortex-M4F (exit code $rc)" ;;
esac
n=$(checks_passed "$OUT/m4.txt") || fail "the C test on the Cortex-M4F"
passed=$((passed + n))
ok "C test on the Cortex-M4F: $n checks"
m4_digest=$(grep -m1 '^digest: 0x' "$OUT/m4.txt" || true)
echo "C API, Cortex-M4F         $m4_digest"
[ "$reference" = "$m4_digest" ] || fail "the C API's result on the Cortex-M4F differs from the host's"
ok "Cortex-M4F digest equals the host's"

echo
echo "c_api: $passed passed, 0 failed"
