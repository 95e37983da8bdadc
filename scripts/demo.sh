#!/usr/bin/env bash
# The main job on a bundled default: installs dependencies, builds, generates the synthetic demo scene
# (photos under many lightings, COLMAP model, masks, ground truth), renders its ground-truth surfels, and
# trains a relightable model on it with the `fast` preset (about 3 minutes on 2 cores).
# Relighting joins this script when it lands (issue #5).
#   scripts/demo.sh [output folder, default: demo]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-demo}"

scripts/setup.sh
bin=build/lumigauss

echo "== 1/4 generating the synthetic scene (demo preset) in $out/scene"
"$bin" synth --preset demo -o "$out/scene" --force
echo "== 2/4 what the loader sees"
"$bin" info "$out/scene"
echo "== 3/4 rendering the ground-truth surfel model of the scene from every camera"
"$bin" render --ply "$out/scene/gt/surfels.ply" --scene "$out/scene" -o "$out/renders" --maps
echo "== 4/4 training a relightable model (fast preset: 1500 unshadowed, 100 transfer, 1400 shadowed iterations)"
"$bin" train "$out/scene" -o "$out/run" --preset fast --force

echo
echo "Done. Look at:"
echo "  $out/scene/images/        the photos (one lighting each), with masks/ and sparse/0/"
echo "  $out/scene/gt/            true albedo, normals, masks; env/ holds each lighting as SH + panorama"
echo "  $out/renders/             the rasterizer's renders of gt/surfels.ply (albedo colours), alpha, depth, normals"
echo "  $out/run/                 the trained model (model.ply, lighting.lgmlp, appearance.json), config, log.jsonl"
echo "  $out/run/previews/        photo | shadowed | unshadowed render under the learned lighting"
