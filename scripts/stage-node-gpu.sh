#!/usr/bin/env bash
# Makes the folder to carry to a GPU machine with no Node and no package registry, for
# `CARRY=.node-gpu scripts/bench-node-gpu.sh` there, and prints each part's size and the total with
# the working tree against the 64 MiB a run may carry. Parts (.node-gpu/, git-ignored):
# - debs/: Debian 12's Node 18 (nodejs, libnode108 and the libraries and JavaScript packages it
#   needs that a bare machine may lack) and the Vulkan loader (libvulkan1), by `apt-get download`;
# - webgpu.tgz: the npm `webgpu` package's linux-x64 build only (dawn.node) with its two runtime
#   dependencies (debug, ms), from node_modules (npm ci);
# - pkg.tgz: the wasm bundle, www/pkg (scripts/build-web.sh, run here if it is missing);
# - sunlit.gz: the stripped release binary (SUNLIT=, default target/release/sunlit, built if missing).
# gzip, not xz: the far side unpacks with what every Debian or Ubuntu has.
set -euo pipefail
cd "$(dirname "$0")/.."
stage=.node-gpu
rm -rf "$stage" && mkdir -p "$stage/debs"
node_version=18.20.4+dfsg-1~deb12u3
(cd "$stage/debs" && apt-get download -qq "nodejs=$node_version" "libnode108=$node_version" libicu72 libssl3 libuv1 libc-ares2 \
  libbrotli1 libnghttp2-14 node-acorn node-cjs-module-lexer node-undici node-busboy node-xtend libvulkan1 2>&1 | grep -v '^W: Download is performed unsandboxed' || true)
[ -f node_modules/webgpu/dist/linux-x64/dawn.node ] || { echo "stage-node-gpu: node_modules/webgpu is missing: npm ci" >&2; exit 1; }
tar czf "$stage/webgpu.tgz" node_modules/webgpu/package.json node_modules/webgpu/index.js node_modules/webgpu/dist/linux-x64 \
  node_modules/debug node_modules/ms
[ -f www/pkg/sunlit_wasm_bg.wasm ] || bash scripts/build-web.sh
tar czf "$stage/pkg.tgz" www/pkg
B=${SUNLIT:-target/release/sunlit}
[ -x "$B" ] || cargo build --release --quiet --bin sunlit
strip -o "$stage/sunlit" "$B" && gzip -6 "$stage/sunlit"

mib() { awk -v b="$1" 'BEGIN { printf "%.1f", b / 1048576 }'; }
tree=$(git ls-files -z | xargs -0 stat -c %s 2>/dev/null | awk '{ s += $1 } END { print s }')
total=$tree
echo "working tree (git ls-files): $(mib "$tree") MiB"
for part in "$stage"/debs/*.deb "$stage"/webgpu.tgz "$stage"/pkg.tgz "$stage"/sunlit.gz; do
  size=$(stat -c %s "$part"); total=$((total + size))
  echo "$(basename "$part"): $(mib "$size") MiB"
done
echo "total: $(mib "$total") MiB of 64 MiB"
[ "$total" -le $((64 * 1048576)) ] || { echo "stage-node-gpu: over the 64 MiB a run may carry" >&2; exit 1; }
