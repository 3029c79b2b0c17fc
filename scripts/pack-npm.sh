#!/usr/bin/env bash
# `npm run pack`: the npm package `sunlit` as exactly one tarball in target/npm/. Builds the wasm
# bundle (scripts/build-web.sh), stages what ships in target/npm/pkg (the ES modules, the wasm
# and its glue, the types; no tests, fixtures, source maps or install scripts), then npm pack.
# SUNLIT_PACK_DIR puts the staging folder and the tarball elsewhere (a test packing beside another).
set -euo pipefail
cd "$(dirname "$0")/.."
[ "${SUNLIT_PACK_SKIP_BUILD:-0}" = 1 ] || bash scripts/build-web.sh
out="${SUNLIT_PACK_DIR:-target/npm}"
version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -n1)
rm -rf "$out" && mkdir -p "$out/pkg/pkg"
cp www/sunlit.js www/device.js www/colour.js www/map.js www/three.js www/engine-worker.js www/pool.js www/clip-worker.js www/profiles.js www/sunlit.d.ts www/three.d.ts "$out/pkg/"
cp www/pkg/sunlit_wasm.js www/pkg/sunlit_wasm_bg.wasm "$out/pkg/pkg/"
cp www/npm-readme.md "$out/pkg/README.md"
cat > "$out/pkg/package.json" <<JSON
{
  "name": "sunlit",
  "version": "$version",
  "description": "Sunlit fractions and direct irradiation of building surfaces on the browser's WebGPU (Rust + wgpu, compiled to wasm)",
  "license": "MIT OR Apache-2.0",
  "type": "module",
  "sideEffects": false,
  "main": "./sunlit.js",
  "types": "./sunlit.d.ts",
  "exports": {
    ".": { "types": "./sunlit.d.ts", "default": "./sunlit.js" },
    "./three": { "types": "./three.d.ts", "default": "./three.js" },
    "./worker": "./engine-worker.js",
    "./package.json": "./package.json"
  },
  "files": ["*.js", "*.d.ts", "pkg/sunlit_wasm.js", "pkg/sunlit_wasm_bg.wasm", "README.md"],
  "peerDependencies": { "three": ">=0.150.0" },
  "peerDependenciesMeta": { "three": { "optional": true } }
}
JSON
(cd "$out" && npm pack ./pkg --pack-destination . --silent >/dev/null)
ls "$out"/*.tgz
echo "packed $(ls "$out"/*.tgz) ($(du -k "$out"/*.tgz | cut -f1) KiB)"
