#!/usr/bin/env bash
# The main job: build the browser bundle and serve the page on http://127.0.0.1:${PORT:-8080}
# with the example office one click away. The CLI: `cargo run --release -- --help`.
set -euo pipefail
cd "$(dirname "$0")/.."
SUNLIT_WEB=1 . scripts/setup.sh

scripts/build-web.sh
echo "open the page, press 'Load the example office', then Compute; or drop your own .glb/.idf there."
exec node scripts/serve.mjs
