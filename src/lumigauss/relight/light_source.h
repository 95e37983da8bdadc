#pragma once
// What `--light` names, turned into a world-frame environment radiance SH (degree 2, sh.h):
//   * a training photo of the run (its name as in appearance.json, or that name without its extension when
//     that is unique): the learned lighting of that photo, lighting.env_sh(index);
//   * a .txt file: 9 rows "R G B" of radiance SH in the world frame (shading/sh_text.h), with the sky
//     residual of the photo it was fitted to when `fit-light` wrote one ("#sky" rows);
//   * a panorama (.hdr, .exr, .png, .jpg/.jpeg): equirectangular, row 0 looking along the world up axis
//     (shading/envmap.h, frame from up_axis.h), projected onto the SH with exact pixel solid angles.
//     LDR panoramas (PNG/JPEG) are used as stored, value/255 with no sRGB linearisation, as the official
//     `process_environment_map_image` (research/lumigauss_official.md 6), optionally with its "fake HDR"
//     boost: every channel value above `hdr_threshold` is multiplied by `hdr_scale`.
// An explicit prefix forces the kind: "photo:NAME", "sh:FILE", "pano:FILE". Without one, a training photo
// name wins over a file of the same name.
#include <optional>
#include <string>
#include <vector>

#include "lumigauss/io/image.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

enum class LightKind { Photo, ShFile, Panorama };

const char* light_kind_name(LightKind kind);  // "training photo", "SH file", "panorama"

struct PanoramaOptions {
    Mat3d frame = Mat3d::identity();  // envmap.h: world direction = frame * panorama direction
    double hdr_threshold = 0.99;      // fake HDR: values > threshold ...
    double hdr_scale = 1.0;           // ... are multiplied by this (1: off); LDR files only
};

struct ResolvedLight {
    LightKind kind = LightKind::Photo;
    std::string source;  // the photo name or the file path
    int photo_index = -1;
    bool boosted = false;  // the fake HDR boost changed some pixel
    ShCoeffs<double> sh;
    Image panorama;  // a panorama light's pixels as used (boosted), for drawing its sky; else empty
    // For drawing its sky: a training photo's residual (a run with sky.lgsky), an SH file's "#sky" rows.
    std::optional<Sh4Coeffs<float>> sky_residual;
};

// True for the extensions read as LDR panoramas (.png, .jpg, .jpeg; case-insensitive).
bool is_ldr_panorama(const std::string& path);
// True for the extensions read as panoramas at all (LDR plus .hdr and .exr).
bool is_panorama_file(const std::string& path);

// The fake HDR boost in place: every value of the colour channels (the first three, or the only one of a
// gray image; alpha is left alone) above `threshold` is multiplied by `scale`. Returns how many changed.
std::size_t fake_hdr_boost(Image& pano, double threshold, double scale);

// Reads a panorama, boosts it if it is LDR and options.hdr_scale != 1, and projects it onto the SH in
// options.frame. Throws Error naming the file when it cannot be read or holds a non-finite value.
ShCoeffs<double> panorama_light(const std::string& path, const PanoramaOptions& options,
                                bool* boosted = nullptr, Image* pixels = nullptr);

// Resolves `--light` against a run (see above). Throws Error naming the argument, with a few of the run's
// photo names, when it is neither a photo nor an existing file of a known kind; or naming the file when it
// cannot be read.
ResolvedLight resolve_light(const std::string& spec, const TrainedRun& run, const PanoramaOptions& options);

// Rec. 709 luma of the DC coefficient: the mean radiance's brightness.
double dc_luma(const ShCoeffs<double>& sh);

// The factor that gives `sh` the median DC luma of the run's learned lights (`--match-exposure`): external
// environments (panoramas, SH files) come in arbitrary units, while the model's albedo was fitted to the
// learned ones. Throws Error when `sh` has no positive DC luma or the run has no photo.
double match_exposure_factor(const ShCoeffs<double>& sh, const TrainedRun& run);

ShCoeffs<double> scaled(const ShCoeffs<double>& sh, double factor);

}  // namespace lumigauss
