#!/usr/bin/env bash
# Installs every build dependency from Debian packages (idempotent) and builds the release tree in build/.
# Usage: scripts/setup.sh [--no-build]
set -euo pipefail
cd "$(dirname "$0")/.."

# chromium: only for the viewer's browser tests (headless, software WebGL) and bench/viewer_bench.sh.
# ffmpeg: run (never linked) by `render --spin` / `--cameras orbit` to make MP4s; without it only frames.
PACKAGES=(build-essential cmake pkg-config git libtbb-dev libglm-dev libstb-dev libtinyexr-dev libpng-dev
          libcli11-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev chromium ffmpeg)

missing=()
for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing ${missing[*]}"
    SUDO=""
    [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

if [ "${1:-}" != "--no-build" ]; then
    cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${LUMIGAUSS_CMAKE_ARGS:-}
    cmake --build build -j "$(nproc)"
fi
