#include "lumigauss/train/empty_space_prune.h"

#include <string>

#include "lumigauss/util/error.h"

namespace lumigauss {

void add_empty_space_weights(Rasterizer& rasterizer, const Camera& camera, SurfelBatch<float>& geometry,
                             std::span<const float> constrained, std::span<const float> empty,
                             EmptySpaceWeights& weights) {
    const std::size_t pixels = std::size_t(camera.width) * std::size_t(camera.height);
    if (constrained.size() != pixels || (!empty.empty() && empty.size() != pixels))
        throw Error("empty-space weights: the masks hold " + std::to_string(constrained.size()) + " and " +
                    std::to_string(empty.size()) + " values for a " + std::to_string(camera.width) + " x " +
                    std::to_string(camera.height) + " image");
    if (weights.constrained.size() != geometry.size()) weights.reset(geometry.size());
    // Channel 0 sums the weight over the constrained pixels, channel 1 over the empty ones.
    geometry.channels = 2;
    geometry.colors.assign(2 * geometry.size(), 1.0f);
    RasterImages<float> images;
    rasterizer.forward(camera, geometry, RasterSettings<float>{}, images);
    RasterImageGrads<float> grads;
    grads.width = camera.width, grads.height = camera.height, grads.channels = 2;
    grads.color.assign(2 * pixels, 0.0f);
    for (std::size_t p = 0; p < pixels; ++p) {
        grads.color[2 * p] = constrained[p];
        grads.color[2 * p + 1] = empty.empty() ? 0.0f : empty[p];
    }
    SurfelGrads<float> sums;
    rasterizer.backward(geometry, grads, sums);
    for (std::size_t i = 0; i < geometry.size(); ++i) {
        weights.constrained[i] += double(sums.colors[2 * i]);
        weights.empty[i] += double(sums.colors[2 * i + 1]);
        if (double(sums.colors[2 * i]) >= kSeenPixels) ++weights.photos_seeing[i];
    }
}

std::vector<std::uint8_t> keep_outside_empty_space(const EmptySpaceWeights& weights, double max_share,
                                                   std::size_t& removed) {
    const std::size_t n = weights.constrained.size();
    std::vector<std::uint8_t> keep(n, 1);
    removed = 0;
    for (std::size_t i = 0; i < n; ++i)
        if (weights.constrained[i] > 0 && weights.empty[i] > max_share * weights.constrained[i])
            keep[i] = 0, ++removed;
    return keep;
}

std::size_t remove_low_contribution(const EmptySpaceWeights& weights, double min_pixels,
                                    std::vector<std::uint8_t>& keep) {
    if (keep.size() != weights.constrained.size())
        throw Error("low-contribution prune: " + std::to_string(keep.size()) + " flags for " +
                    std::to_string(weights.constrained.size()) + " surfels");
    std::size_t removed = 0;
    for (std::size_t i = 0; i < keep.size(); ++i)
        if (keep[i] && weights.constrained[i] < min_pixels) keep[i] = 0, ++removed;
    return removed;
}

std::size_t remove_weakly_seen_ground(const EmptySpaceWeights& weights, std::span<const float> centres,
                                      Vec3f up, double max_height, int min_photos,
                                      std::vector<std::uint8_t>& keep) {
    const std::size_t n = weights.photos_seeing.size();
    if (keep.size() != n || centres.size() != 3 * n)
        throw Error("weakly-seen-ground prune: " + std::to_string(keep.size()) + " flags and " +
                    std::to_string(centres.size() / 3) + " centres for " + std::to_string(n) + " surfels");
    std::size_t removed = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3f c{centres[3 * i], centres[3 * i + 1], centres[3 * i + 2]};
        if (keep[i] && double(dot(c, up)) < max_height &&
            weights.photos_seeing[i] < std::uint32_t(min_photos))
            keep[i] = 0, ++removed;
    }
    return removed;
}

}  // namespace lumigauss
