#!/usr/bin/env bash
# Trains LumiGauss on a scene with ground-truth lighting (default: ../shared/data/plaza), evaluates every run
# with the gt-env protocol on the test views (novel views under novel lights) and on the training views
# (each under its own true light), and prints one table.
#
#   bench/plaza.sh [--scene DIR] [--runs DIR] [--build DIR] [--rows LIST] [--ablations] [--paper-ablations]
#                  [-- TRAIN ARGS]
#
# Rows (--rows, comma-separated; default "default,paper,fast"; any ablation row below can be named too):
#   default        the default preset (40k iterations, sky and floater handling)
#   paper          the official LumiGauss (40k)
#   fast           the fast variant of the default preset (3k)
#   paper-fast     the official schedule shrunk to 3k
# --ablations adds, on the fast preset, each improvement of the default preset switched off alone (issue #25):
#   fast-no-point-normals   surfels start randomly turned, as officially (init_normals_from_points=false)
#   fast-no-sky             no sky behind the surfels (sky_background=false: the sky losses go with it)
#   fast-no-sky-alpha       the sky masks do not push alpha to 0 (lambda_sky_alpha=0)
#   fast-no-sky-free-reg    the normal/distortion losses also on sky pixels (sky_free_regularizers=false)
#   fast-no-prune-end       nothing pruned after densification, as officially (prune_until_end=false)
#   fast-no-empty-prune     surfels painting the sky (most of their weight on empty pixels) not removed
#                           (empty_space_prune_share=0)
#   fast-no-low-contribution  surfels adding under 4 pixels to all the photos kept (min_contribution_pixels=0)
#   fast-no-traced-shadows  the shadow transfer learned per surfel, as officially (geometric_transfer_every=0)
#   fast-no-ground-seeds    no starting points on the bare ground under the cameras (ground_seeds=false)
#   fast-no-ground          black below the horizon where no surfel covers a pixel (ground_backdrop=false)
#   fast-no-grazing-side    level surfels seen at grazing angles show the camera-facing side, as officially
#                           (grazing_side_degrees=0)
#   fast-sky-pins-light     the sky's pixels shape the light again, no sky residual, no ground-light prior
#                           (sky_pins_light=true, sky_residual=false, lambda_ground_light=0,
#                           lambda_sky_hemisphere=0: the fast preset before session 37)
#   fast-no-ground-light    the free light without the ground-light prior (lambda_ground_light=0)
#   fast-no-sky-hemisphere  each photo's unseen sky left to the fit (lambda_sky_hemisphere=0)
#   fast-no-horizon         the sky drawn in every direction, below the horizon too (sky_horizon_fade=0;
#                           its gt-env then also fills holes with the true sky's lower half, as trained)
#   fast-no-sky-masks       the scene's sky masks ignored (use_sky_masks=false): the background-explained
#                           pixels carry the alpha penalty instead
#   fast-no-sky-masks-no-bg-alpha   and without that penalty either (lambda_background_alpha=0)
# --paper-ablations adds the paper's own ablation rows (Table 1, lower part) on the paper preset:
#   no_stage1, no_cons_unsh, no_range01, no_env_pos (see bench/RESULTS.md, session 6).
#
# Runs go to --runs (default runs/<scene name>): a run that has its model is only evaluated again; one with a
# checkpoint is resumed (so an interrupted benchmark continues where it stopped); otherwise it is trained.
# Training time is the wall time summed over the run's log segments (a resumed run adds its segments).
set -euo pipefail
cd "$(dirname "$0")/.."

scene=../shared/data/plaza
runs=""
build=build
rows="default,paper,fast"
ablations=0
paper_ablations=0
extra=()
while [[ $# -gt 0 ]]; do
    case "$1" in
        --scene) scene="$2"; shift 2 ;;
        --runs) runs="$2"; shift 2 ;;
        --build) build="$2"; shift 2 ;;
        --rows) rows="$2"; shift 2 ;;
        --ablations) ablations=1; shift ;;
        --paper-ablations) paper_ablations=1; shift ;;
        --) shift; extra=("$@"); break ;;
        *) echo "bench/plaza.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
done
[[ -d "$scene" ]] || { echo "bench/plaza.sh: scene folder '$scene' not found" >&2; exit 2; }
[[ -f "$scene/meta.json" ]] || { echo "bench/plaza.sh: '$scene/meta.json' not found (gt-env needs ground truth)" >&2; exit 2; }
runs="${runs:-runs/$(basename "$scene")}"
bin="$build/lumigauss"
[[ -x "$bin" ]] || { echo "bench/plaza.sh: $bin not built (run scripts/setup.sh, or pass --build)" >&2; exit 2; }

# The fast preset with one improvement of the default preset switched off (issue #25): name, then its
# settings, in the order --ablations trains them.
ablations_list=(
    fast-no-point-normals "--set init_normals_from_points=false"
    fast-no-sky "--set sky_background=false"
    fast-no-sky-alpha "--set lambda_sky_alpha=0"
    fast-no-sky-free-reg "--set sky_free_regularizers=false"
    fast-no-prune-end "--set prune_until_end=false"
    fast-no-empty-prune "--set empty_space_prune_share=0"
    fast-no-low-contribution "--set min_contribution_pixels=0"
    fast-no-traced-shadows "--set geometric_transfer_every=0"
    fast-no-ground-seeds "--set ground_seeds=false"
    fast-no-ground "--set ground_backdrop=false"
    fast-no-grazing-side "--set grazing_side_degrees=0"
    fast-sky-pins-light "--set sky_pins_light=true --set sky_residual=false --set lambda_ground_light=0 --set lambda_sky_hemisphere=0"
    fast-no-ground-light "--set lambda_ground_light=0"
    fast-no-sky-hemisphere "--set lambda_sky_hemisphere=0"
    fast-no-horizon "--set sky_horizon_fade=0"
    fast-no-sky-masks "--set use_sky_masks=false"
    fast-no-sky-masks-no-bg-alpha "--set use_sky_masks=false --set lambda_background_alpha=0"
)
# The train arguments of an ablation row; empty for other names.
ablation_settings() {
    for ((i = 0; i < ${#ablations_list[@]}; i += 2)); do
        [[ "${ablations_list[$i]}" == "$1" ]] && { echo "--preset fast ${ablations_list[$((i + 1))]}"; return; }
    done
}

declare -a names=() settings=()
add_row() { names+=("$1"); settings+=("$2"); }
IFS=',' read -r -a wanted <<< "$rows"
for row in "${wanted[@]}"; do
    case "$row" in
        default|paper|fast|paper-fast) add_row "$row" "--preset $row" ;;
        *) [[ -n "$(ablation_settings "$row")" ]] ||
               { echo "bench/plaza.sh: unknown row '$row' (default, paper, fast, paper-fast or an ablation)" >&2
                 exit 2; }
           add_row "$row" "$(ablation_settings "$row")" ;;
    esac
done
if [[ $ablations == 1 ]]; then
    for ((i = 0; i < ${#ablations_list[@]}; i += 2)); do
        add_row "${ablations_list[$i]}" "--preset fast ${ablations_list[$((i + 1))]}"
    done
fi
if [[ $paper_ablations == 1 ]]; then
    add_row no_stage1 "--preset paper --set warmup=1 --set start_shadowed=501"
    add_row no_cons_unsh "--preset paper --set consistency_final_ratio=0 --set lambda_unshadowed_stage3=0"
    add_row no_range01 "--preset paper --set lambda_range01=0"
    add_row no_env_pos "--preset paper --set lambda_env=0"
fi

# Wall time of a run: the last elapsed_s of each log segment (elapsed restarts at every resume), summed.
train_seconds() {
    awk -F'"elapsed_s":' 'NF > 1 { split($2, a, /[,}]/); t = a[1] + 0;
                                    if (t < last) total += last; last = t }
                          END { printf "%.0f", total + last }' "$1/log.jsonl"
}
# One key of an eval-summary line.
summary_value() { tr ' ' '\n' <<< "$1" | sed -n "s/^$2=//p"; }

summary=$(mktemp)
trap 'rm -f "$summary"' EXIT
for i in "${!names[@]}"; do
    name=${names[$i]}
    run="$runs/$name"
    # shellcheck disable=SC2206
    args=(${settings[$i]} "${extra[@]}")
    if [[ -f "$run/model.ply" ]]; then
        echo "== $name: trained already ($run)"
    elif [[ -f "$run/checkpoint.lgck" ]]; then
        echo "== $name: resuming $run"
        "$bin" train "$scene" -o "$run" --resume
    else
        echo "== $name: training (${settings[$i]}) -> $run"
        "$bin" train "$scene" -o "$run" "${args[@]}"
    fi
    echo "== $name: evaluating (gt-env, test views, then training views)"
    test_line=$("$bin" eval "$run" --scene "$scene" --protocol gt-env -o "$run/eval" | tee /dev/stderr |
                grep '^eval-summary:')
    train_line=$("$bin" eval "$run" --scene "$scene" --protocol gt-env --cameras train --no-sheets \
                 -o "$run/eval_train" | grep '^eval-summary:')
    surfels=$(awk -F'"surfels":' 'NF > 1 { split($2, a, /[,}]/); s = a[1] } END { print s }' "$run/log.jsonl")
    echo "$name $(train_seconds "$run") $surfels $(summary_value "$train_line" normal_median_deg)" \
         "${test_line#eval-summary: }" >> "$summary"
done

echo
echo "gt-env on $scene (test views: novel views under novel lights; light scale fitted on training photos only)"
printf '%-30s %8s %8s %8s %8s %8s %8s %8s %8s %7s %7s %7s %7s %7s %7s %8s %8s %8s %8s %8s %8s\n' run "shad.PSNR" \
       "shad.SSIM" "unsh.PSNR" "unsh.SSIM" "alb.PSNR" "norm.mean" "norm.med" "trainmed" "sky%" "skyveil" "lightres" \
       "seenres" "lightdir" "empty%" "cov.PSNR" "img.PSNR" "walls" "wallgain" "train min" "surfels"
reference=""
while read -r name seconds surfels train_median rest; do
    declare -A m=()
    for kv in $rest; do m[${kv%%=*}]=${kv#*=}; done
    printf '%-30s %8.2f %8.4f %8.2f %8.4f %8.2f %8.2f %8.2f %8.2f %7.2f %7.4f %7.3f %7.3f %7.2f %7.2f %8.2f %8.2f %8.2f %8.3f %8.1f %8s\n' "$name" \
           "${m[shadowed_psnr]}" "${m[shadowed_ssim]}" "${m[unshadowed_psnr]}" "${m[unshadowed_ssim]}" \
           "${m[albedo_psnr]}" "${m[normal_mean_deg]}" "${m[normal_median_deg]}" "$train_median" \
           "$(awk -v s="${m[sky_alpha]}" 'BEGIN { print 100 * s }')" "${m[sky_mean_alpha]:-nan}" "${m[light_residual]}" \
           "${m[light_seen_residual]:-nan}" "${m[light_direction]:-nan}" "$(awk -v s="${m[empty]}" 'BEGIN { print 100 * s }')" "${m[covered_psnr]}" \
           "${m[scaled_psnr]:-nan}" "${m[other_psnr]:-nan}" "${m[other_gain]:-nan}" \
           "$(awk -v s="$seconds" 'BEGIN { print s / 60 }')" "$surfels"
    reference="${m[light_reference_residual]:-nan} ${m[light_reference_seen_residual]:-nan}"
    unset m
done < "$summary"
echo "(norm.mean/norm.med: normal error on the test views, degrees; trainmed: median normal error on the"
echo " training views; sky%: test-view sky pixels (gt/mask = 0) where the render's alpha > 0.5; skyveil: the"
echo " mean alpha over those sky pixels (faint surfels in front of the cameras that never reach 0.5); lightres:"
echo " relative residual of the light-scale fit, 0 when every learned light is one common scale of the true one;"
echo " seenres: the same on the part of each light its photo's normals can tell apart (the rest is left to priors);"
echo "  lights fitted to the photos' shading with the TRUE albedo and normals reach (lightres seenres):" \
     "${reference:-nan nan};"
echo " lightdir: how directional the learned lights are, median |band 1|/DC over the true one's (1 = as the truth);"
echo " empty%: evaluated test pixels the model leaves empty (alpha <= 0.5); cov.PSNR: shadowed PSNR over the others;"
echo " img.PSNR: shadowed PSNR with the light scale fitted per channel on the training images instead;"
echo " walls: shadowed PSNR over the pixels whose true normal is not within 25 deg of up (walls, roofs);"
echo " wallgain: the gain that would take the render onto the photos there, mean over RGB: 1 when their"
echo " albedo is right against the ground's)"
