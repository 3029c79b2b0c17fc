#!/usr/bin/env bash
# The seed's Tables 2 and 4: pre-processing time of the generated Blaas-like and NYT-like models
# over its sampling grid (days per year × samples per day), printed as markdown beside the
# paper's GPU figures (2011, GTX 570). JSON lines of every run go to $OUT (bench-grid.jsonl).
#
#   scripts/bench-grid.sh                      # every model, the paper's six plans
#   MODELS="blaas-louvres" PLANS="27x19" scripts/bench-grid.sh
#   VIEWS=2000 scripts/bench-grid.sh           # time 2,000 views a run and extrapolate (NYT)
#   RESOLUTION=256 TIMEOUT=900 scripts/bench-grid.sh
set -euo pipefail
cd "$(dirname "$0")/.."
runtime="/tmp/sunlit-runtime-${USER:-$(id -un)}"
mkdir -p -m 700 "$runtime"
export XDG_RUNTIME_DIR="$runtime"

MODELS=${MODELS:-"blaas-self blaas-louvres blaas-buildings blaas-trees-summer nyt-self nyt-flat nyt-rods nyt-blocks"}
PLANS=${PLANS:-"14x15 14x53 27x19 27x53 53x15 53x53"}
RESOLUTION=${RESOLUTION:-512}
TIMEOUT=${TIMEOUT:-1800}
OUT=${OUT:-bench-grid.jsonl}
views=()
[ -n "${VIEWS:-}" ] && views=(--views "$VIEWS")

cargo build --release --quiet
: > "$OUT"
for model in $MODELS; do
  for plan in $PLANS; do
    # The paper's NYT table has 51 samples a day where the Blaas one has 53.
    [[ $model == nyt-* ]] && plan=${plan/x53/x51}
    if ! timeout "$TIMEOUT" target/release/sunlit bench "$model" --samples "$plan" --resolution "$RESOLUTION" "${views[@]}" >> "$OUT"; then
      echo "{\"model\":\"$model\",\"samples\":\"$plan\",\"failed\":true}" >> "$OUT"
    fi
  done
done

python3 - "$OUT" <<'EOF'
import json, sys
# The paper's pre-processing times (Blaas in seconds, NYT in minutes).
paper = {
    "blaas-self": (1, [0.08, 0.29, 0.20, 0.56, 0.32, 1.14]),
    "blaas-louvres": (1, [0.11, 0.39, 0.28, 0.76, 0.42, 1.59]),
    "blaas-buildings": (1, [0.12, 0.41, 0.28, 0.79, 0.44, 1.63]),
    "blaas-trees-summer": (1, [2.05, 7.38, 5.38, 14.76, 8.12, 29.39]),
    "blaas-trees-winter": (1, [2.05, 7.38, 5.38, 14.76, 8.12, 29.39]),
    "nyt-self": (60, [0.03, 0.11, 0.07, 0.22, 0.13, 0.44]),
    "nyt-flat": (60, [0.92, 3.20, 2.29, 6.23, 3.55, 12.33]),
    "nyt-rods": (60, [4.79, 16.88, 12.08, 13.92, 18.76, 65.04]),
    "nyt-blocks": (60, [5.17, 18.13, 13.01, 35.48, 20.18, 70.16]),
}
columns = ["14x15", "14x53", "27x19", "27x53", "53x15", "53x53"]
rows = {}
for line in open(sys.argv[1]):
    r = json.loads(line)
    plan = r["samples"].replace("x51", "x53")
    if r.get("failed"):
        cell = "timed out"
    else:
        s = r["estimated_seconds_all_views"]
        est = "~" if r["views_timed"] < r["views"] else ""
        cell = f"{est}{s:.1f} s" if s < 120 else f"{est}{s / 60:.1f} min"
    rows.setdefault(r["model"], {})[plan] = cell
print("| model | " + " | ".join(columns) + " |")
print("|---|" + "---|" * len(columns))
for model, cells in rows.items():
    print(f"| {model} | " + " | ".join(cells.get(c, "–") for c in columns) + " |")
    if model in paper:
        unit, figures = paper[model]
        shown = [f"{f} s" if unit == 1 else f"{f} min" for f in figures]
        print(f"| paper (GTX 570) | " + " | ".join(shown) + " |")
EOF
