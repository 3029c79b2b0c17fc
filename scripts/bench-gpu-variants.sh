#!/usr/bin/env bash
# Several builds of sunlit side by side on one lent GPU, in turns, for a kernel change's A/B on
# the same machine (docs/benchmarks-gpu.md, 2026-11-30). Here, first: each build stripped and
# gzipped into the carry folder under its name, with the Vulkan loader's packages,
#   scripts/stage-gpu-variants.sh new=path/to/new/sunlit old=path/to/old/sunlit
# (.gpu-carry in .git/info/exclude); then on the GPU machine, carrying .gpu-carry:
#   VARIANTS="new old" scripts/bench-gpu-variants.sh
# Runs, each variant in turn: nyt-blocks' even spread of 20,040 views (the first variant's
# checked against exact on 30 views), blaas-trees-summer's and blaas-louvres' every view
# (checked on 50), then the spread and blaas-trees-summer again. One JSON line a run into
# OUT/bench.jsonl (the run's label, exit code, wall time and bench output), a summary line a
# run on stdout; runs that would start after BUDGET seconds (default 150) are skipped.
set -uo pipefail
cd "$(dirname "$0")/.."
C=${CARRY:-.gpu-carry}; R=${OUT:-target/bench-gpu-variants}; mkdir -p "$R"; T0=$(date +%s)
read -r -a variants <<< "${VARIANTS:?VARIANTS: the names of the gzipped builds in $C}"
if [ -d "$C/gl" ] && ! ldconfig -p | grep -q 'libvulkan.so.1 '; then
  for f in "$C"/gl/*.deb; do dpkg -x "$f" /; done; ldconfig
fi
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$icd" ] && export VK_DRIVER_FILES=$icd
[ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && [ -f "$egl" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$egl
bin=/tmp/sunlit-variants; mkdir -p "$bin"
for v in "${variants[@]}"; do gunzip -c "$C/$v.gz" > "$bin/$v" && chmod +x "$bin/$v" || exit 1; done
{ nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv; nproc; } > "$R/machine.txt" 2>&1

. scripts/timed-run.sh
run() { # label timeout variant args...
  local label=$1 t=$2 v=$3; shift 3
  if [ $(( $(date +%s) - T0 )) -gt "${BUDGET:-150}" ]; then echo "skip $label" >> "$R/stderr.txt"; return; fi
  local rc; timed_run "$R" "$label" "$t" "$v" "$bin/$v" "$@"; rc=$?
  python3 - "$label" "$rc" "$R/last.json" <<'PY'
import json, sys
label, rc, path = sys.argv[1:]
try:
    o = json.loads(open(path).read())
except ValueError:
    o = {}
print(label, rc, o.get("estimated_seconds_all_views"), o.get("views_rendered"), o.get("max_abs_error"), flush=True)
PY
}
first=${variants[0]}
for v in "${variants[@]}"; do
  check=(); [ "$v" = "$first" ] && check=(--check 30)
  run "nyt-20040-$v" 60 "$v" bench nyt-blocks --engine compute --views 20040 "${check[@]}"
done
for v in "${variants[@]}"; do run "trees-$v" 40 "$v" bench blaas-trees-summer --engine compute --check 50; done
for v in "${variants[@]}"; do run "louvres-$v" 40 "$v" bench blaas-louvres --engine compute --check 50; done
for v in "${variants[@]}"; do run "nyt-20040-$v-again" 60 "$v" bench nyt-blocks --engine compute --views 20040; done
for v in "${variants[@]}"; do run "trees-$v-again" 40 "$v" bench blaas-trees-summer --engine compute; done
echo "done in $(( $(date +%s) - T0 )) s: $R/bench.jsonl"
