#!/usr/bin/env bash
# The CUDA backend's checks on a GPU machine that has the CUDA driver but not this project's build
# dependencies: runs binaries built elsewhere (with -DLUMIGAUSS_CUDA=ON), from a folder that also holds the
# shared libraries they need (bench/cuda_device_pack.sh makes it).
#   bench/cuda_device_check.sh PACK_DIR [LOG_DIR]
# 1. the CUDA tests (GPU against CPU, directly and through render/rasterizer.h), 2. `lumigauss render --ply`
# on both backends (a synthetic scene's ground-truth surfels), their PNGs compared, 3. `train --backend cuda`
# against `--backend cpu` on a synthetic scene (TRAIN_PRESET, default fast): time per iteration and the
# gt-env metrics of each run, 4. the benchmark (medians printed), 5. the tests under compute-sanitizer
# (memcheck, racecheck) when it is installed. SKIP_TRAIN=1 leaves out step 3.
set -uo pipefail
pack=$(cd "$1" && pwd)
logs=${2:-/tmp/lumigauss-cuda-check}
mkdir -p "$logs"
export LD_LIBRARY_PATH="$pack/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv 2>&1 | tee "$logs/gpu.txt"
status=0
echo "== CUDA tests"
"$pack/tests_cuda" --gtest_filter='CudaRasterizer*:RasterizerBackends*' 2>&1 | tee "$logs/tests.txt" | tail -25 || status=1
echo "== lumigauss render --ply: GPU against CPU"
work=$(mktemp -d)
"$pack/lumigauss" synth -o "$work/scene" --preset tiny --width 320 --height 240 --gt-surfels 50000 >/dev/null || status=1
for backend in cpu cuda; do
    "$pack/lumigauss" render --ply "$work/scene/gt/surfels.ply" --scene "$work/scene" --backend "$backend" \
        -o "$work/$backend" | tail -1 || status=1
done
python3 - "$work" <<'PY' || status=1
import sys, pathlib
import numpy as np
from PIL import Image
work = pathlib.Path(sys.argv[1])
worst, count = 0, 0
for cpu in sorted((work / "cpu").glob("*.png")):
    a = np.asarray(Image.open(cpu), dtype=np.int32)
    b = np.asarray(Image.open(work / "cuda" / cpu.name), dtype=np.int32)
    worst, count = max(worst, int(np.abs(a - b).max())), count + 1
print(f"{count} images; largest difference {worst} / 255")
sys.exit(0 if count > 0 and worst <= 1 else 1)
PY
if [ -z "${SKIP_TRAIN:-}" ]; then
    echo "== train --backend cuda against --backend cpu (${TRAIN_PRESET:-fast})"
    "$pack/lumigauss" synth -o "$work/train_scene" --preset demo >/dev/null || status=1
    for backend in cpu cuda; do
        "$pack/lumigauss" train "$work/train_scene" -o "$work/run_$backend" --preset "${TRAIN_PRESET:-fast}" \
            --backend "$backend" -q 2>&1 | tee "$logs/train_$backend.txt" | grep -E "done|rasterizing|time in" ||
            status=1
        "$pack/lumigauss" eval "$work/run_$backend" --scene "$work/train_scene" --protocol gt-env \
            -o "$work/eval_$backend" --backend "$backend" -q 2>&1 | tee "$logs/eval_$backend.txt" | tail -1 ||
            status=1
    done
fi
echo "== benchmark"
"$pack/raster_cuda_bench" --benchmark_repetitions="${REPS:-5}" --benchmark_report_aggregates_only=true \
    --benchmark_min_time="${MIN_TIME:-0.2}" ${FILTER:+--benchmark_filter="$FILTER"} \
    --benchmark_out="$logs/bench.json" --benchmark_out_format=json 2>&1 | tee "$logs/bench.txt" |
    grep -E 'GPU|median' || status=1
if command -v compute-sanitizer >/dev/null; then
    for tool in memcheck racecheck; do
        echo "== compute-sanitizer $tool"
        timeout "${SANITIZER_TIMEOUT:-90}" compute-sanitizer --tool "$tool" --error-exitcode 9 "$pack/tests_cuda" \
            --gtest_filter='CudaRasterizer*:RasterizerBackends*' \
            >"$logs/sanitizer_$tool.txt" 2>&1
        echo "exit $?"
        tail -4 "$logs/sanitizer_$tool.txt"
    done
fi
exit $status
