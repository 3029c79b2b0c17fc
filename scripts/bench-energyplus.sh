#!/usr/bin/env bash
# EnergyPlus's own PolygonClipping vs sunlit + EnergyPlus with sunlit's fractions, on the one-zone
# office with N louvres (annual, Timestep 4, Golden CO). Prints the seconds of each and the ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
SUNLIT_ENERGYPLUS=1 . scripts/setup.sh
cargo build --release --quiet --bin sunlit --example make_office_idf
epw="$(dirname "$ENERGYPLUS")/WeatherData/USA_CO_Golden-NREL.724666_TMY3.epw"
out=$(mktemp -d)
seconds() { local s=$(date +%s.%N); "$@" >/dev/null 2>&1; echo "$(date +%s.%N) - $s" | bc; }
printf '%-9s %14s %12s %14s %12s %8s\n' louvres "E+ clipping" "sunlit" "E+ with CSV" "sunlit+E+" ratio
for n in ${LOUVRES:-10 100}; do
  d="$out/$n"; mkdir -p "$d"
  ./target/release/examples/make_office_idf "$d/clip.idf" --louvres "$n" >/dev/null
  # Periodic daily updates for EnergyPlus's own run, as in the paper's case studies.
  sed -i 's/  Timestep,                !- Shading Calculation Update Frequency Method/  Periodic,                !- Shading Calculation Update Frequency Method/; s/  Yes;                     !- Output External/  No;                      !- Output External/' "$d/clip.idf"
  clip=$(seconds "$ENERGYPLUS" -w "$epw" -d "$d/clip" "$d/clip.idf")
  ./target/release/examples/make_office_idf "$d/model.idf" --louvres "$n" --no-shading-calculation >/dev/null
  ours=$(seconds ./target/release/sunlit annual "$d/model.idf" --epw "$epw" -o "$d/shading.csv" --idf-out "$d/hooked.idf")
  hooked=$(seconds "$ENERGYPLUS" -w "$epw" -d "$d/hooked" "$d/hooked.idf")
  total=$(echo "$ours + $hooked" | bc)
  printf '%-9s %12.1f s %10.2f s %12.1f s %10.1f s %7.1fx\n' "$n" "$clip" "$ours" "$hooked" "$total" "$(echo "$clip / $total" | bc -l)"
done
