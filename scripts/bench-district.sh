#!/usr/bin/env bash
# The district benchmark (docs/district.md, "Benchmark"): a generated LoD2 district
# (examples/make_district.rs) counted as one tile holding the whole city (the one-process run),
# then in square tiles with a context radius, each tile in its own process, each timed with its
# peak resident memory (GNU time). Prints a line a run, then the tiles' largest peak against the
# whole run's.
#
#   scripts/bench-district.sh [OUT_DIR]
#
# Environment (defaults in brackets): COLUMNS [50] ROWS [40] (buildings, one a block), SEED [1],
# TILE [330] (metres; 330 cuts the default district into 4 × 4), CONTEXT [150], EPW [Golden CO's
# TMY3 from EnergyPlus's WeatherData: `SUNLIT_ENERGYPLUS=1 . scripts/setup.sh` sets $ENERGYPLUS],
# WHOLE [1] (0 skips the one-process run), ROOFTOPS [0] (1: a stair housing or chimney on every
# roof, make_district --rooftops: about 11 receivers a building instead of 6), and DISTRICT_ARGS, more
# `sunlit district` options for every run (e.g. "--days-per-year 27 --samples-per-day 19").
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-$(mktemp -d)}
mkdir -p "$out"
: "${COLUMNS:=50}" "${ROWS:=40}" "${SEED:=1}" "${ROOFTOPS:=0}" "${TILE:=330}" "${CONTEXT:=150}" "${EPW:=$(dirname "${ENERGYPLUS:-.}")/WeatherData/USA_CO_Golden-NREL.724666_TMY3.epw}" "${WHOLE:=1}"
read -r -a more <<<"${DISTRICT_ARGS:-}"
cargo build --release --quiet --bin sunlit --example make_district
city="$out/district.city.json"
rooftops=()
[ "$ROOFTOPS" = 1 ] && rooftops=(--rooftops)
./target/release/examples/make_district "$city" --columns "$COLUMNS" --rows "$ROWS" --seed "$SEED" "${rooftops[@]}" >&2
./target/release/sunlit info "$city" --json | python3 -c 'import json, sys; v = json.load(sys.stdin); print("city:", len(v["receivers"]), "receiver surfaces,", v["triangles"], "triangles")'
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"

# One tile K of a tiling: wall seconds, peak RSS (MiB) and the tile's own line.
tile() { # dir tile context k
  mkdir -p "$1"
  local log="$1/tile-$4.time"
  /usr/bin/time -f "%e %M" -o "$log" ./target/release/sunlit district "$city" --epw "$EPW" --tile "$2" --context "$3" \
    -o "$1" --index "$4" "${more[@]}" 2>"$1/tile-$4.err"
  read -r seconds kib <"$log"
  printf 'tile %-3s %8.1f s %8.1f MiB  %s\n' "$4" "$seconds" "$(echo "$kib / 1024" | bc -l)" "$(grep '^tile' "$1/tile-$4.err" | tail -1)"
  echo "$kib" >>"$1/peaks"
}

# How many tiles a tiling has: the refusal of an index past the last names the count.
tiles() { # tile context
  local probe; probe=$(mktemp -d)
  ./target/release/sunlit district "$city" --epw "$EPW" --tile "$1" --context "$2" -o "$probe" --index 999999 2>&1 \
    | sed -n 's/.*(\([0-9]*\) tiles:.*/\1/p' | head -1
  rm -rf "$probe"
}

n=$(tiles "$TILE" "$CONTEXT")
echo "== $n tiles of $TILE m, context $CONTEXT m"
for k in $(seq 0 $((n - 1))); do tile "$out/tiled" "$TILE" "$CONTEXT" "$k"; done
./target/release/sunlit district "$city" --epw "$EPW" --tile "$TILE" --context "$CONTEXT" -o "$out/tiled" --merge "${more[@]}"
if [ "$WHOLE" = 1 ]; then
  echo "== the whole city as one tile (--tile 100000 --context 100000)"
  tile "$out/whole" 100000 100000 0
fi
if [ "$WHOLE" = 1 ]; then
  python3 - "$out" <<'PY'
import sys
d = sys.argv[1]
whole = max(int(x) for x in open(f"{d}/whole/peaks"))
tiles = [int(x) for x in open(f"{d}/tiled/peaks")]
print(f"peak memory: whole {whole / 1024:.0f} MiB; tiles max {max(tiles) / 1024:.0f} MiB ({100 * max(tiles) / whole:.0f} %), "
      f"median {sorted(tiles)[len(tiles) // 2] / 1024:.0f} MiB")
PY
fi
echo "machine: load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
