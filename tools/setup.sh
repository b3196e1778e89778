#!/usr/bin/env bash
# Installs what the embedded checks need on a fresh machine that has only a
# rustup toolchain (RUSTUP_AUTO_INSTALL=0: rust-toolchain files install
# nothing, so this script does it):
# - the thumbv7em-none-eabihf (Cortex-M4F firmware, no-panic check) and
#   x86_64-unknown-none (kernel cross-build) targets;
# - llvm-tools (llvm-size, llvm-nm, llvm-objdump for the size report and the
#   no-panic diagnostics, under $(rustc --print sysroot)/lib/rustlib/*/bin);
# - qemu-system-arm (runs the firmware) and valgrind (callgrind instruction
#   counts of `palpate budget` and its test; memcheck of the C ABI's test),
#   from apt-get, with sudo when not root;
# - the C toolchains of the C ABI's checks (tools/ffi-check.sh,
#   tools/firmware-check.sh --c): the host's C compiler and make (gcc, make)
#   and the Cortex-M one with its C library (gcc-arm-none-eabi,
#   libnewlib-arm-none-eabi: newlib-nano), from apt-get;
# - cmake and libclang-dev (apt-get): tools/cycles builds the Unicorn
#   emulator's C with cmake and its Rust bindings with bindgen (libclang);
# - cargo-deny (licenses, bans, sources, advisories; `deny.toml`), built from
#   crates.io with `cargo install --locked` (about 3-5 min the first time).
# Idempotent; a fast no-op when all is present. cargo-deny builds (CPU)
# while apt-get downloads and unpacks (network, disk), side by side, when a C
# compiler is there already (its `ring` dependency compiles C); else after.
#
#   tools/setup.sh               everything
#   tools/setup.sh --no-deny     everything but cargo-deny
#   tools/setup.sh --deny-only   cargo-deny only (after the rest: it needs a C compiler)
#
# .ci/run takes the last two apart: it builds cargo-deny at the lowest CPU
# priority beside its other steps, on the cores they leave idle.
set -euo pipefail
deny=yes
rest=yes
case "${1:-}" in
    "") ;;
    --no-deny) deny=no ;;
    --deny-only) rest=no ;;
    *) echo "usage: tools/setup.sh [--no-deny | --deny-only]" >&2; exit 2 ;;
esac
install_deny() { cargo install cargo-deny --locked --version 0.20.2; }
have_deny() { command -v cargo-deny >/dev/null; }
if [ "$rest" = no ]; then
    have_deny || install_deny
    cargo deny --version
    exit 0
fi

rustup target add thumbv7em-none-eabihf x86_64-unknown-none
rustup component add llvm-tools rustfmt clippy
deny_pid=""
if [ "$deny" = yes ] && ! have_deny && command -v cc >/dev/null; then
    install_deny &
    deny_pid=$!
fi

missing=()
command -v qemu-system-arm >/dev/null || missing+=(qemu-system-arm)
command -v valgrind >/dev/null || missing+=(valgrind)
command -v cmake >/dev/null || missing+=(cmake)
ldconfig -p 2>/dev/null | grep -q 'libclang[-0-9.]*\.so\b' || missing+=(libclang-dev)
command -v cc >/dev/null || missing+=(gcc)
command -v make >/dev/null || missing+=(make)
command -v arm-none-eabi-gcc >/dev/null || missing+=(gcc-arm-none-eabi)
# newlib-nano: the compiler prints the bare name when it has no such library.
if ! command -v arm-none-eabi-gcc >/dev/null ||
    [ "$(arm-none-eabi-gcc -print-file-name=libc_nano.a)" = libc_nano.a ]; then
    missing+=(libnewlib-arm-none-eabi)
fi
if [ ${#missing[@]} -gt 0 ]; then
    sudo=""
    if [ "$(id -u)" != 0 ]; then
        if ! command -v sudo >/dev/null; then
            echo "setup: ${missing[*]} missing and installing needs root (no sudo here)" >&2
            exit 1
        fi
        sudo="sudo"
    fi
    $sudo apt-get update -qq
    $sudo env DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
if [ -n "$deny_pid" ]; then
    wait "$deny_pid"
elif [ "$deny" = yes ] && ! have_deny; then
    install_deny
fi
qemu-system-arm --version | head -1
valgrind --version
cmake --version | head -1
arm-none-eabi-gcc --version | head -1
if [ "$deny" = yes ]; then
    cargo deny --version
fi
