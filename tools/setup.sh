#!/usr/bin/env bash
# Installs what the embedded checks need on a fresh machine that has only a
# rustup toolchain (RUSTUP_AUTO_INSTALL=0: rust-toolchain files install
# nothing, so this script does it). Idempotent; a no-op when all is present.
set -euo pipefail

rustup target add thumbv7em-none-eabihf x86_64-unknown-none
rustup component add llvm-tools

if ! command -v qemu-system-arm >/dev/null; then
    sudo=""
    if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends qemu-system-arm
fi
qemu-system-arm --version | head -1
