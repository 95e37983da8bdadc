#pragma once
// What the trainer tests of both tiers share: the tiny synthetic scene (generated once per test process), a
// trainer on it, the paper-fast preset shrunk to a few hundred iterations, and bit-for-bit comparison of
// training states (resume must be exact).
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "fast/synth_test_util.h"
#include "lumigauss/io/dataset.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss::trainer_test {

using synth_test::TempDir;

struct TinyScene {
    std::string root;
    Dataset data;
    std::vector<TrainView> views;
};

inline const TinyScene& tiny_scene() {
    static TempDir dir("train_trainer");
    static const TinyScene scene = [] {
        synth::generate_synthetic_scene(synth_test::tiny_options(dir.str()));
        TinyScene s;
        s.root = dir.str();
        s.data = load_dataset(s.root, DatasetOptions{});
        s.views = load_train_views(s.data);
        return s;
    }();
    return scene;
}

inline Trainer make_trainer(const TrainConfig& config) {
    const TinyScene& s = tiny_scene();
    return Trainer(s.views, s.data.point_xyz, s.data.point_rgb, config);
}

// The fast preset with its schedule shrunk so that all three stages and some densification fit in a few
// hundred iterations.
inline TrainConfig shrunk_config() {
    TrainConfig c = train_preset("paper-fast");
    c.iterations = 400;
    c.warmup = 200;
    c.start_shadowed = 220;
    c.densify_from = 50;
    c.densify_until = 180;
    c.densify_interval = 50;
    c.opacity_reset_interval = 150;
    c.start_regularization = 100;
    c.lr_position_max_steps = 300;
    return c;
}

// ---- Bitwise comparison of states ----------------------------------------------------------------------

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

inline void expect_same_adam(const AdamGroup& a, const AdamGroup& b, const std::string& what) {
    EXPECT_EQ(a.step_count(), b.step_count()) << what;
    EXPECT_TRUE(same_bits(a.exp_avg(), b.exp_avg())) << what << " exp_avg";
    EXPECT_TRUE(same_bits(a.exp_avg_sq(), b.exp_avg_sq())) << what << " exp_avg_sq";
    EXPECT_EQ(a.row_width(), b.row_width()) << what;
}

// Everything a TrainState holds, bit for bit (learning rates are not state: step() sets them first).
inline void expect_same_state(const TrainState& a, const TrainState& b) {
    EXPECT_EQ(train_config_to_json(a.config), train_config_to_json(b.config));
    EXPECT_EQ(a.iteration, b.iteration);
    EXPECT_EQ(a.scene_extent, b.scene_extent);
    EXPECT_EQ(a.image_names, b.image_names);
    ASSERT_EQ(a.model.size(), b.model.size());
    for (int p = 0; p < kModelParamCount; ++p) {
        const auto param = ModelParam(p);
        const std::string name = GaussianModel::name(param);
        EXPECT_TRUE(same_bits(a.model.param(param), b.model.param(param))) << name;
        expect_same_adam(a.model.adam(param), b.model.adam(param), name);
    }
    EXPECT_TRUE(same_bits(a.model.grad_accum(), b.model.grad_accum())) << "grad_accum";
    EXPECT_TRUE(same_bits(a.model.grad_count(), b.model.grad_count())) << "grad_count";
    EXPECT_TRUE(same_bits(a.model.max_radii(), b.model.max_radii())) << "max_radii";
    EXPECT_EQ(a.model.spatial_lr_scale(), b.model.spatial_lr_scale());
    ASSERT_EQ(a.lighting.num_images(), b.lighting.num_images());
    ASSERT_EQ(a.lighting_adam.size(), b.lighting_adam.size());
    for (int g = 0; g < kMlpGroupCount; ++g) {
        const std::string name = std::string("lighting ") + mlp_group_name(MlpGroup(g));
        EXPECT_TRUE(same_bits(a.lighting.param(MlpGroup(g)), b.lighting.param(MlpGroup(g)))) << name;
        expect_same_adam(a.lighting_adam[std::size_t(g)], b.lighting_adam[std::size_t(g)], name);
    }
    EXPECT_TRUE(same_bits(a.sky_residuals.params(), b.sky_residuals.params())) << "sky residuals";
    ASSERT_EQ(a.sky_residual_adam.size(), b.sky_residual_adam.size());
    for (std::size_t i = 0; i < a.sky_residual_adam.size(); ++i)
        expect_same_adam(a.sky_residual_adam[i], b.sky_residual_adam[i], "sky residual " + std::to_string(i));
}

}  // namespace lumigauss::trainer_test
