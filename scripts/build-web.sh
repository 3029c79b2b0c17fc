#!/usr/bin/env bash
# Builds the browser bundle into www/pkg: the library as wasm (wgpu on WebGPU) with its
# wasm-bindgen glue, the viewer's shader, and the example model. Run by `npm start` and `npm test`.
set -euo pipefail
cd "$(dirname "$0")/.."
profile="${SUNLIT_WEB_PROFILE:-release}"
flag=(); [ "$profile" = release ] && flag=(--release)
# No default features: the CLI's fixtures (model generators) stay out of the bundle.
CARGO_PROFILE_RELEASE_DEBUG=0 cargo rustc --lib "${flag[@]}" --no-default-features --target wasm32-unknown-unknown --crate-type cdylib
rm -rf www/pkg.tmp && mkdir -p www/pkg.tmp
# The `name` section (function names, ~16% of the bytes) only serves a debugger: left out.
wasm-bindgen --target web --remove-name-section --remove-producers-section --out-dir www/pkg.tmp --out-name sunlit_wasm \
  "target/wasm32-unknown-unknown/$profile/sunlit.wasm"
cp shaders/viewer.wgsl www/pkg.tmp/viewer.wgsl
cp examples/office.glb www/pkg.tmp/office.glb
# Swap in whole so a failed build never leaves a half-written bundle being served.
rm -rf www/pkg && mv www/pkg.tmp www/pkg
echo "built www/pkg ($(du -h www/pkg/sunlit_wasm_bg.wasm | cut -f1) wasm)"
