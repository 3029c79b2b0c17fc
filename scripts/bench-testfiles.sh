#!/usr/bin/env bash
# sunlit's share of an annual EnergyPlus run on EnergyPlus's own test files
# (tests/energyplus_testfiles/, Chicago O'Hare TMY3): the model as written, made a weather-file
# run; `sunlit annual` on it (CSV and hooked model); EnergyPlus on the hooked model. Each figure is
# the median of RUNS (default 5) wall-clock runs taken in turn. FILES= overrides the list.
set -euo pipefail
cd "$(dirname "$0")/.."
SUNLIT_ENERGYPLUS=1 . scripts/setup.sh
cargo build --release --quiet --bin sunlit
epw="$(dirname "$ENERGYPLUS")/WeatherData/USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw"
runs=${RUNS:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
seconds() { local s=$(date +%s.%N); "$@" >/dev/null 2>&1; echo "$(date +%s.%N) - $s" | bc; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
printf '%-28s %12s %12s %14s %16s\n' file "E+ annual" "sunlit" "E+ hooked" "sunlit / E+"
for f in ${FILES:-4ZoneWithShading_Simple_1 5ZoneAirCooled}; do
  d="$out/$f"; mkdir -p "$d"
  # Design days only → the weather file only (5ZoneAirCooled already runs its weather file).
  perl -0pe 's/Yes,(\s+!- Run Simulation for Sizing Periods\s+)No,(\s+!- Run Simulation for Weather File Run Periods)/No,$1Yes,$2/' \
    "tests/energyplus_testfiles/$f.idf" > "$d/model.idf"
  grep -qE '^\s*Yes,\s+!- Run Simulation for Weather File Run Periods' "$d/model.idf" || { echo "$f: not a weather-file run" >&2; exit 1; }
  eplus=(); ours=(); hooked=()
  for _ in $(seq "$runs"); do
    eplus+=("$(seconds "$ENERGYPLUS" -w "$epw" -d "$d/eplus" "$d/model.idf")")
    ours+=("$(seconds ./target/release/sunlit annual "$d/model.idf" --epw "$epw" -o "$d/shading.csv" --idf-out "$d/hooked.idf")")
    hooked+=("$(seconds "$ENERGYPLUS" -w "$epw" -d "$d/hooked" "$d/hooked.idf")")
  done
  e=$(printf '%s\n' "${eplus[@]}" | median); s=$(printf '%s\n' "${ours[@]}" | median); h=$(printf '%s\n' "${hooked[@]}" | median)
  grep -q "EnergyPlus Completed Successfully" "$d/hooked/eplusout.err" || { echo "$f: the hooked run did not complete" >&2; exit 1; }
  printf '%-28s %10.3f s %10.3f s %12.3f s %14.1f %%\n' "$f" "$e" "$s" "$h" "$(echo "100 * $s / $e" | bc -l)"
done
