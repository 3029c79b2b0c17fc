#!/usr/bin/env bash
# Every test: formatting, lints (no unwrap/expect in library code), all cargo tests on the GPU
# (lavapipe here), then the browser: the wasm tests in headless Chromium's WebGPU (SwiftShader)
# and the page end to end with Playwright, then the JS API under Node on Dawn (tests/node/). GPU
# tests never skip: without an adapter they fail (tests/node/ skips only where Dawn finds none).
set -euo pipefail
cd "$(dirname "$0")/.."
SUNLIT_ENERGYPLUS=1 SUNLIT_RADIANCE=1 SUNLIT_CITY=1 SUNLIT_PV=1 SUNLIT_WEB=1 SUNLIT_BROWSER=1 . scripts/setup.sh

# A full run's builds and venvs take about 6 GiB; a full disk otherwise shows up late, as a
# linker's bus error, so say how much there is up front.
free_gib=$(df -Pk . | awk 'NR==2 {print int($4 / 1048576)}')
echo "sunlit test: ${free_gib} GiB free on $(df -P . | awk 'NR==2 {print $6}')"
[ "$free_gib" -ge 8 ] || echo "sunlit test: warning: under 8 GiB free; the build may run out of disk" >&2

cargo fmt --check
cargo clippy --all-targets --quiet -- -D warnings
cargo clippy --lib --quiet --target wasm32-unknown-unknown -- -D warnings
# The fuzz targets are their own workspace (no build of the crate compiles them): check they still
# build against the library's API, so a move in the library cannot silently break them.
cargo check --quiet --manifest-path fuzz/Cargo.toml --target-dir target/fuzz-check
mkdir -p target
status=0
cargo test --no-fail-fast 2>&1 | tee target/test.log || status=1
# The library's counting pass on the browser's WebGPU (the bin is native-only, hence no features).
cargo test --target wasm32-unknown-unknown --no-default-features --test web 2>&1 | tee target/test-web.log || status=1
# The page: builds www/pkg, then drives it; the 3D view lands in target/artifacts/page.png.
scripts/build-web.sh
# tests/browser/npm.test.mjs packs the npm package (scripts/pack-npm.sh, reusing www/pkg) and
# builds a fresh Vite app with it (npm install of three + vite: needs the npm registry).
node --test tests/browser/ 2>&1 | tee target/test-browser.log || status=1
# The same bundle and JS API under Node on Dawn's WebGPU (npm `webgpu`; SwiftShader's Vulkan driver
# here, since Dawn refuses lavapipe 22.3): skips, saying why, only where Dawn finds no adapter.
node --test tests/node/ 2>&1 | tee target/test-node.log || status=1
exit $status
