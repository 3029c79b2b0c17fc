#!/usr/bin/env bash
# End to end on one EnergyPlus test file (Chicago O'Hare TMY3), one run each: EnergyPlus's own
# clipping with its default Periodic updates (every 20 days) and with Timestep updates, and
# `sunlit annual` + EnergyPlus on the hooked model. For each: wall-clock time, annual site energy
# and its shift against the Timestep clipping, and for the hooked run the steps where sunlit's CSV
# and EnergyPlus's reported `Surface Outside Face Sunlit Fraction` disagree on dark vs lit, and the
# largest per-surface mean |Δ| over lit steps against the Timestep clipping.
#   scripts/bench-eplus-large.sh [MODEL.idf]   (default: RefBldgMediumOfficeNew2004_Chicago)
# SUNLIT=path/to/sunlit uses that binary instead of building the release one; ENERGYPLUS=path
# uses that EnergyPlus 25.2 (else scripts/setup.sh installs it).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${ENERGYPLUS:-}" ]; then SUNLIT_ENERGYPLUS=1 . scripts/setup.sh; fi
if [ -z "${SUNLIT:-}" ]; then
  cargo build --release --quiet --bin sunlit
  SUNLIT=./target/release/sunlit
fi
model=${1:-tests/energyplus_testfiles/RefBldgMediumOfficeNew2004_Chicago.idf}
epw="$(dirname "$ENERGYPLUS")/WeatherData/USA_IL_Chicago-OHare.Intl.AP.725300_TMY3.epw"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
seconds() { local s=$(date +%s.%N); "$@" >/dev/null 2>&1; echo "$(date +%s.%N) - $s" | bc; }

# The model as a weather-file run (design days only → the weather file only), its own
# ShadowCalculation removed, the reported fractions and the summary table asked for.
python3 - "$model" "$out" <<'EOF'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
text = re.sub(r"Yes,(\s+!- Run Simulation for Sizing Periods\s+)No([,;])(\s+!- Run Simulation for Weather File Run Periods)",
              r"No,\1Yes\2\3", text, flags=re.I)
if not re.search(r"Yes[,;]\s+!- Run Simulation for Weather File Run Periods", text, flags=re.I):
    sys.exit(f"{sys.argv[1]}: not a weather-file run")
text = re.sub(r"\n\s*ShadowCalculation,[^;]*;", "\n", text, flags=re.I)
if not re.search(r"\n\s*Output:Table:SummaryReports,", text) and not re.search(r"\n\s*OutputControl:Table:Style,", text):
    text += "\nOutput:Table:SummaryReports, AllSummary;\nOutputControl:Table:Style, Comma;\n"
text += "\nOutput:Variable, *, Surface Outside Face Sunlit Fraction, Timestep;\n"
open(f"{sys.argv[2]}/periodic.idf", "w").write(text)
open(f"{sys.argv[2]}/timestep.idf", "w").write(
    text + "ShadowCalculation, PolygonClipping, Timestep, 1, 15000, SutherlandHodgman, 512, SimpleSkyDiffuseModeling, No;\n")
EOF

t_periodic=$(seconds "$ENERGYPLUS" -r -w "$epw" -d "$out/periodic" "$out/periodic.idf")
t_timestep=$(seconds "$ENERGYPLUS" -r -w "$epw" -d "$out/timestep" "$out/timestep.idf")
t_sunlit=$(seconds "$SUNLIT" annual "$out/timestep.idf" --epw "$epw" -o "$out/shading.csv" --idf-out "$out/hooked.idf")
t_hooked=$(seconds "$ENERGYPLUS" -r -w "$epw" -d "$out/hooked" "$out/hooked.idf")
for run in periodic timestep hooked; do
  grep -q "EnergyPlus Completed Successfully" "$out/$run/eplusout.err" || { echo "$run: EnergyPlus did not complete" >&2; exit 1; }
done

python3 - "$out" "$model" "$t_periodic" "$t_timestep" "$t_sunlit" "$t_hooked" <<'EOF'
import csv, os, re, sys
out, model, tp, tt, ts, th = sys.argv[1], sys.argv[2], *map(float, sys.argv[3:])
def site(run):
    # The comma-separated table, or the HTML one where the model asks for HTML only.
    if os.path.exists(f"{out}/{run}/eplustbl.csv"):
        for line in open(f"{out}/{run}/eplustbl.csv", errors="replace"):
            f = line.split(",")
            if len(f) > 2 and f[1] == "Total Site Energy":
                return float(f[2])
    html = open(f"{out}/{run}/eplustbl.htm", errors="replace").read()
    return float(re.search(r"Total Site Energy</td>\s*<td[^>]*>\s*([0-9.]+)", html).group(1))
def reported(run):
    rows = list(csv.reader(open(f"{out}/{run}/eplusout.csv")))
    suffix = ":SURFACE OUTSIDE FACE SUNLIT FRACTION [](TIMESTEP)"
    # Rows of HVAC system timesteps leave the zone-timestep columns empty.
    return {h.upper()[: -len(suffix)]: [float(r[i]) for r in rows[1:] if i < len(r) and r[i].strip()]
            for i, h in enumerate(rows[0]) if h.upper().endswith(suffix)}
rows = list(csv.reader(open(f"{out}/shading.csv")))
ours = {h.strip().upper(): [float(r[i]) for r in rows[1:]] for i, h in enumerate(rows[0]) if i > 0 and h.strip()}
clip, used = reported("timestep"), reported("hooked")
disagree_clip = disagree_used = 0
worst = 0.0
for name, a in ours.items():
    b, c = clip[name], used[name]
    disagree_clip += sum((x > 0) != (y > 0) for x, y in zip(a, b))
    disagree_used += sum((x > 0) != (y > 0) for x, y in zip(a, c))
    lit = [abs(x - y) for x, y in zip(a, b) if x > 0 or y > 0]
    worst = max(worst, sum(lit) / max(len(lit), 1))
ref = site("timestep")
pct = lambda run: 100 * (site(run) - ref) / ref
print(f"{model}: {len(ours)} surfaces hooked, Chicago O'Hare TMY3, one run each")
print("| run | wall clock | site energy | vs Timestep clipping |")
print("|---|---|---|---|")
print(f"| EnergyPlus, PolygonClipping, Periodic (default, 20 days) | {tp:.1f} s | {site('periodic'):.2f} GJ | {pct('periodic'):+.3f} % |")
print(f"| EnergyPlus, PolygonClipping, Timestep | {tt:.1f} s | {ref:.2f} GJ | reference |")
print(f"| sunlit annual + EnergyPlus hooked (Scheduled) | {ts:.1f} s + {th:.1f} s | {site('hooked'):.2f} GJ | {pct('hooked'):+.3f} % |")
print(f"dark/lit disagreements, sunlit vs EnergyPlus's reported fraction: {disagree_clip} (Timestep clipping), {disagree_used} (hooked run)")
print(f"largest per-surface mean |Δ| over lit steps vs the Timestep clipping: {worst:.4f}")
EOF
