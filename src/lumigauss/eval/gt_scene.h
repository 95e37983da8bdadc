#pragma once
// A scene that ships its true lighting, in the layout of data/plaza (and of what `lumigauss synth` writes):
// meta.json (per image: name, split, condition, exposure), env/COND_sh.txt (the true radiance SH of each
// condition), optionally env/COND.{exr,hdr} (its panorama) and gt/{mask,albedo,normal}/NAME.png. What the
// gt-env protocol (eval/gt_env.h) and its light-scale fits (eval/light_scale.h) read of it.
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/io/dataset.h"
#include "lumigauss/io/image.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

struct GtImageMeta {
    std::string name, split, condition;
    double exposure = 1.0;
};

struct GtSceneMeta {
    std::string root, meta_path;
    std::vector<GtImageMeta> images;
    std::map<std::string, std::string>
        condition_sh;  // condition id -> SH file ("sh" of meta.json conditions)

    const GtImageMeta* find(const std::string& name) const;  // nullptr if absent
    // The SH file of a condition: meta.json's "sh" entry of it, else env/COND_sh.txt.
    std::string sh_path(const std::string& condition) const;
};

// Reads <root>/meta.json. Throws Error naming the file if it is missing or malformed.
GtSceneMeta load_gt_scene_meta(const std::string& scene_root);
// The true radiance SH of a condition; throws Error naming the SH file if it is missing or malformed.
ShCoeffs<double> load_condition_sh(const GtSceneMeta& meta, const std::string& condition);

// <root>/gt/<kind>/<image name with a .png extension> (kind: mask, albedo, normal).
std::string gt_image_path(const std::string& root, const std::string& kind, const std::string& image_name);

// A ground-truth image with `channels` channels at width x height (area-resampled if the file differs).
Image load_gt_image(const std::string& path, int width, int height, int channels);

// The evaluation mask of a view (gt_env.h, step 3), and whether the scene has a gt/mask for it.
Image evaluation_mask(const GtSceneMeta& meta, const Dataset& scene, const View& view, bool& has_gt_mask);

// The environment of a photo: scale_c * exposure * (true SH of its condition), per channel.
ShCoeffs<float> scaled_true_env(const GtSceneMeta& meta, const GtImageMeta& image,
                                const std::array<double, 3>& scale);

// The conditions' panoramas (env/COND.exr or .hdr), each read once.
class TruePanoramas {
  public:
    explicit TruePanoramas(const GtSceneMeta& meta) : meta_(meta) {}
    // nullptr when the scene has no panorama of the condition.
    const Image* find(const std::string& condition);

  private:
    const GtSceneMeta& meta_;
    std::map<std::string, std::optional<Image>> cache_;
};

}  // namespace lumigauss
