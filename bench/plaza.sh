#!/usr/bin/env bash
# Trains LumiGauss on a scene with ground-truth lighting (default: ../shared/data/plaza) with the paper preset,
# evaluates it with the gt-env protocol (novel views under novel lights), and prints one table.
#
#   bench/plaza.sh [--scene DIR] [--runs DIR] [--build DIR] [--preset paper|fast] [--ablations] [-- TRAIN ARGS]
#
# Runs go to --runs (default runs/<scene name>): a run that has its model is only evaluated again; one with a
# checkpoint is resumed (so an interrupted benchmark continues where it stopped); otherwise it is trained.
# --ablations adds the rows of the paper's ablation (Table 1, lower part), each a full training:
#   no_stage1      without the unshadowed warm-up: transfer fitting from iteration 1 (warmup=1, then the preset's
#                  stage-2 length: 500 iterations as officially, 100 in the fast preset), then shadowed.
#                  (Densification then runs in stage 3 until 15k: the official rule accumulates statistics
#                  outside stage 2, i.e. before warmup or after start_shadowed.)
#   no_cons_unsh   without l_consistency and the unshadowed reconstruction term in the last stage
#                  (consistency_final_ratio=0, lambda_unshadowed_stage3=0; stage 2 still fits the transfer)
#   no_range01     without l_[0,1] (lambda_range01=0)
#   no_env_pos     without l_+ (lambda_env=0)
# Training time is the wall time summed over the run's log segments (a resumed run adds its segments).
set -euo pipefail
cd "$(dirname "$0")/.."

scene=../shared/data/plaza
runs=""
build=build
preset=paper
ablations=0
extra=()
while [[ $# -gt 0 ]]; do
    case "$1" in
        --scene) scene="$2"; shift 2 ;;
        --runs) runs="$2"; shift 2 ;;
        --build) build="$2"; shift 2 ;;
        --preset) preset="$2"; shift 2 ;;
        --ablations) ablations=1; shift ;;
        --) shift; extra=("$@"); break ;;
        *) echo "bench/plaza.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
done
[[ -d "$scene" ]] || { echo "bench/plaza.sh: scene folder '$scene' not found" >&2; exit 2; }
[[ -f "$scene/meta.json" ]] || { echo "bench/plaza.sh: '$scene/meta.json' not found (gt-env needs ground truth)" >&2; exit 2; }
runs="${runs:-runs/$(basename "$scene")}"
bin="$build/lumigauss"
[[ -x "$bin" ]] || { echo "bench/plaza.sh: $bin not built (run scripts/setup.sh, or pass --build)" >&2; exit 2; }

declare -a names=(baseline) settings=("")
if [[ $ablations == 1 ]]; then
    names+=(no_stage1 no_cons_unsh no_range01 no_env_pos)
    # Stage 2 (transfer fitting) keeps the preset's length: 500 iterations in the paper preset, 100 in fast.
    stage2=$([[ $preset == fast ]] && echo 100 || echo 500)
    settings+=("--set warmup=1 --set start_shadowed=$((stage2 + 1))"
               "--set consistency_final_ratio=0 --set lambda_unshadowed_stage3=0"
               "--set lambda_range01=0"
               "--set lambda_env=0")
fi

# Wall time of a run: the last elapsed_s of each log segment (elapsed restarts at every resume), summed.
train_seconds() {
    awk -F'"elapsed_s":' 'NF > 1 { split($2, a, /[,}]/); t = a[1] + 0;
                                    if (t < last) total += last; last = t }
                          END { printf "%.0f", total + last }' "$1/log.jsonl"
}

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
        echo "== $name: training ($preset preset) -> $run"
        "$bin" train "$scene" -o "$run" --preset "$preset" "${args[@]}"
    fi
    echo "== $name: evaluating (gt-env)"
    line=$("$bin" eval "$run" --scene "$scene" --protocol gt-env -o "$run/eval" | tee /dev/stderr |
           grep '^eval-summary:')
    surfels=$(awk -F'"surfels":' 'NF > 1 { split($2, a, /[,}]/); s = a[1] } END { print s }' "$run/log.jsonl")
    echo "$name $(train_seconds "$run") $surfels ${line#eval-summary: }" >> "$summary"
done

echo
echo "gt-env on $scene (novel views under novel lights; light scale fitted on training photos only)"
printf '%-14s %9s %8s %9s %8s %9s %9s %9s %9s %10s %8s\n' run "shad.PSNR" "shad.SSIM" "unsh.PSNR" \
       "unsh.SSIM" "alb.PSNR" "norm.mean" "norm.med" "train min" "surfels" "render ms"
while read -r name seconds surfels rest; do
    declare -A m=()
    for kv in $rest; do m[${kv%%=*}]=${kv#*=}; done
    printf '%-14s %9.2f %8.4f %9.2f %8.4f %9.2f %9.2f %9.2f %9.1f %10s %8.1f\n' "$name" \
           "${m[shadowed_psnr]}" "${m[shadowed_ssim]}" "${m[unshadowed_psnr]}" "${m[unshadowed_ssim]}" \
           "${m[albedo_psnr]}" "${m[normal_mean_deg]}" "${m[normal_median_deg]}" \
           "$(awk -v s="$seconds" 'BEGIN { print s / 60 }')" "$surfels" "${m[render_ms]}"
    unset m
done < "$summary"
