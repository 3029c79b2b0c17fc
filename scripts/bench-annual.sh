#!/usr/bin/env bash
# Times `sunlit annual` on the example office (all 10 receivers, Golden CO, 4 timesteps per hour):
# the sampling plans of the paper's tables, pure spline and refined, against --dense.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/setup.sh
cargo build --release --quiet --bin sunlit
out=$(mktemp -d)
run() { # label, args...
  local label=$1; shift
  local start=$(date +%s.%N)
  local log; log=$(./target/release/sunlit annual examples/office.glb --location 39.74,-105.18,-7 "$@" -o "$out/$label.csv" 2>&1 | tail -1)
  local end=$(date +%s.%N)
  printf '%-22s %8.1f s  %s\n' "$label" "$(echo "$end - $start" | bc)" "${log##*; }"
}
for plan in "14 15" "27 19" "53 53"; do
  set -- $plan
  run "${1}x${2}-spline" --days-per-year "$1" --samples-per-day "$2" --refine 1
  run "${1}x${2}-refined" --days-per-year "$1" --samples-per-day "$2"
done
run dense --dense
python3 - "$out" <<'PY'
import csv, sys, os
d = sys.argv[1]
dense = list(csv.reader(open(os.path.join(d, "dense.csv"))))
for name in sorted(f for f in os.listdir(d) if f != "dense.csv"):
    rows = list(csv.reader(open(os.path.join(d, name))))
    errs = [abs(float(a) - float(b)) for ra, rb in zip(rows[1:], dense[1:]) for a, b in zip(ra[1:-1], rb[1:-1]) if float(a) > 0 or float(b) > 0]
    rms = (sum(e * e for e in errs) / len(errs)) ** 0.5
    print(f"{name[:-4]:<22} vs dense: RMS {rms:.4f}, max {max(errs):.4f} over {len(errs)} lit values")
PY
