#!/usr/bin/env bash
# Cargo's runner for thumbv7em-none-eabihf (.cargo/config.toml): runs a firmware ELF under QEMU's
# mps2-an386 (Cortex-M4F) with semihosting for output and exit code, and `-icount shift=3`: the
# emulated clock advances exactly 8 ns per executed instruction, so the 25 MHz SysTick counts one
# tick per 5 instructions, repeatably (`shift=0` works too, at one tick per 40 instructions).
#
#   examples/firmware/qemu-run.sh ELF [QEMU ARGUMENTS...]
#
# An ELF built with defmt (it has a `.defmt` section: `--features defmt`) writes defmt frames, not
# text; they are decoded with `defmt-print` (cargo install defmt-print --version 1.2.0 --locked).
# The exit status is the firmware's (QEMU passes on its semihosting exit code), or defmt-print's
# if the decoding fails.
set -euo pipefail

if [ $# -lt 1 ]; then
    echo "usage: $0 ELF [QEMU ARGUMENTS...]" >&2
    exit 2
fi
elf=$1
shift
qemu=(qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial none
    -semihosting-config enable=on,target=native -icount shift=3 -kernel "$elf" "$@")

sections() {
    local readelf
    for readelf in arm-none-eabi-readelf readelf; do
        if command -v "$readelf" >/dev/null; then
            "$readelf" -S -W "$1"
            return
        fi
    done
    echo "$0: no readelf to look into $1 (apt-get install binutils-arm-none-eabi)" >&2
    return 1
}

if ! sections "$elf" | grep -q ' \.defmt '; then
    exec "${qemu[@]}"
fi
if ! command -v defmt-print >/dev/null; then
    echo "$0: $elf logs through defmt; install the decoder:" >&2
    echo "    cargo install defmt-print --version 1.2.0 --locked" >&2
    exit 1
fi
"${qemu[@]}" | defmt-print -e "$elf" --log-format '{t} {L} {s}'
