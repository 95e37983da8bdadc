#!/usr/bin/env bash
# The main job on a bundled default: installs dependencies, builds, generates the synthetic demo scene
# (photos under many lightings, COLMAP model, masks, ground truth), renders its ground-truth surfels, and
# trains a relightable model on it with the `fast` preset (about 3 minutes on 2 cores), scores it on the test
# photos under their true lighting (gt-env), relights it under another sky, turning the sky around, and writes
# the model as a web page that relights in any browser.
#   scripts/demo.sh [output folder, default: demo]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-demo}"

scripts/setup.sh
bin=build/lumigauss

echo "== 1/6 generating the synthetic scene (demo preset) in $out/scene"
"$bin" synth --preset demo -o "$out/scene" --force
echo "== 2/6 what the loader sees"
"$bin" info "$out/scene"
echo "== 3/6 rendering the ground-truth surfel model of the scene from every camera"
"$bin" render --ply "$out/scene/gt/surfels.ply" --scene "$out/scene" -o "$out/renders" --maps
echo "== 4/6 training a relightable model (fast preset: 1500 unshadowed, 100 transfer, 1400 shadowed iterations)"
"$bin" train "$out/scene" -o "$out/run" --preset fast --force
echo "== 5/6 evaluating novel views under novel lights (gt-env protocol)"
summary=$("$bin" eval "$out/run" --scene "$out/scene" --protocol gt-env -o "$out/eval" | tee /dev/stderr |
          grep '^eval-summary:')
echo "== 6/6 relighting the test views under the first sky of the scene, turned in 8 steps"
# The panorama of the scene's first sky: its own pixels behind the model (a degree-2 SH of a sunny sky rings
# black away from the sun), its SH for the shading.
sky=$(ls "$out/scene/env/"*_sh.txt | head -n 1)
[ -f "${sky%_sh.txt}.exr" ] && sky="${sky%_sh.txt}.exr"
"$bin" render "$out/run" --scene "$out/scene" --cameras test --light "$sky" --match-exposure --spin 8 \
    --background sky \
    -o "$out/relit"
# The model and its lights in one web page that relights in any browser (no lumigauss needed to open it).
"$bin" export "$out/run" --format html -o "$out/model.html"

value() { tr ' ' '\n' <<< "$summary" | sed -n "s/^$1=//p"; }
echo
echo "gt-env on the demo's test views (novel views under novel lights):"
printf '  shadowed PSNR %.2f dB, SSIM %.4f | unshadowed PSNR %.2f dB | albedo PSNR %.2f dB\n' \
    "$(value shadowed_psnr)" "$(value shadowed_ssim)" "$(value unshadowed_psnr)" "$(value albedo_psnr)"
printf '  normal error mean %.1f deg, median %.1f deg | sky pixels covered by surfels %.2f %%\n' \
    "$(value normal_mean_deg)" "$(value normal_median_deg)" "$(awk -v s="$(value sky_alpha)" 'BEGIN { print 100 * s }')"
printf '  under a light scale fitted per channel on the training photos instead: shadowed PSNR %.2f dB\n' \
    "$(value scaled_psnr)"
echo
echo "Done. Look at:"
echo "  $out/scene/images/        the photos (one lighting each), with masks/ and sparse/0/"
echo "  $out/scene/gt/            true albedo, normals, masks; env/ holds each lighting as SH + panorama"
echo "  $out/renders/             the rasterizer's renders of gt/surfels.ply (albedo colours), alpha, depth, normals"
echo "  $out/run/                 the trained model (model.ply, lighting.lgmlp, appearance.json), config, log.jsonl"
echo "  $out/run/previews/        photo | shadowed | unshadowed render under the learned lighting"
echo "  $out/run/progress.html    the run's loss, PSNR and surfel plots and its previews at every checkpoint"
echo "  $out/eval/                report.md, metrics.json and contact sheets of the test photos"
echo "  $out/relit/               the test views relit (shadowed, unshadowed, shadow, albedo, normals, ...) per sky turn"
echo "  $out/model.html           the model in a web page: open it in a browser to orbit and relight it"
