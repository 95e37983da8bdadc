#!/usr/bin/env bash
# Phase by phase A/B of builds of bench/raster_bench on a noisy machine: the binaries run alternately,
# ROUNDS times each, 3 repetitions per turn, and for every benchmark and binary it prints the fastest and
# the median of the whole call and of each phase counter (*_ms) over all repetitions. Use it where a change
# targets one phase: the total's noise can hide a phase that got faster (bench/ab_compare.sh compares totals).
#
#   bench/phase_compare.sh FILTER ROUNDS BINARY...
#   bench/phase_compare.sh '^BM_ForwardBackward/w:320/h:240/surfels:200000' 6 /tmp/raster_bench_old build/bench/raster_bench
set -euo pipefail
source "$(dirname "$0")/script_args.sh"
usage_unless $# 3
filter="$1"; rounds="$2"; shift 2
require_executables "$@"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for round in $(seq "$rounds"); do
    side=0
    for bin in "$@"; do
        side=$((side + 1))
        # CSV: a header naming the columns (counters quoted), then one row per repetition and aggregate.
        "$bin" --benchmark_filter="$filter" --benchmark_repetitions=3 --benchmark_min_time=0.3 \
            --benchmark_format=csv 2>/dev/null |
            awk -F, -v side="$side" -v label="$bin" '
                /^name,/ { for (i = 1; i <= NF; i++) { gsub(/"/, "", $i); col[i] = $i }; next }
                /^"BM_/ && !/_(mean|median|stddev|cv)"/ {
                    gsub(/"/, "", $1); sub(/\/real_time$/, "", $1)
                    for (i = 2; i <= NF; i++)
                        if (col[i] == "real_time" || col[i] ~ /_ms$/) print side, label, $1, col[i], $i
                }' >>"$out/runs"
    done
done
[ -s "$out/runs" ] || { echo "phase_compare.sh: no benchmark matched '$filter'" >&2; exit 1; }
sort -k3,3 -k1,1n -k4,4 -k5,5g "$out/runs" | awk '
    function flush() {
        if (n == 0) return
        m = n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
        if (v[n] > 0) line = line sprintf(" %s=%.2f/%.2f", key == "real_time" ? "total" : key, v[1], m)
        n = 0
    }
    {
        group = $3 " | " $2
        if (group != current) { flush(); if (line != "") print line; line = group " (ms, fastest/median):"; current = group; key = "" }
        if ($4 != key) { flush(); key = $4 }
        v[++n] = $5
    }
    END { flush(); if (line != "") print line }'
