#!/usr/bin/env bash
# sunlit bench on a real GPU: every engine (compute, exact, gpu, auto with a fresh and a cached
# profile) on the generated bench models, one JSON line a run with its wall time, into OUT
# (default target/bench-gpu). Needs a Vulkan driver for the GPU (NVIDIA's ICD); SUNLIT= names the
# binary (default target/release/sunlit, built if missing). ATLAS= and LANES= pass --atlas/--lanes
# to the GPU runs. BUDGET= seconds after which the remaining runs are skipped (default 480).
# SKIP_EXACT=1 leaves out the CPU-only runs (exact, noop).
# VIEWS=N times an even spread of N views a model instead of all (a quick try on lavapipe).
# The issue's targets come first (the compute rasterizer on all of nyt-blocks' and
# blaas-trees-summer's views, and exact clipping on the same machine beside them), so a short
# lease records them before anything else. The compute kernel's first line is the one to set
# beside the H200's 2026-11-28 figure (1,335 µs a nyt-blocks view, 5 batches counted twice, 16
# views a submission): its JSON has bin_pool_reruns, bin_pool_nodes and
# compute_views_per_submission (the batches are no longer the atlas's 16 views).
# BEFORE=path/to/an/older/sunlit adds that binary's compute runs right after the new one's (the
# spread, blaas-trees-summer's and blaas-louvres' every view), for a before/after on one lease.
# ONLY=REGEX runs only the runs whose label matches (e.g. ONLY=cull for the GPU culling pass).
# TIMEOUT_SCALE=N multiplies every run's timeout (sized for the lease's 16 cores): the lavapipe
# form on a loaded 2-core machine needs about 6 (generating nyt-blocks alone took 47-68 s there).
# Counting with the GPU's culling (--cull gpu) is timed first, beside the CPU-culled count of the
# same views, then the culling pass alone (--gpu-cull: clusters of <= 128 triangles against 1,024
# views a dispatch, src/count/gpu/cluster_cull.rs). ONLY=cull runs just those.
# Used for docs/benchmarks-gpu.md (an H100 and an H200 lent for one session: see there).
set -uo pipefail
cd "$(dirname "$0")/.."
B=${SUNLIT:-target/release/sunlit}
[ -x "$B" ] || cargo build --release --quiet --bin sunlit
OUT=${OUT:-target/bench-gpu}; mkdir -p "$OUT"
T0=$(date +%s)
gpu_flags=(); [ -n "${ATLAS:-}" ] && gpu_flags+=(--atlas "$ATLAS"); [ -n "${LANES:-}" ] && gpu_flags+=(--lanes "$LANES")
views=(); [ -n "${VIEWS:-}" ] && views=(--views "$VIEWS")
. scripts/timed-run.sh
run() { # label timeout args...
  local label=$1 t=$(( $2 * ${TIMEOUT_SCALE:-1} )); shift 2
  if [ -n "${ONLY:-}" ] && ! [[ $label =~ $ONLY ]]; then return; fi
  if [ $(( $(date +%s) - T0 )) -gt "${BUDGET:-480}" ]; then echo "skip $label" >> "$OUT/stderr.txt"; return; fi
  # SKIP_EXACT=1: a second lease on the same machine need not time the CPU again.
  if [ -n "${SKIP_EXACT:-}" ] && [[ $label == *exact* || $label == *noop* ]]; then return; fi
  timed_run "$OUT" "$label" "$t" "" "$B" "$@"
}
profiles=$(mktemp -d); trap 'rm -rf "$profiles"' EXIT
# The machine first, so every figure below has its GPU and driver beside it.
{ nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv 2>&1; "$B" --version 2>&1; } > "$OUT/machine.txt"
# The targets: nyt-blocks 27×19 (353,780 views) best GPU kernel ≤ 8 s and ≥ 4× exact on 16
# cores; blaas-trees-summer (16,492 views) ≤ 0.5 s. A short lease first gets the three engines
# on the same even spread of 20,040 nyt-blocks views (extrapolated), then every view.
# The new path first: counts drawn from the GPU's culling (--cull gpu: one indirect draw a tile,
# src/count/gpu/pulled.rs) on 20,040 nyt-blocks views with the CPU-culled count of the same views
# beside it (same binary, --cull cpu), blaas-trees-summer's every view both ways, and the host's
# cost of each on noop. Each JSON line's `cull` says which path ran, and `shading_tested_on_cpu`
# how many views the GPU's shading test (shaders/may_shade.wgsl) left to the host.
# The compute kernel for many SMs first (binning a workgroup per 256 triangles, up to 1,024
# views a submission, the node pool sized from the batch before; docs/benchmarks-gpu.md): never
# measured on a GPU, and the H200's 2026-11-28 line (470 s, 5 batches counted twice) is the one
# to set it beside. nyt-blocks' even spread of 20,040 views, then blaas-trees-summer's every view.
# BEST="--engine …" (scripts/bench-gpu-lease.sh sets it from the spread's lines) times the
# fastest kernel of the spread on every view of nyt-blocks, checked: the issue's first target.
[ -n "${BEST:-}" ] && run nyt-blocks-best-all 150 bench nyt-blocks $BEST --check 30 "${views[@]}" "${gpu_flags[@]}"
run nyt-blocks-compute-20040 60 bench nyt-blocks --engine compute --views "${VIEWS:-20040}" --check 30 "${gpu_flags[@]}"
[ -n "${BEFORE:-}" ] && B="$BEFORE" run nyt-blocks-compute-20040-before 60 bench nyt-blocks --engine compute --views "${VIEWS:-20040}" "${gpu_flags[@]}"
run blaas-trees-summer-compute 40 bench blaas-trees-summer --engine compute --check 50 "${views[@]}" "${gpu_flags[@]}"
[ -n "${BEFORE:-}" ] && B="$BEFORE" run blaas-trees-summer-compute-before 40 bench blaas-trees-summer --engine compute "${views[@]}" "${gpu_flags[@]}"
[ -n "${BEFORE:-}" ] && B="$BEFORE" run blaas-louvres-compute-before 40 bench blaas-louvres --engine compute "${views[@]}" "${gpu_flags[@]}"
# Then the cheapest host form (--cull gpu-batch: the GPU's culling drawn with one draw a batch,
# src/count/gpu/batched.rs; the least host time a view on noop, docs/benchmarks-gpu.md), with its
# answers checked, and its host cost on noop; then the per-tile form and the CPU's culling.
# (On lavapipe the batch draw is a lit pixel from the per-tile form on some louvre views: lavapipe
# clips at the tile's viewport; a GPU with a guard band should not. Compare the two --check lines.)
run nyt-blocks-cull-gpu-batch 90 bench nyt-blocks --engine gpu --cull gpu-batch --views "${VIEWS:-20040}" --check 10 "${gpu_flags[@]}"
run blaas-trees-summer-cull-gpu-batch 40 bench blaas-trees-summer --engine gpu --cull gpu-batch --check 20 "${views[@]}" "${gpu_flags[@]}"
run nyt-blocks-noop-cull-gpu-batch 60 bench nyt-blocks --engine gpu --backend noop --cull gpu-batch --lanes 1 --views "${VIEWS:-20040}"
run nyt-blocks-cull-gpu 90 bench nyt-blocks --engine gpu --cull gpu --views "${VIEWS:-20040}" --check 10 "${gpu_flags[@]}"
run nyt-blocks-cull-cpu 90 bench nyt-blocks --engine gpu --cull cpu --views "${VIEWS:-20040}" "${gpu_flags[@]}"
run blaas-trees-summer-cull-gpu 40 bench blaas-trees-summer --engine gpu --cull gpu --check 20 "${views[@]}" "${gpu_flags[@]}"
run blaas-trees-summer-cull-cpu 40 bench blaas-trees-summer --engine gpu --cull cpu "${views[@]}" "${gpu_flags[@]}"
run nyt-blocks-noop-cull-gpu 60 bench nyt-blocks --engine gpu --backend noop --cull gpu --lanes 1 --views "${VIEWS:-20040}"
# The culling pass alone (its list form, --gpu-cull), as timed before the draw existed.
run nyt-blocks-gpu-cull 90 bench nyt-blocks --engine gpu --views "${VIEWS:-20040}" --gpu-cull "${gpu_flags[@]}"
run nyt-blocks-noop-cull 90 bench nyt-blocks --engine gpu --backend noop --lanes 1 --views "${VIEWS:-20040}" --gpu-cull
run blaas-trees-summer-gpu-cull 40 bench blaas-trees-summer --engine gpu --gpu-cull "${views[@]}" "${gpu_flags[@]}"
if [ -z "${VIEWS:-}" ]; then
  run nyt-blocks-gpu-20040 60 bench nyt-blocks --engine gpu --views 20040 "${gpu_flags[@]}"
  run nyt-blocks-exact-20040 60 bench nyt-blocks --engine exact --views 20040
fi
run nyt-blocks-compute-all 150 bench nyt-blocks --engine compute --check 30 "${views[@]}" "${gpu_flags[@]}"
run nyt-blocks-exact-all 150 bench nyt-blocks --engine exact "${views[@]}"
run synthetic 40 bench --suns 64 "${gpu_flags[@]}"
# The host's cost a view alone (wgpu's no-op backend), to set beside the real GPU's.
run nyt-blocks-noop 60 bench nyt-blocks --engine gpu --backend noop --lanes 1 --views 20000
run nyt-blocks-noop-compute 60 bench nyt-blocks --engine compute --backend noop --lanes 1 --views 20000
for m in blaas-louvres blaas-trees-summer nyt-self nyt-flat; do
  run "$m-compute" 40 bench "$m" --engine compute --check 50 "${views[@]}" "${gpu_flags[@]}"
  run "$m-gpu" 40 bench "$m" --engine gpu --check 50 "${views[@]}" "${gpu_flags[@]}"
  run "$m-exact" 40 bench "$m" --engine exact "${views[@]}"
  run "$m-auto-first" 40 bench "$m" --engine-profile "$profiles/$m.json" "${views[@]}" "${gpu_flags[@]}"
  run "$m-auto" 40 bench "$m" --engine-profile "$profiles/$m.json" "${views[@]}" "${gpu_flags[@]}"
done
m=nyt-blocks
run "$m-compute-3000" 60 bench $m --engine compute --views 3000 --check 30 "${gpu_flags[@]}"
run "$m-gpu-3000" 60 bench $m --engine gpu --views 3000 --check 30 "${gpu_flags[@]}"
run "$m-exact-3000" 60 bench $m --engine exact --views 3000
run "$m-auto-first-3000" 60 bench $m --views 3000 --engine-profile "$profiles/$m.json" "${gpu_flags[@]}"
run "$m-auto-all" 150 bench $m --engine-profile "$profiles/$m.json" "${gpu_flags[@]}"
echo "results: $OUT/bench.jsonl"
