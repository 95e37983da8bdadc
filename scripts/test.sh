#!/usr/bin/env bash
# Installs dependencies, builds, and runs the test suite with CTest.
#   scripts/test.sh            both tiers in a release build, then the fast tier under ASan/UBSan
#   scripts/test.sh --all      the slow tier under ASan/UBSan too
#   scripts/test.sh --no-asan  skip the sanitizer build
set -euo pipefail
cd "$(dirname "$0")/.."
all=0; asan=1
for a in "$@"; do
    case "$a" in
        --all) all=1 ;;
        --no-asan) asan=0 ;;
        *) echo "test.sh: unknown option $a" >&2; exit 2 ;;
    esac
done
jobs=$(nproc)

scripts/setup.sh --no-build
asan_slow=OFF asan_labels=fast
[ $all -eq 1 ] && asan_slow=ON asan_labels="fast|slow"
# The release tree is the one scripts/setup.sh and scripts/demo.sh build: configured with the same options, so
# that running the tests after the demo rebuilds nothing (CI adds -DLUMIGAUSS_WERROR=ON via .ci/run).
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DLUMIGAUSS_BUILD_SLOW_TESTS=ON ${LUMIGAUSS_CMAKE_ARGS:-}
cmake --build build -j "$jobs"
status=0
(cd build && ctest --output-on-failure -j "$jobs" -L "fast|slow") || status=1

if [ $asan -eq 1 ]; then
    cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLUMIGAUSS_WERROR=ON -DLUMIGAUSS_SANITIZE=ON \
          -DLUMIGAUSS_BUILD_BENCH=OFF -DLUMIGAUSS_BUILD_SLOW_TESTS=$asan_slow ${LUMIGAUSS_CMAKE_ARGS:-}
    cmake --build build-asan -j "$jobs"
    # The headless-Chromium tests check the page's scripts, which the sanitizers do not see; their server side
    # is covered under the sanitizers by the other view tests. They run in the release tree only.
    (cd build-asan && ctest --output-on-failure -j "$jobs" -L "$asan_labels" -E '^CliViewBrowser\.') || status=1
fi
exit $status
