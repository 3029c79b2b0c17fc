#!/usr/bin/env bash
# auto against the better of its two engines on each bench model: `sunlit bench MODEL --views N`
# with --engine exact, gpu and auto (auto read from a profile its own first run measured and
# pinned, as a device keeps its profile). Prints each engine's seconds for all of the model's
# 27×19 views (extrapolated from an even spread of N: VIEWS=, default 1000) and auto's ratio to
# the better of the two, each with the once-a-run costs it paid (GPU start-up, calibration)
# added. MODELS= overrides the list; RESOLUTION= the tile side (512).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --bin sunlit
models=${MODELS:-blaas-self blaas-louvres blaas-buildings blaas-trees-winter blaas-trees-summer nyt-self nyt-flat}
views=${VIEWS:-1000}
resolution=${RESOLUTION:-512}
profiles=$(mktemp -d)
trap 'rm -rf "$profiles"' EXIT
total='.estimated_seconds_all_views + .gpu_startup_seconds + .calibration_seconds'
seconds() { ./target/release/sunlit bench "$1" --views "$views" --resolution "$resolution" "${@:2}" | jq "$total"; }
printf '%-20s %10s %10s %10s %12s %s\n' model exact gpu auto auto/best "auto's split (exact/gpu views)"
for m in $models; do
  exact=$(seconds "$m" --engine exact)
  gpu=$(seconds "$m" --engine gpu)
  ./target/release/sunlit bench "$m" --views "$views" --resolution "$resolution" --engine-profile "$profiles/$m.json" >/dev/null
  json=$(./target/release/sunlit bench "$m" --views "$views" --resolution "$resolution" --engine-profile "$profiles/$m.json")
  auto=$(jq "$total" <<<"$json")
  split=$(jq -r '"\(.exact_views)/\(.gpu_views)"' <<<"$json")
  ratio=$(jq -n --argjson a "$auto" --argjson e "$exact" --argjson g "$gpu" '$a / ([$e, $g] | min) * 100 | round / 100')
  printf '%-20s %9.2fs %9.2fs %9.2fs %11sx %s\n' "$m" "$exact" "$gpu" "$auto" "$ratio" "$split"
done
