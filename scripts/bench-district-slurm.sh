#!/usr/bin/env bash
# The 2,000-building district on Slurm's tiles (docs/district.md, "2,000 buildings on Slurm's
# tiles"): on a running Slurm cluster (SLURM_CONF set; tests/slurm.rs starts a one-node one the
# same way), with the exact engine and every other default,
#   1. the whole city as one process (`--tile 100000 --context 100000 --index 0`) under
#      /usr/bin/time -v, here;
#   2. 16 tiles of 330 m with a 150 m context, an array task a tile, each the task command
#      `sunlit district … --index K` under /usr/bin/time -v (a Slurm without accounting storage
#      has no sacct MaxRSS), for the tiles' peaks against the whole run's;
#   3. the same 16 tiles with a context reaching across the city (100 km: the radius that holds
#      every shadow), submitted by `sunlit district --slurm` itself (an array task a tile and the
#      merge job), for the rows against the whole run's (scripts/compare-district.py, ≤ 1e-9).
# Every run is started under `nice -n 5` (run slurmd under it too: its tasks inherit it).
#
#   SLURM_CONF=… scripts/bench-district-slurm.sh OUT_DIR [SUNLIT]
#
# OUT_DIR gets district.city.json (make_district --columns 50 --rows 40 --seed 1, 11,905
# receivers), whole/, tiled-150/ (time/tile-K.time), tiled-full/. Waits for the jobs, then prints
# both comparisons. EPW defaults to Golden CO's TMY3 ($ENERGYPLUS/../WeatherData).
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "$1")
sunlit=$(realpath "${2:-target/release/sunlit}")
: "${SLURM_CONF:?set SLURM_CONF to the slurm.conf of a running cluster}"
: "${EPW:=$(dirname "${ENERGYPLUS:-.}")/WeatherData/USA_CO_Golden-NREL.724666_TMY3.epw}"
epw=$(realpath "$EPW")
mkdir -p "$out/tiled-150/time"
city="$out/district.city.json"
[ -s "$city" ] || { cargo build --release --quiet --example make_district &&
  ./target/release/examples/make_district "$city" --columns 50 --rows 40 --seed 1 >&2; }
common=(district "$city" --epw "$epw" --engine exact)
echo "load at start: $(uptime)"

# 2. the 150 m tiles, each under GNU time, as an array of the task command.
cmd="/usr/bin/time -v -o $out/tiled-150/time/tile-\$SLURM_ARRAY_TASK_ID.time $sunlit ${common[*]} --tile 330 --context 150 -o $out/tiled-150 --index \$SLURM_ARRAY_TASK_ID"
j150=$(sbatch --parsable --job-name=tile150 --array=0-15 -o "$out/tiled-150/time/%a.out" --wrap "$cmd")
# 3. the tiles with every caster in context, by sunlit's own --slurm (array and merge job).
"$sunlit" "${common[@]}" --tile 330 --context 100000 -o "$out/tiled-full" --slurm | tee "$out/tiled-full.submit"
jobs=$(sed -n 's/^\(array\|merge\) job \([0-9]*\):.*/\2/p' "$out/tiled-full.submit" | paste -sd,)
# 1. the whole city as one process, here.
nice -n 5 /usr/bin/time -v -o "$out/whole.time" "$sunlit" "${common[@]}" --tile 100000 --context 100000 -o "$out/whole" --index 0 2>"$out/whole.err"
until [ -z "$(squeue -h -j "$j150,$jobs" 2>/dev/null)" ]; do sleep 10; done
echo "load at end: $(uptime)"
grep -E 'Elapsed|User time|System time|Maximum resident' "$out/whole.time"
grep '^tile' "$out/whole.err"
scripts/compare-district.py peaks "$out/whole.time" "$out"/tiled-150/time/tile-*.time || true
scripts/compare-district.py rows "$out/whole" "$out/tiled-full"
