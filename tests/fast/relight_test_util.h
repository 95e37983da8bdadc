#pragma once
// Shared pieces of the relight_* tests: a random relightable model in front of a camera, an in-memory
// trained run around it, and a bright environment.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"
#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/train/gaussian_model.h"

namespace lumigauss::relight_test {

inline double uniform(std::mt19937_64& rng, double lo = -1.0, double hi = 1.0) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// `count` surfels inside the view of `cam` at depths 2..6, random orientation, opacity, albedo in
// (0.2, 0.8) and transfer sets with a channel-0 DC near 1.
inline std::vector<std::vector<float>> random_raw(const Camera& cam, std::uint64_t seed, std::size_t count) {
    std::mt19937_64 rng(seed);
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].assign(count * std::size_t(GaussianModel::width(ModelParam(p))), 0.0f);
    const Mat3d rt = transpose(cam.rotation);
    for (std::size_t i = 0; i < count; ++i) {
        const double z = uniform(rng, 2.0, 6.0);
        const Vec3d p = rt * (Vec3d{uniform(rng) * 0.5 * z, uniform(rng) * 0.5 * z, z} - cam.translation);
        for (int k = 0; k < 3; ++k) raw[int(ModelParam::Xyz)][3 * i + std::size_t(k)] = float(p[k]);
        for (int k = 0; k < 4; ++k)
            raw[int(ModelParam::Rotation)][4 * i + std::size_t(k)] =
                float(uniform(rng) + (k == 0 ? 1.5 : 0.0));
        for (int k = 0; k < 2; ++k)
            raw[int(ModelParam::Scaling)][2 * i + std::size_t(k)] = float(uniform(rng, -2.5, -1.0));
        raw[int(ModelParam::Opacity)][i] = float(uniform(rng, -1.0, 3.0));
        for (int c = 0; c < 3; ++c)
            raw[int(ModelParam::Albedo)][3 * i + std::size_t(c)] =
                float((uniform(rng, 0.2, 0.8) - 0.5) / sh_const::kY00);
        for (ModelParam t : {ModelParam::TransferPositive, ModelParam::TransferNegative}) {
            auto& v = raw[int(t)];
            for (int k = 0; k < kTransferStored; ++k)
                v[i * kTransferStored + std::size_t(k)] = float(0.2 * uniform(rng));
            v[i * kTransferStored] = float(1.0 + 0.2 * uniform(rng));
        }
    }
    return raw;
}

inline GaussianModel random_model(const Camera& cam, std::uint64_t seed, std::size_t count = 60) {
    return GaussianModel::from_raw(random_raw(cam, seed, count), 1.0);
}

// A run held in memory: the model, a seeded lighting MLP with one embedding per name.
inline TrainedRun in_memory_run(SurfelModel model, const std::vector<std::string>& names,
                                std::uint32_t seed = 7) {
    TrainedRun run;
    run.dir = "memory-run";
    run.paths = run_paths(run.dir);
    run.model = std::move(model);
    run.lighting = LightingMlp(int(names.size()), seed);
    run.image_names = names;
    return run;
}

// A sky-like environment: bright DC, a light from `sun`, some band-2 detail.
inline ShCoeffs<double> bright_sh(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    ShCoeffs<double> sh;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c)
            sh.c[k][c] = (k == 0 ? 2.0 : 0.4) * uniform(rng, k == 0 ? 0.8 : -1.0, 1.0);
    return sh;
}

}  // namespace lumigauss::relight_test
