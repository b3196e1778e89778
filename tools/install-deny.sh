#!/usr/bin/env bash
# Installs cargo-deny (licenses, bans, sources, advisories; `deny.toml`) from
# crates.io with `cargo install --locked` when it is missing: about 3-5 min
# of compiling the first time, a no-op after. Called by tools/setup.sh and,
# beside the other steps, by .ci/run.
set -euo pipefail
if ! command -v cargo-deny >/dev/null; then
    cargo install cargo-deny --locked --version 0.20.2
fi
cargo deny --version
