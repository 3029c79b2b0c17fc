#!/usr/bin/env bash
# Every test: formatting, lints (no unwrap/expect in library code), then all cargo tests on the
# GPU (lavapipe here). GPU tests never skip: without an adapter they fail.
set -euo pipefail
cd "$(dirname "$0")/.."
SUNLIT_ENERGYPLUS=1 . scripts/setup.sh

cargo fmt --check
cargo clippy --all-targets --quiet -- -D warnings
# The same core builds for the browser (wgpu's WebGPU backend): keep it compiling.
if rustup target list --installed 2>/dev/null | grep -q wasm32-unknown-unknown; then
  cargo check --lib --quiet --target wasm32-unknown-unknown
else
  echo "skipped: wasm32 check (no wasm32-unknown-unknown target)" >&2
fi
cargo test --no-fail-fast 2>&1 | tee target/test.log
