#!/bin/sh
# Runs fuzz targets in turn, nice'd, one at a time; logs under fuzz/logs/.
# Usage: fuzz/run_all.sh [TARGET[:SECONDS]…]   (default: every target for 600 s)
cd "$(dirname "$0")" || exit 1
mkdir -p logs
for spec in ${*:-gltf idf epjson epw csv cityjson obj}; do
    t=${spec%%:*}
    secs=600
    [ "$t" != "$spec" ] && secs=${spec#*:}
    mkdir -p "corpus/$t"
    echo "$t start $(date -u +%H:%M:%S) for ${secs}s" >> logs/summary.txt
    nice -n 19 cargo +nightly fuzz run "$t" "corpus/$t" "seeds/$t" -- \
        -max_total_time="$secs" -timeout=20 -rss_limit_mb=3072 -max_len=400000 -print_final_stats=1 \
        > "logs/$t.log" 2>&1
    echo "$t exit $? at $(date -u +%H:%M:%S)" >> logs/summary.txt
done
