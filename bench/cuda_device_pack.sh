#!/usr/bin/env bash
# Packs what bench/cuda_device_check.sh runs: the CUDA build's test and benchmark binaries and the CLI
# (stripped) and the non-system shared libraries they load, into one folder that can travel to a GPU machine.
#   bench/cuda_device_pack.sh BUILD_DIR PACK_DIR
set -euo pipefail
build=$1 pack=$2
rm -rf "$pack" && mkdir -p "$pack/lib"
for bin in tests/tests_cuda bench/raster_cuda_bench lumigauss; do
    strip -o "$pack/$(basename "$bin")" "$build/$bin"
done
for bin in "$pack"/tests_cuda "$pack"/raster_cuda_bench "$pack"/lumigauss; do
    ldd "$bin" | awk '/=> \//{print $3}' | grep -vE '/(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt)\.so' |
        while read -r lib; do cp -L "$lib" "$pack/lib/"; done
done
du -sh "$pack"
