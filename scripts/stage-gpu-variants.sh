#!/usr/bin/env bash
# Stages builds of sunlit for scripts/bench-gpu-variants.sh on a lent GPU: each NAME=BINARY
# stripped and gzipped into the carry folder (CARRY, default .gpu-carry, which must be ignored:
# .git/info/exclude), with the Vulkan loader and libglvnd's Debian packages in CARRY/gl, and
# prints what the carry weighs against the 64 MiB a run may carry. Then, on the GPU machine:
#   VARIANTS="NAME ..." scripts/bench-gpu-variants.sh        (carry: .gpu-carry)
# e.g. scripts/stage-gpu-variants.sh spans=../wt/target/release/sunlit main=target/release/sunlit
set -euo pipefail
cd "$(dirname "$0")/.."
C=${CARRY:-.gpu-carry}
[ $# -gt 0 ] || { echo "usage: scripts/stage-gpu-variants.sh NAME=BINARY ..." >&2; exit 2; }
git check-ignore -q "$C" || { echo "stage-gpu-variants: $C is not ignored by git: add /$C/ to .git/info/exclude" >&2; exit 1; }
mkdir -p "$C/gl"
if ! ls "$C"/gl/libvulkan1_*.deb >/dev/null 2>&1; then
  (cd "$C/gl" && apt-get download -qq libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 2>&1 | grep -v 'unsandboxed' || true)
fi
for pair in "$@"; do
  name=${pair%%=*}; binary=${pair#*=}
  [[ $name =~ ^[A-Za-z0-9_-]+$ && $name != "$pair" ]] || { echo "stage-gpu-variants: '$pair' is not NAME=BINARY" >&2; exit 2; }
  [ -x "$binary" ] || { echo "stage-gpu-variants: $binary (for $name) is not an executable" >&2; exit 1; }
  strip -o "$C/$name" "$binary" && gzip -6 -f "$C/$name"
  echo "$name: $("$binary" --version) from $binary"
done
du -sh "$C"
