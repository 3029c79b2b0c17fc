#!/usr/bin/env bash
# The main job: build, make the example office model, and show its receivers and sunlit fractions.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/setup.sh

cargo build --release --quiet --bin sunlit --example make_office
./target/release/examples/make_office examples/office.glb >/dev/null
./target/release/sunlit info examples/office.glb
./target/release/sunlit fraction examples/office.glb --sun "${SUN:-200,35}"
mkdir -p out
./target/release/sunlit annual examples/office.glb --location 39.74,-105.18,-7 -o out/office-shading.csv
echo "EnergyPlus CSV (Schedule:File:Shading layout): out/office-shading.csv"
