#!/usr/bin/env bash
# A/B comparison of two builds of one Google Benchmark program on a noisy machine: the two binaries run
# alternately, ROUNDS times each, one short run per benchmark per turn, so that a slow phase of the machine
# hits both alike. Prints per benchmark the fastest run of each (min: the noise here only ever slows a run
# down), the medians, and the median and range of the per-round new/old ratios.
#
#   bench/ab_compare.sh OLD_BINARY NEW_BINARY [FILTER] [ROUNDS, default 8] [MIN_TIME s, default 0.6]
#   bench/ab_compare.sh /tmp/raster_bench_old build/bench/raster_bench '^BM_Backward/w:320/h:240/surfels:200000'
set -euo pipefail
source "$(dirname "$0")/script_args.sh"
usage_unless $# 2
old="$1"; new="$2"; filter="${3:-.}"; rounds="${4:-8}"; min_time="${5:-0.6}"
require_executables "$old" "$new"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for round in $(seq "$rounds"); do
    for side in old new; do
        bin="$old"; [ "$side" = new ] && bin="$new"
        # CSV rows: "name",iterations,real_time,...; keep name and real time, tagged with side and round.
        "$bin" --benchmark_filter="$filter" --benchmark_min_time="$min_time" --benchmark_format=csv 2>/dev/null |
            awk -F, -v side="$side" -v round="$round" '/^"BM_/ { gsub(/"/, "", $1); print side, round, $1, $3 }' \
            >>"$out/runs"
    done
done
[ -s "$out/runs" ] || { echo "ab_compare.sh: no benchmark matched '$filter'" >&2; exit 1; }
awk '
    function median(list, n,    i, j, t, a) {
        n = split(list, a, " ")
        for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j - 1] > a[j]; j--) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
        return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
    }
    function minimum(list,    n, i, a, m) {
        n = split(list, a, " "); m = a[1]
        for (i = 2; i <= n; i++) if (a[i] < m) m = a[i]
        return m
    }
    {
        side = $1; round = $2; name = $3; t = $4
        if (!(name in seen)) { seen[name] = 1; order[++count] = name }
        times[side, name] = times[side, name] " " t
        at[side, name, round] = t; rounds[name] = (round > rounds[name] ? round : rounds[name])
    }
    END {
        printf "%-58s %9s %9s %7s %9s %9s %7s %7s %15s\n", "benchmark (ms)", "old min", "new min", "ratio", \
               "old med", "new med", "ratio", "pair med", "pair range"
        for (i = 1; i <= count; i++) {
            name = order[i]; ratios = ""; lo = 1e30; hi = 0
            for (r = 1; r <= rounds[name]; r++)
                if (("old", name, r) in at && ("new", name, r) in at) {
                    q = at["new", name, r] / at["old", name, r]; ratios = ratios " " q
                    if (q < lo) lo = q
                    if (q > hi) hi = q
                }
            omin = minimum(times["old", name]); nmin = minimum(times["new", name])
            omed = median(times["old", name]); nmed = median(times["new", name])
            shown = name; sub(/^BM_/, "", shown); sub(/\/real_time$/, "", shown)
            printf "%-58s %9.2f %9.2f %7.3f %9.2f %9.2f %7.3f %7.3f %7.3f..%.3f\n", shown, omin, nmin, nmin / omin, \
                   omed, nmed, nmed / omed, median(ratios), lo, hi
        }
    }' "$out/runs"
