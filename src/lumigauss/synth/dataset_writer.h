#pragma once
// The files of a synthetic dataset (layout and conventions of data/plaza; see the generated README.md).
#include <cstdint>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/synth/gt_surfels.h"
#include "lumigauss/synth/ray_tracer.h"
#include "lumigauss/synth/sfm_points.h"
#include "lumigauss/synth/sky.h"
#include "lumigauss/synth/synth.h"
#include "lumigauss/synth/world.h"

namespace lumigauss::synth {

// One photo: what was decided about it before rendering.
struct Photo {
    std::string name;  // train_0000.png, test_0000.png
    int image_id = 0;  // 1-based, training photos first (also the COLMAP camera id)
    bool train = true;
    int condition = 0;  // index into the conditions
    double exposure = 1.0;
    Camera camera;
    int n_transients = 0;
};

// Creates the output folders (refusing a non-empty folder unless options.overwrite, which then removes only
// the dataset's own files and folders).
void prepare_output_dir(const SynthOptions& options);

// images/NAME (8-bit sRGB), masks/NAME, sky_masks/NAME (255 - gt/mask: the pixel sees no geometry),
// gt/{albedo,normal,mask,transient,sun_visibility}/NAME.
// Returns the photo's 8-bit RGB pixels (interleaved) for the point colours.
// With object_masks, masks/NAME is the landmark's coverage (SynthOptions::object_masks).
std::vector<std::uint8_t> write_photo_files(const std::string& dir, const Photo& photo, const ViewBuffers& b,
                                            bool object_masks = false);

// env/COND_sh.txt (sky + sun), env/COND.exr (equirect radiance 128 x 64), env/COND.png (sRGB preview).
void write_environment(const std::string& dir, const LightCondition& c);

void write_split_csv(const std::string& dir, const std::vector<Photo>& photos);

struct MetaInputs {
    const SynthOptions* options;
    const Landmark* landmark;
    const std::vector<Photo>* photos;
    const std::vector<LightCondition>* conditions;
    int n_points;
    double noise_sigma;
    double scene_diag;
    const GtSurfels* gt_surfels;  // empty model when none were written
};
void write_meta_json(const std::string& dir, const MetaInputs& in);
void write_readme(const std::string& dir, const MetaInputs& in);

// Camera-to-world 4x4 (OpenCV axes) of a world-to-camera camera.
std::vector<std::vector<double>> camera_to_world(const Camera& camera);

}  // namespace lumigauss::synth
