#pragma once
// Surfels that paint empty space. A surfel whose blend weight in the training photos falls mostly on pixels
// that must stay empty (the sky of a sky mask, the outside of an object mask, or without masks the pixels
// whose sky the photo already shows) is a sky painter: where the sky drawn behind the surfels is a poor
// model of the photo's sky (a degree-2 SH near the horizon), large faint surfels survive the alpha penalty
// by painting it, and from another viewpoint they hang in front of the scene as a veil. Summed over all the
// photos, a surface the photos see has most of its weight on the scene; a painter has most on the sky.
//
// What a surfel contributes to pixel p is its blend weight w_ip = alpha_ip T_ip, so that for colours of 1
// the colour gradient of surfel i under a pixel gradient g_p is sum_p w_ip g_p: one forward and one
// backward per photo give both sums.
//
// The same sums find the surfels that hardly matter: summed over every photo, a surfel hidden behind the
// surface or outside every photo has a weight of a few pixels at most. On plaza (fast preset) 13 % of
// the surfels add less than 4 pixels each; removing them changes no score by more than 0.03 dB.
#include <cstdint>
#include <span>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/vec.h"
#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/rasterizer.h"

namespace lumigauss {

// Per surfel, summed over the photos added: its blend weight over the pixels a photo constrains, and the
// part of it on pixels that must stay empty.
struct EmptySpaceWeights {
    std::vector<double> constrained, empty;
    // How many of the photos added give the surfel at least kSeenPixels of weight on constrained pixels.
    std::vector<std::uint32_t> photos_seeing;

    void reset(std::size_t surfels) {
        constrained.assign(surfels, 0.0), empty.assign(surfels, 0.0), photos_seeing.assign(surfels, 0);
    }
};

// The blend weight (pixels) from which a photo counts as seeing a surfel.
inline constexpr double kSeenPixels = 1.0;

// Adds one photo. `geometry` holds the surfels as rasterized (SurfelModel::activated; its colours are
// overwritten); `constrained` and `empty` hold one weight per pixel of the camera's image (empty <=
// constrained: the pixels that must stay empty are constrained too). `empty` may be empty (none).
void add_empty_space_weights(Rasterizer& rasterizer, const Camera& camera, SurfelBatch<float>& geometry,
                             std::span<const float> constrained, std::span<const float> empty,
                             EmptySpaceWeights& weights);

// 0 for the surfels with more than `max_share` of their weight on empty pixels, 1 for the others (a
// surfel no photo sees is kept: nothing says what it is). `removed` counts the zeros.
std::vector<std::uint8_t> keep_outside_empty_space(const EmptySpaceWeights& weights, double max_share,
                                                   std::size_t& removed);

// Sets keep[i] = 0 for the surfels still kept whose summed weight over the constrained pixels is below
// `min_pixels`: together they add less colour to every training photo than that many pixels (hidden behind
// the surface, or outside every photo). Returns how many it removed.
std::size_t remove_low_contribution(const EmptySpaceWeights& weights, double min_pixels,
                                    std::vector<std::uint8_t>& keep);

// Sets keep[i] = 0 for the surfels still kept whose centre lies below `max_height` along `up` (unit; height
// = dot(centre, up)) and that fewer than `min_photos` photos see (photos_seeing). A surface seen by one
// photo can take any depth and tilt along that photo's rays and still match it; the ground around the
// cameras is seen so (steeply by the nearest photo, at a grazing angle or not at all by the others), and from
// a new viewpoint such surfels are streaks and slashes across it. `centres`: 3 floats per surfel. Returns
// how many it removed.
std::size_t remove_weakly_seen_ground(const EmptySpaceWeights& weights, std::span<const float> centres,
                                      Vec3f up, double max_height, int min_photos,
                                      std::vector<std::uint8_t>& keep);

}  // namespace lumigauss
