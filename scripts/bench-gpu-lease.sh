#!/usr/bin/env bash
# Everything issue #32 measures on a lent GPU, in one command, the targets first, so that a single
# short lease records them (docs/benchmarks-gpu.md). Here, first:
#   scripts/stage-node-gpu.sh                       # .node-gpu/: Node, Dawn, the bundle, the binary
#   (cd .node-gpu && mkdir -p gl && cd gl && apt-get download libvulkan1 libegl1 libglvnd0 \
#      libopengl0 libgl1 libglx0 libgles2)         # the loader and libglvnd for NVIDIA's ICD
# then on the GPU machine, carrying .node-gpu:
#   scripts/bench-gpu-lease.sh
# Phases, each skipped once the lease's time (LEASE, default 540 s) would not cover it:
#   1. every kernel on nyt-blocks' even spread of 20,040 views (compute, the GPU's culling drawn a
#      batch at once and a tile at a time, the CPU's culling), each on blaas-trees-summer's every
#      view, exact clipping on the spread, and the host's cost on noop (scripts/bench-gpu.sh);
#   2. the page's path: blaas-trees-summer's 27×19 year, Timestep 4, through the JS API under Node
#      on Dawn beside the native CLI's same year (scripts/bench-node-gpu.sh);
#   3. the spread's fastest kernel on all 353,780 views, checked (BEST in scripts/bench-gpu.sh);
#   4. exact clipping on all views, then whatever of bench-gpu.sh's list the time leaves.
# Results, at most 8 files as the lease returns them, in OUT (default target/bench-gpu-lease):
# gpu/{bench.jsonl,stderr.txt,machine.txt,last.json}, node-bench.jsonl, node-stderr.txt, lease.log.
# Locally (lavapipe, a quick try of the script itself): NODE_CARRY= VIEWS=8 TIMEOUT_SCALE=8
# SUNLIT=target/release/sunlit scripts/bench-gpu-lease.sh (Node and the binary from this machine).
set -uo pipefail
cd "$(dirname "$0")/.."
R=${OUT:-target/bench-gpu-lease}; mkdir -p "$R/gpu"
T0=$(date +%s)
C=${CARRY:-.node-gpu}
log() { echo "$(( $(date +%s) - T0 )) s: $*" | tee -a "$R/lease.log"; }
left() { echo $(( ${LEASE:-540} - ($(date +%s) - T0) )); }

# The Vulkan loader and libglvnd (NVIDIA's Vulkan ICD lives in libGLX_nvidia, which needs
# libGLdispatch), unpacked where a bare machine lacks them; then NVIDIA's ICD by name.
if [ -d "$C/gl" ] && ! ldconfig -p | grep -q 'libvulkan.so.1 '; then
  for f in "$C"/gl/*.deb; do dpkg -x "$f" /; done; ldconfig; log "unpacked $(ls "$C"/gl | wc -l) loader packages"
fi
icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
egl=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$icd" ]; then export VK_DRIVER_FILES=$icd; fi
if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ] && [ -f "$egl" ]; then export __EGL_VENDOR_LIBRARY_FILENAMES=$egl; fi
if [ -z "${SUNLIT:-}" ]; then
  gunzip -c "$C/sunlit.gz" > /tmp/sunlit-lease && chmod +x /tmp/sunlit-lease && export SUNLIT=/tmp/sunlit-lease
fi
log "binary $SUNLIT ($("$SUNLIT" --version 2>&1)); VK_DRIVER_FILES=${VK_DRIVER_FILES:-unset}"
nvidia-smi -L >> "$R/lease.log" 2>&1

# 1. Every kernel on the spread, the exact engine beside them.
spread='nyt-blocks-compute-20040|blaas-trees-summer-compute|nyt-blocks-cull-gpu-batch|blaas-trees-summer-cull-gpu-batch'
spread+='|nyt-blocks-noop-cull-gpu-batch|nyt-blocks-cull-gpu|nyt-blocks-cull-cpu|blaas-trees-summer-cull-gpu|nyt-blocks-exact-20040'
log "phase 1: the spread"
OUT=$R/gpu BUDGET=$(( $(left) - 330 )) ONLY="^($spread)\$" bash scripts/bench-gpu.sh

# 2. The page's path under Node on Dawn, beside native, on the same GPU.
# Never measured before, so it gets what phase 1 leaves but a minute (the spread already
# extrapolates the kernels to every view; phases 3 and 4 confirm it where time allows).
if [ "$(left)" -gt 150 ]; then
  log "phase 2: the page's path"
  node_out=/tmp/sunlit-lease-node; rm -rf "$node_out"
  OUT=$node_out CARRY=${NODE_CARRY-$C} MODELS=blaas-trees-summer BUDGET=$(( $(left) - 100 )) RUN_TIMEOUT=$(( ($(left) - 60) / 2 )) \
    bash scripts/bench-node-gpu.sh
  cp "$node_out/bench.jsonl" "$R/node-bench.jsonl" 2>/dev/null; cp "$node_out/stderr.txt" "$R/node-stderr.txt" 2>/dev/null
fi

# 3. The fastest kernel of the spread on every view: the issue's ≤ 8 s target.
best=$(python3 - "$R/gpu/bench.jsonl" <<'PY'
import json, sys
kernels = {"nyt-blocks-compute-20040": "--engine compute", "nyt-blocks-cull-gpu-batch": "--engine gpu --cull gpu-batch",
           "nyt-blocks-cull-gpu": "--engine gpu --cull gpu", "nyt-blocks-cull-cpu": "--engine gpu --cull cpu"}
timed = []
for line in open(sys.argv[1]):
    run = json.loads(line)
    if run["label"] in kernels and run["rc"] == 0 and run["out"].strip():
        timed.append((json.loads(run["out"])["estimated_seconds_all_views"], kernels[run["label"]]))
print(min(timed)[1] if timed else "")
PY
)
if [ -n "$best" ] && [ "$(left)" -gt 60 ]; then
  log "phase 3: every view with $best"
  OUT=$R/gpu BEST=$best BUDGET=0 ONLY='^nyt-blocks-best-all$' TIMEOUT_SCALE=1 bash scripts/bench-gpu.sh
fi

# 4. Exact clipping on every view (the ≥ 4× target's other side), then the rest of the list.
if [ "$(left)" -gt 70 ]; then
  log "phase 4: exact on every view"
  OUT=$R/gpu BUDGET=0 ONLY='^nyt-blocks-exact-all$' bash scripts/bench-gpu.sh
fi
if [ "$(left)" -gt 60 ]; then
  log "phase 5: the rest"
  OUT=$R/gpu BUDGET=$(( $(left) - 60 )) ONLY="^(nyt-blocks-noop|nyt-blocks-noop-compute|blaas-louvres-(compute|gpu|exact)|nyt-flat-compute|synthetic)\$" \
    bash scripts/bench-gpu.sh
fi
log "done"
