#!/usr/bin/env bash
# Measures the issue #2 target (forward + backward at 320x240, 200k surfels, 2 threads; 20 repetitions)
# again and again on a machine whose load comes and goes, to catch its quiet spells: every PAUSE seconds,
# a discarded 5-repetition warm-up (the first run after an idle pause is slower here), then each binary
# in turn, the order alternating from cycle to cycle. One line per run: time, binary, median, mean, stddev.
#
#   bench/poll_target.sh CYCLES PAUSE BINARY...
#   bench/poll_target.sh 60 45 build/bench/raster_bench /tmp/raster_bench_old | tee poll.log
set -euo pipefail
source "$(dirname "$0")/script_args.sh"
usage_unless $# 3
cycles="$1"; pause="$2"; shift 2
require_executables "$@"
filter='^BM_ForwardBackward/w:320/h:240/surfels:200000/threads:2'
binaries=("$@")
for cycle in $(seq "$cycles"); do
    "${binaries[0]}" --benchmark_filter="$filter" --benchmark_repetitions=5 >/dev/null 2>&1
    order=("${binaries[@]}")
    if [ $((cycle % 2)) -eq 0 ]; then  # reversed every other cycle
        order=()
        for ((i = ${#binaries[@]} - 1; i >= 0; i--)); do order+=("${binaries[i]}"); done
    fi
    for bin in "${order[@]}"; do
        "$bin" --benchmark_filter="$filter" --benchmark_repetitions=20 --benchmark_report_aggregates_only=true \
            2>/dev/null | awk -v t="$(date +%H:%M:%S)" -v b="$bin" '
                /_median/ { median = $2 } /_mean/ { mean = $2 } /_stddev/ { sd = $2 }
                END { printf "%s %s median %s mean %s stddev %s ms\n", t, b, median, mean, sd }'
    done
    if [ "$cycle" -lt "$cycles" ]; then sleep "$pause"; fi
done
