#!/usr/bin/env bash
# auto against the better of its two engines on each bench model: `sunlit bench MODEL --views N`
# with --engine exact, gpu and auto (auto read from a profile its own first run measured and
# pinned, as a device keeps its profile). Prints each engine's seconds for all of the model's
# 27×19 views (extrapolated from an even spread of N: VIEWS=, default 1000) with the once-a-run
# costs it paid (GPU start-up and upload, calibration) added, each the median of RUNS runs
# (default 3) taken in turn, and auto's ratio to the better of the two. MODELS= overrides the
# list; RESOLUTION= the tile side (512).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --bin sunlit
models=${MODELS:-blaas-self blaas-louvres blaas-buildings blaas-trees-winter blaas-trees-summer nyt-self nyt-flat}
views=${VIEWS:-1000}
resolution=${RESOLUTION:-512}
profiles=$(mktemp -d)
trap 'rm -rf "$profiles"' EXIT
total='.estimated_seconds_all_views + (.gpu_startup_seconds // 0) + (.calibration_seconds // 0)'
runs=${RUNS:-3}
# sunlit's stderr (the adapter line) is shown only when it fails.
bench() { ./target/release/sunlit bench "$1" --views "$views" --resolution "$resolution" "${@:2}" 2>"$profiles/stderr" || { cat "$profiles/stderr" >&2; return 1; }; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
printf '%-20s %10s %10s %10s %12s %s\n' model exact gpu auto auto/best "auto's split (exact/gpu views)"
for m in $models; do
  bench "$m" --engine-profile "$profiles/$m.json" >/dev/null
  exact=(); gpu=(); auto=()
  for _ in $(seq "$runs"); do
    exact+=("$(bench "$m" --engine exact | jq "$total")")
    gpu+=("$(bench "$m" --engine gpu | jq "$total")")
    json=$(bench "$m" --engine-profile "$profiles/$m.json")
    auto+=("$(jq "$total" <<<"$json")")
  done
  e=$(printf '%s\n' "${exact[@]}" | median); g=$(printf '%s\n' "${gpu[@]}" | median); a=$(printf '%s\n' "${auto[@]}" | median)
  split=$(jq -r '"\(.exact_views)/\(.gpu_views)"' <<<"$json")
  ratio=$(jq -n --argjson a "$a" --argjson e "$e" --argjson g "$g" '$a / ([$e, $g] | min) * 100 | round / 100')
  printf '%-20s %9.2fs %9.2fs %9.2fs %11sx %s\n' "$m" "$e" "$g" "$a" "$ratio" "$split"
done
