#!/usr/bin/env bash
# Coverage-guided fuzzing of every parser and file reader (fuzz/targets/) with libFuzzer, ASan and UBSan.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET ...]     (default: 60 s, every target)
# Builds build-fuzz/ with clang, starts each target from its seeds (the project's own writers) plus the
# corpus kept in fuzz/corpus/NAME/ (created; not committed), with a 2 GB memory limit, and prints one line per
# target: executions, corpus size, coverage, and where a finding was saved (fuzz/findings/NAME/).
# Without clang or libFuzzer, the same targets still run in every test build (ctest -R fuzz.).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
if ! command -v clang++ >/dev/null; then
    echo "fuzz.sh: installing clang (libFuzzer)"
    sudo apt-get update -qq && sudo apt-get install -y -qq clang
fi
CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLUMIGAUSS_LIBFUZZER=ON \
    -DLUMIGAUSS_BUILD_TESTS=OFF -DLUMIGAUSS_BUILD_BENCH=OFF > /dev/null
cmake --build build-fuzz -j "$(nproc)" --target $(ls fuzz/targets | sed 's/\.cpp$//; s/^/fuzz_/')
targets=("$@")
[ ${#targets[@]} -eq 0 ] && mapfile -t targets < <(ls fuzz/targets | sed 's/\.cpp$//')
status=0
printf '%-16s %12s %8s %8s %s\n' target executions corpus edges finding
for t in "${targets[@]}"; do
    corpus=fuzz/corpus/$t findings=fuzz/findings/$t seeds=build-fuzz/seeds/$t
    mkdir -p "$corpus" "$findings"
    LUMIGAUSS_FUZZ_WRITE_SEEDS=$seeds "build-fuzz/fuzz/fuzz_$t" > /dev/null
    log=build-fuzz/fuzz_$t.log
    if LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp "build-fuzz/fuzz/fuzz_$t" "$corpus" "$seeds" -max_total_time="$seconds" -rss_limit_mb=2048 \
        -malloc_limit_mb=2048 -timeout=10 -max_len=65536 -print_final_stats=1 \
        -artifact_prefix="$findings/" > "$log" 2>&1; then
        finding=none
    else
        finding=$(ls -t "$findings" | head -1)
        finding=${finding:+$findings/$finding}
        status=1
    fi
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    edges=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
    printf '%-16s %12s %8s %8s %s\n' "$t" "${runs:-?}" "$(ls "$corpus" | wc -l)" "${edges:-?}" "${finding:-see $log}"
done
exit $status
