#!/usr/bin/env bash
# Runs the rasterizer benchmarks (3 repetitions each) and prints one table of medians, plus the 1 -> 2
# thread speed-up of each case. Usage: bench/run_raster_bench.sh [build dir, default build] [filter]
set -euo pipefail
build="${1:-build}"
filter="${2:-.}"
csv=$(mktemp)
trap 'rm -f "$csv"' EXIT
"$build/bench/raster_bench" --benchmark_filter="$filter" --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true --benchmark_out="$csv" --benchmark_out_format=csv >/dev/null
# The CSV starts with context lines, then a header: name,iterations,real_time,cpu_time,time_unit,...,counters
awk -F, '
    /^name,/ { for (i = 1; i <= NF; i++) { c = $i; gsub(/"/, "", c); col[c] = i }; next }
    $1 ~ /_median"?$/ {
        name = $1; gsub(/"/, "", name); sub(/\/real_time_median$/, "", name)
        split(name, p, "/"); kind = p[1]; sub(/^BM_/, "", kind)
        w = p[2]; h = p[3]; n = p[4]; t = p[5]; sub(/.*:/, "", w); sub(/.*:/, "", h); sub(/.*:/, "", n); sub(/.*:/, "", t)
        key = kind " " w "x" h " " n
        ms[key, t] = $col["real_time"]
        ppp[key] = $col["pairs_per_pixel"]; lpp[key] = $col["lanes_per_pixel"]; isect[key] = $col["intersections"]
        if (!(key in seen)) { seen[key] = 1; order[++count] = key }
    }
    END {
        printf "%-16s %-9s %8s %12s %10s %10s %10s %10s %8s\n", "pass", "image", "surfels", "intersect.", \
               "pairs/px", "lanes/px", "1 thr ms", "2 thr ms", "speedup"
        for (i = 1; i <= count; i++) {
            k = order[i]; split(k, f, " ")
            s1 = ms[k, 1]; s2 = ms[k, 2]
            printf "%-16s %-9s %8s %12.0f %10.1f %10.1f %10.1f %10.1f %8.2f\n", f[1], f[2], f[3], isect[k], \
                   ppp[k], lpp[k], s1, s2, (s2 > 0 ? s1 / s2 : 0)
        }
    }' "$csv"
