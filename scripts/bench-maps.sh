#!/usr/bin/env bash
# Benchmarks of `sunlit map` (docs/maps.md):
#  1. the Blaas-like louvres at a 0.1 m grid (~250k points) x every sun-up hour of a year
#     (target <= 30 s, <= 2 GiB on 2 cores), RUNS whole-process timings with /usr/bin/time -v;
#  2. nyt-flat's facades at a 1 m grid, annual hourly (target <= 10 min);
#  3. Ladybug's DirectSunStudy (ladybug-radiance + pyradiance, in a venv under $VENV) on the same
#     0.5 m points as sunlit, with the same sun vectors: time and per point agreement.
#
#   scripts/bench-maps.sh               # all three
#   PARTS="1" scripts/bench-maps.sh     # only the first
#   RUNS=3 VENV=/tmp/lbvenv scripts/bench-maps.sh
set -euo pipefail
cd "$(dirname "$0")/.."
PARTS=${PARTS:-"1 2 3"}
RUNS=${RUNS:-3}
VENV=${VENV:-/tmp/sunlit-ladybug-venv}
OUT=${OUT:-/tmp/sunlit-bench-maps}
GOLDEN="39.74,-105.18,-7"
mkdir -p "$OUT"
cargo build --release --quiet --bin sunlit
bin=target/release/sunlit

for part in $PARTS; do
  case $part in
    1)
      $bin bench blaas-louvres --write "$OUT/blaas-louvres.glb"
      $bin map "$OUT/blaas-louvres.glb" --grid 0.1 --location "$GOLDEN" -o "$OUT/blaas-0.1.csv" --json | tee "$OUT/blaas-0.1.json"
      for _ in $(seq "$RUNS"); do
        /usr/bin/time -f '%e s wall, %U s user, %S s system, %M KB peak' \
          timeout 900 $bin map "$OUT/blaas-louvres.glb" --grid 0.1 --location "$GOLDEN" -o "$OUT/blaas-0.1.csv"
      done
      ;;
    2)
      $bin bench nyt-flat --write "$OUT/nyt-flat.glb"
      $bin map "$OUT/nyt-flat.glb" --grid 1 --location "40.71,-74.0,-5" -o "$OUT/nyt-1.csv" --json | tee "$OUT/nyt-1.json"
      ;;
    3)
      [ -x "$VENV/bin/python" ] || { python3 -m venv "$VENV" && "$VENV/bin/pip" install -q ladybug-radiance==0.2.12 pyradiance==1.3.1; }
      [ -f "$OUT/blaas-louvres.glb" ] || $bin bench blaas-louvres --write "$OUT/blaas-louvres.glb"
      $bin map "$OUT/blaas-louvres.glb" --grid 0.5 --location "$GOLDEN" -o "$OUT/blaas-0.5.csv" --json | tee "$OUT/blaas-0.5.json"
      # Paired: Ladybug then sunlit, RUNS times, so both see the same load; the median of the
      # per-pair wall-time ratios is the speed-up (sunlit writes its points to another file so
      # Ladybug always reads the first run's).
      for run in $(seq "$RUNS"); do
        /usr/bin/time -f "ladybug $run %e s wall %U+%S s cpu" "$VENV/bin/python" scripts/bench_maps_ladybug.py \
          "$OUT/blaas-louvres.glb" "$OUT/blaas-0.5.csv" 39.74 -105.18 -7 2>>"$OUT/pairs.txt" | tee "$OUT/ladybug-0.5-$run.json"
        /usr/bin/time -f "sunlit $run %e s wall %U+%S s cpu" $bin map "$OUT/blaas-louvres.glb" --grid 0.5 \
          --location "$GOLDEN" -o "$OUT/blaas-0.5-again.csv" 2>>"$OUT/pairs.txt"
      done
      grep -E '^(ladybug|sunlit) ' "$OUT/pairs.txt" | tail -n $((2 * RUNS))
      ;;
  esac
done
