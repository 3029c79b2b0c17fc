#!/usr/bin/env bash
# Paired timing of two whole commands on a noisy machine: A and B run in turn N times, each
# under /usr/bin/time, and the medians and the A/B ratios are printed. Taking them in turn puts
# both under the same load drift, which a run of A's then a run of B's would not.
#
#   scripts/paired.sh N "COMMAND A" "COMMAND B"
#
# Prints, for A and B: median wall seconds, median CPU seconds (user + system), median peak
# memory (MiB); then A/B for wall and CPU (A is the first command: below 1 means A is faster). Each command runs through `sh -c`; its output is
# discarded and a non-zero exit stops the script, so a failed run never reads as a fast one.
set -euo pipefail

if [[ $# -ne 3 || ! $1 =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: scripts/paired.sh N \"COMMAND A\" \"COMMAND B\" (N: runs of each, at least 1)" >&2
  exit 2
fi
runs=$1
a=$2
b=$3
log=$(mktemp)
trap 'rm -f "$log"' EXIT

time_one() { # label command
  local out
  out=$(mktemp)
  if ! /usr/bin/time -f "%e %U %S %M" -o "$out" sh -c "$2" >/dev/null 2>&1; then
    echo "paired.sh: command $1 failed: $2" >&2
    rm -f "$out"
    exit 1
  fi
  echo "$1 $(tail -n 1 "$out")" >>"$log"
  rm -f "$out"
}

for _ in $(seq "$runs"); do
  time_one A "$a"
  time_one B "$b"
done

python3 - "$log" <<'EOF'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1])]
def medians(label):
    runs = [r for r in rows if r[0] == label]
    wall = statistics.median(float(r[1]) for r in runs)
    cpu = statistics.median(float(r[2]) + float(r[3]) for r in runs)
    mem = statistics.median(float(r[4]) / 1024 for r in runs)
    return wall, cpu, mem
a, b = medians("A"), medians("B")
for label, (wall, cpu, mem) in (("A", a), ("B", b)):
    print(f"{label}: wall {wall:.2f} s, cpu {cpu:.2f} s, peak {mem:.0f} MiB (median of {sum(r[0] == label for r in rows)})")
def ratio(x, y):
    return f"{x / y:.3f}x" if y > 0 else "n/a (B took no measurable time)"
print(f"A/B: wall {ratio(a[0], b[0])}, cpu {ratio(a[1], b[1])}")
EOF
