#!/usr/bin/env bash
# Times `sunlit annual` at 27×19 (Golden CO, 4 timesteps per hour, 512²) on the street-trees
# model (a three-storey facade behind five deciduous trees, `examples/make_trees.rs`) at the
# Blaas case's smallest and largest leaf counts, and the same trees counted as evergreen (one
# regime), for the cost of the leaf regimes. Usage: scripts/bench-foliage.sh [LEAVES...]
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/setup.sh
cargo build --release --quiet --bin sunlit --example make_trees
out=$(mktemp -d)
for leaves in "${@:-35905 233866}"; do
  for leaves in $leaves; do
    ./target/release/examples/make_trees "$leaves" "$out/trees-$leaves.glb"
    for mode in deciduous evergreen; do
      extra=(); [ "$mode" = evergreen ] && extra=(--evergreen)
      start=$(date +%s.%N)
      log=$(./target/release/sunlit annual "$out/trees-$leaves.glb" --location 39.74,-105.18,-7 --timesteps-per-hour 4 \
        --days-per-year 27 --samples-per-day 19 "${extra[@]}" -o "$out/$leaves-$mode.csv" 2>&1 | tail -1)
      end=$(date +%s.%N)
      printf '%7s leaves %-10s %8.1f s  %s\n' "$leaves" "$mode" "$(echo "$end - $start" | bc)" "${log##*; }"
    done
  done
done
rm -rf "$out"
