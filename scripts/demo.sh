#!/usr/bin/env bash
# The main job on a bundled default: installs dependencies, builds, generates the synthetic demo scene
# (photos under many lightings, COLMAP model, masks, ground truth) and renders it.
# Training and relighting join this script when they land (issues #4 and #5).
#   scripts/demo.sh [output folder, default: demo]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-demo}"

scripts/setup.sh
bin=build/lumigauss

echo "== 1/3 generating the synthetic scene (demo preset) in $out/scene"
"$bin" synth --preset demo -o "$out/scene" --force
echo "== 2/3 what the loader sees"
"$bin" info "$out/scene"
echo "== 3/3 rendering the ground-truth surfel model of the scene from every camera"
"$bin" render --ply "$out/scene/gt/surfels.ply" --scene "$out/scene" -o "$out/renders" --maps

echo
echo "Done. Look at:"
echo "  $out/scene/images/        the photos (one lighting each), with masks/ and sparse/0/"
echo "  $out/scene/gt/            true albedo, normals, masks; env/ holds each lighting as SH + panorama"
echo "  $out/renders/             the rasterizer's renders of gt/surfels.ply (albedo colours), alpha, depth, normals"
