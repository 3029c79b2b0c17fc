# Sourced by the device benches (scripts/bench-gpu.sh, scripts/bench-gpu-variants.sh): one timed
# run of a command into one JSON line, so every bench's log reads the same.
#
#   timed_run DIR LABEL TIMEOUT VARIANT CMD...
#
# Runs CMD under `timeout TIMEOUT`, its stdout kept in DIR/last.json and its stderr appended to
# DIR/stderr.txt after a "== LABEL: CMD" line, then appends {"label", "variant" (left out when
# VARIANT is empty), "rc", "wall" (seconds), "out" (CMD's stdout)} to DIR/bench.jsonl. Returns
# CMD's exit code (124 when it ran past TIMEOUT).
timed_run() {
  local dir=$1 label=$2 t=$3 variant=$4; shift 4
  echo "== $label: $*" >> "$dir/stderr.txt"
  local s e rc; s=$(date +%s.%N)
  timeout "$t" "$@" > "$dir/last.json" 2>>"$dir/stderr.txt"; rc=$?
  e=$(date +%s.%N)
  python3 - "$label" "$variant" "$rc" "$s" "$e" "$dir/last.json" <<'PY' >> "$dir/bench.jsonl"
import json, sys
label, variant, rc, s, e, path = sys.argv[1:]
line = {"label": label, "variant": variant, "rc": int(rc), "wall": round(float(e) - float(s), 3), "out": open(path).read()}
if not variant:
    del line["variant"]
print(json.dumps(line))
PY
  return "$rc"
}
