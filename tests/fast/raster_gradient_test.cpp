// Finite-difference checks of every rasterizer gradient, in double precision, through the real tiled
// backward: dL/d(means, quaternions, scales, opacities, colours) for a loss touching every output map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_backward.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::convert_batch;
using testing::random_surfels;
using testing::RandomSceneOptions;
using testing::test_camera;

// L = sum over maps of <weights, map>, with fixed random weights per map.
struct LinearLoss {
    RasterImageGrads<double> w;
    double operator()(const RasterImages<double>& img) const {
        const auto dot = [](const std::vector<double>& a, const std::vector<double>& b) {
            double s = 0;
            for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) s += a[i] * b[i];
            return s;
        };
        return dot(w.color, img.color) + dot(w.alpha, img.alpha) + dot(w.depth, img.depth) +
               dot(w.median_depth, img.median_depth) + dot(w.normal, img.normal) +
               dot(w.distortion, img.distortion);
    }
};

struct MapsUsed {
    bool color = true, alpha = true, depth = true, median = true, normal = true, distortion = true;
};

LinearLoss random_loss(const Camera& cam, int channels, std::uint32_t seed, MapsUsed used) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    const std::size_t np = std::size_t(cam.width) * cam.height;
    const auto fill = [&](std::size_t n, bool on) {
        std::vector<double> v;
        if (on) {
            v.resize(n);
            for (double& x : v) x = u(rng);
        }
        return v;
    };
    LinearLoss L;
    L.w.color = fill(np * channels, used.color);
    L.w.alpha = fill(np, used.alpha);
    L.w.depth = fill(np, used.depth);
    L.w.median_depth = fill(np, used.median);
    L.w.normal = fill(np * 3, used.normal);
    L.w.distortion = fill(np, used.distortion);
    for (double& x : L.w.distortion) x *= 50;  // distortion values are small; make their gradient count
    return L;
}

double loss_of(const Camera& cam, const SurfelBatch<double>& s, const LinearLoss& L,
               const std::vector<double>& bg) {
    RasterState<double> st;
    RasterSettings<double> settings;
    settings.background = bg;
    return L(rasterize_forward_cpu(cam, s, settings, st));
}

struct ParamRef {
    const char* name;
    std::vector<double> SurfelBatch<double>::*field;
    std::vector<double> SurfelGrads<double>::*grad;
};

void check_gradients(const Camera& cam, SurfelBatch<double> s, const LinearLoss& L,
                     const std::vector<double>& bg, double rel_tol, int* checked = nullptr) {
    RasterState<double> st;
    RasterSettings<double> settings;
    settings.background = bg;
    rasterize_forward_cpu(cam, s, settings, st);
    const SurfelGrads<double> g = rasterize_backward_cpu(s, st, L.w);
    const ParamRef params[] = {{"mean", &SurfelBatch<double>::means, &SurfelGrads<double>::means},
                               {"quat", &SurfelBatch<double>::quats, &SurfelGrads<double>::quats},
                               {"scale", &SurfelBatch<double>::scales, &SurfelGrads<double>::scales},
                               {"opacity", &SurfelBatch<double>::opacities, &SurfelGrads<double>::opacities},
                               {"color", &SurfelBatch<double>::colors, &SurfelGrads<double>::colors}};
    int count = 0, nonzero = 0;
    for (const ParamRef& p : params) {
        std::vector<double>& values = s.*(p.field);
        for (std::size_t i = 0; i < values.size(); ++i) {
            const double h = 1e-6 * std::max(1.0, std::abs(values[i]));
            const double keep = values[i];
            values[i] = keep + h;
            const double lp = loss_of(cam, s, L, bg);
            values[i] = keep - h;
            const double lm = loss_of(cam, s, L, bg);
            values[i] = keep;
            const double numeric = (lp - lm) / (2 * h);
            const double analytic = (g.*(p.grad))[i];
            const double scale = std::max({1.0, std::abs(numeric), std::abs(analytic)});
            EXPECT_NEAR(analytic, numeric, rel_tol * scale) << p.name << "[" << i << "]";
            ++count;
            nonzero += std::abs(numeric) > 1e-6;
        }
    }
    EXPECT_GT(nonzero, count / 2) << "most parameters should influence the loss";
    if (checked) *checked = count;
}

TEST(RasterGradient, AllMapsAllParametersMatchFiniteDifferences) {
    const Camera cam = test_camera(37, 35);
    for (std::uint32_t seed = 21; seed <= 23; ++seed) {
        RandomSceneOptions o;
        o.count = 10;
        const auto s = random_surfels<double>(cam, seed, o);
        check_gradients(cam, s, random_loss(cam, 3, seed, {}), {0.3, 0.1, 0.7}, 2e-5);
    }
}

TEST(RasterGradient, EachMapAlone) {
    const Camera cam = test_camera(33, 30);
    const auto s = random_surfels<double>(cam, 31, {});
    const MapsUsed only[] = {
        {true, false, false, false, false, false}, {false, true, false, false, false, false},
        {false, false, true, false, false, false}, {false, false, false, true, false, false},
        {false, false, false, false, true, false}, {false, false, false, false, false, true}};
    for (const MapsUsed& m : only) check_gradients(cam, s, random_loss(cam, 3, 5, m), {}, 2e-5);
}

TEST(RasterGradient, SixChannelsAndDenseOverlap) {
    const Camera cam = test_camera(32, 32);
    RandomSceneOptions o;
    o.channels = 6;
    o.count = 16;
    o.min_scale = 0.3, o.max_scale = 0.9;  // many overlaps: long blending chains
    o.min_opacity = 0.5, o.max_opacity = 0.9;
    check_gradients(cam, random_surfels<double>(cam, 41, o), random_loss(cam, 6, 41, {}), {}, 2e-5);
}

// The backward walks a block's list in chunks of cpu::kUnblendChunk entries (tile_backward.h), handing
// each chunk to a separate gradient pass. Faint, large, overlapping surfels make lists several chunks long,
// so the walk's state must carry across chunk boundaries.
TEST(RasterGradient, LongBlendingChainsSpanSeveralWalkChunks) {
    const Camera cam = test_camera(20, 18);
    RandomSceneOptions o;
    o.count = 160;
    o.min_scale = 0.6, o.max_scale = 1.2;
    o.min_opacity = 0.03, o.max_opacity = 0.08;
    const auto s = random_surfels<double>(cam, 58, o);
    RasterState<double> st;
    rasterize_forward_cpu(cam, s, RasterSettings<double>{}, st);
    // The longest list the backward walks: entries the forward composited into one block.
    std::uint32_t longest = 0;
    for (std::size_t i = 0; i + 1 < st.block_start.size(); ++i)
        if ((i + 1) % (cpu::kTileBlocks + 1) != 0)  // not across two tiles' offsets
            longest = std::max(longest, st.block_start[i + 1] - st.block_start[i]);
    ASSERT_GT(longest, 2 * cpu::kUnblendChunk) << "the scene should need at least three chunks";
    check_gradients(cam, s, random_loss(cam, 3, 58, {}), {0.3, 0.1, 0.7}, 2e-5);
}

TEST(RasterGradient, AnyChannelCountUsesTheGeneralPath) {
    const Camera cam = test_camera(30, 20);
    for (int channels : {1, 4}) {
        RandomSceneOptions o;
        o.channels = channels;
        o.count = 8;
        check_gradients(cam, random_surfels<double>(cam, 45, o), random_loss(cam, channels, 45, {}), {},
                        2e-5);
    }
}

TEST(RasterGradient, SurfelCrossingTheCameraPlane) {
    const Camera cam = test_camera(32, 24);
    RandomSceneOptions o;
    o.count = 4;
    o.min_depth = 0.6, o.max_depth = 1.0;
    o.min_scale = 1.0, o.max_scale = 2.0;
    check_gradients(cam, random_surfels<double>(cam, 51, o), random_loss(cam, 3, 51, {}), {}, 2e-5);
}

// The backward of the projection runs on eight surfels at a time, one per lane, each lane choosing how
// its filter centre was placed: on the 3-sigma box's centre, or (disk crossing the camera plane) on the
// projected mean. Near surfels large enough to cross the plane, mixed with ordinary ones in the same
// groups of eight (and a group left part empty at the end).
TEST(RasterGradient, MixedFilterCentresInOneGroupOfSurfels) {
    const Camera cam = test_camera(32, 24);
    RandomSceneOptions o;
    o.count = 21;
    o.min_depth = 0.6, o.max_depth = 4.0;
    o.min_scale = 0.1, o.max_scale = 1.5;
    const auto s = random_surfels<double>(cam, 71, o);
    RasterState<double> st;
    rasterize_forward_cpu(cam, s, RasterSettings<double>{}, st);
    int conic = 0, mean = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (st.visible[i]) (st.projections[i].conic_center ? conic : mean) += 1;
    ASSERT_GE(conic, 4);
    ASSERT_GE(mean, 2);
    check_gradients(cam, s, random_loss(cam, 3, 71, {}), {0.2, 0.4, 0.6}, 2e-5);
}

// The projection's backward on its own, for one surfel at a time (the scalar instantiation of the lane
// code the rasterizer runs eight at a time): a random linear loss on every projected quantity the pixels
// see (rows of the ray transform, filter centre, normal), against central differences in every input.
TEST(RasterGradient, ProjectionBackwardMatchesFiniteDifferences) {
    const Camera cam = test_camera(32, 24);
    const auto view = pinhole_view<double>(cam);
    RandomSceneOptions o;
    o.count = 40;
    o.min_depth = 0.6, o.max_depth = 5.0;  // both ways of centring the filter
    o.min_scale = 0.05, o.max_scale = 1.5;
    const auto s = random_surfels<double>(cam, 91, o);
    std::mt19937 rng(92);
    std::uniform_real_distribution<double> u(-1, 1);
    int checked = 0, conic = 0, mean = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        raster::ProjectedSurfel<double> p;
        if (!raster::project_surfel(s.geometry(i), s.opacities[i], view, p)) continue;
        raster::ProjectedSurfelGrad<double> w;
        for (int k = 0; k < 3; ++k)
            w.tu[k] = u(rng), w.tv[k] = u(rng), w.tw[k] = u(rng), w.normal[k] = u(rng);
        w.center = {u(rng), u(rng)};
        const auto loss = [&](const raster::SurfelGeometry<double>& g) {
            raster::ProjectedSurfel<double> q;
            raster::project_surfel(g, s.opacities[i], view, q);
            return dot(w.tu, q.tu) + dot(w.tv, q.tv) + dot(w.tw, q.tw) + dot(w.normal, q.normal) +
                   w.center.x * q.center.x + w.center.y * q.center.y;
        };
        const auto analytic = raster::project_surfel_vjp(s.geometry(i), view, p, w);
        double inputs[9], grads[9];
        const auto g0 = s.geometry(i);
        for (int k = 0; k < 3; ++k) inputs[k] = g0.mean[k], grads[k] = analytic.mean[k];
        for (int k = 0; k < 4; ++k) inputs[3 + k] = g0.quat[k], grads[3 + k] = analytic.quat[k];
        inputs[7] = g0.scale_u, inputs[8] = g0.scale_v, grads[7] = analytic.scale_u,
        grads[8] = analytic.scale_v;
        const auto geometry_of = [](const double* x) {
            return raster::SurfelGeometry<double>{{x[0], x[1], x[2]}, {x[3], x[4], x[5], x[6]}, x[7], x[8]};
        };
        for (int k = 0; k < 9; ++k) {
            double x[9];
            std::copy_n(inputs, 9, x);
            const double h = 1e-6 * std::max(1.0, std::abs(x[k]));
            x[k] = inputs[k] + h;
            const double lp = loss(geometry_of(x));
            x[k] = inputs[k] - h;
            const double lm = loss(geometry_of(x));
            const double numeric = (lp - lm) / (2 * h);
            EXPECT_NEAR(grads[k], numeric, 1e-5 * std::max({1.0, std::abs(numeric), std::abs(grads[k])}))
                << "surfel " << i << ", input " << k
                << (p.conic_center ? " (conic centre)" : " (projected mean)");
            ++checked;
        }
        (p.conic_center ? conic : mean) += 1;
    }
    EXPECT_GE(conic, 5);
    EXPECT_GE(mean, 2);
    EXPECT_GE(checked, 9 * 10);
}

TEST(RasterGradient, TinySurfelsInTheScreenFilterBranch) {
    const Camera cam = test_camera(32, 24);
    RandomSceneOptions o;
    o.count = 8;
    o.min_scale = 0.001, o.max_scale = 0.01;
    check_gradients(cam, random_surfels<double>(cam, 61, o), random_loss(cam, 3, 61, {}), {0.5, 0.5, 0.5},
                    2e-5);
}

TEST(RasterGradient, ScreenSpaceGradientIsTheCentreTranslationGradient) {
    // mean2d must equal dL/d(delta) where the surfel's image is translated by delta pixels: moving the mean
    // by z/fx along the camera's x axis does exactly that to the ray transform. The low-pass filter centre
    // moves too, so surfels facing the camera and large enough that the filter never wins are used: then
    // the two agree exactly.
    const Camera cam = test_camera(40, 36);
    RandomSceneOptions o;
    o.count = 6;
    o.min_scale = 0.4, o.max_scale = 0.9;
    auto s = random_surfels<double>(cam, 71, o);
    const Vec4<double> facing = quaternion_from_rotation(transpose(cam.rotation));
    for (std::size_t i = 0; i < s.size(); ++i)
        for (int k = 0; k < 4; ++k) s.quats[4 * i + k] = facing[k];
    const LinearLoss L = random_loss(cam, 3, 71, {true, true, false, false, false, false});
    RasterState<double> st;
    rasterize_forward_cpu(cam, s, RasterSettings<double>{}, st);
    const auto g = rasterize_backward_cpu(s, st, L.w);
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (!st.visible[i]) continue;
        const Vec3d mean{s.means[3 * i], s.means[3 * i + 1], s.means[3 * i + 2]};
        const double z = cam.world_to_camera(mean).z;
        const Vec3d right = transpose(cam.rotation) * Vec3d{z / cam.fx, 0, 0};  // one pixel in x
        // d/ddelta of L(mean + delta * right) by the chain rule on the analytic mean gradient.
        const double via_mean =
            g.means[3 * i] * right.x + g.means[3 * i + 1] * right.y + g.means[3 * i + 2] * right.z;
        EXPECT_NEAR(g.mean2d[2 * i], via_mean, 1e-9 * std::max(1.0, std::abs(via_mean))) << i;
        EXPECT_NE(g.mean2d[2 * i], 0.0);
    }
}

// The finite-difference tests above prove the double-precision backward; training runs the float one, whose
// tile kernels are compiled per instruction set on packs of pixels. Same inputs, same loss: the float
// gradients must agree with the double ones to float accuracy, for every parameter and channel count.
TEST(RasterGradient, FloatBackwardMatchesTheProvenDoubleBackward) {
    const Camera cam = test_camera(61, 47);  // not a multiple of the tile or block size
    for (int channels : {3, 6, 5}) {
        RandomSceneOptions o;
        o.channels = channels;
        o.count = 60;
        o.min_opacity = 0.3, o.max_opacity = 0.99;
        const auto sf = convert_batch<float>(random_surfels<double>(cam, 81 + std::uint32_t(channels), o));
        const auto sd = convert_batch<double>(sf);
        const LinearLoss L = random_loss(cam, channels, 83, {});
        RasterImageGrads<float> wf;
        const auto to_float = [](const std::vector<double>& v) {
            return std::vector<float>(v.begin(), v.end());
        };
        wf.color = to_float(L.w.color), wf.alpha = to_float(L.w.alpha), wf.depth = to_float(L.w.depth);
        wf.median_depth = to_float(L.w.median_depth), wf.normal = to_float(L.w.normal);
        wf.distortion = to_float(L.w.distortion);
        RasterSettings<float> set_f;
        RasterSettings<double> set_d;
        set_f.background = {0.2f, 0.5f, 0.1f, 0.3f, 0.7f, 0.9f};
        set_d.background = {0.2f, 0.5f, 0.1f, 0.3f, 0.7f, 0.9f};
        set_f.background.resize(std::size_t(channels)), set_d.background.resize(std::size_t(channels));
        RasterState<float> st_f;
        RasterState<double> st_d;
        rasterize_forward_cpu(cam, sf, set_f, st_f);
        rasterize_forward_cpu(cam, sd, set_d, st_d);
        const SurfelGrads<float> gf = rasterize_backward_cpu(sf, st_f, wf);
        const SurfelGrads<double> gd = rasterize_backward_cpu(sd, st_d, L.w);
        const auto compare = [&](const char* name, const std::vector<float>& f,
                                 const std::vector<double>& d) {
            ASSERT_EQ(f.size(), d.size()) << name;
            double largest = 0;
            for (double x : d) largest = std::max(largest, std::abs(x));
            ASSERT_GT(largest, 0.0) << name;
            for (std::size_t i = 0; i < d.size(); ++i)
                EXPECT_NEAR(f[i], d[i], 2e-4 * largest)
                    << name << "[" << i << "], " << channels << " channels";
        };
        compare("means", gf.means, gd.means);
        compare("quats", gf.quats, gd.quats);
        compare("scales", gf.scales, gd.scales);
        compare("opacities", gf.opacities, gd.opacities);
        compare("colors", gf.colors, gd.colors);
        compare("mean2d", gf.mean2d, gd.mean2d);
    }
}

// The training loop's backward reuses its output and the state's gradient slots from call to call. Scenes
// of shrinking and growing size (and some surfels invisible, whose gradients must be reset to zero) run
// through one state and one output: each result must equal a fresh backward's bit for bit.
TEST(RasterGradient, BufferReusingBackwardEqualsTheFreshOne) {
    const Camera cam = test_camera(61, 47);
    RasterState<float> reused_state;
    SurfelGrads<float> reused;
    for (int round = 0; round < 4; ++round) {
        RandomSceneOptions o;
        o.channels = round % 2 ? 6 : 3;
        o.count = round == 2 ? 20 : 80;
        auto sf = convert_batch<float>(random_surfels<double>(cam, 300 + std::uint32_t(round), o));
        // Move every other surfel of the last rounds behind the camera: its old gradient must not survive.
        if (round >= 2)
            for (std::size_t i = 0; i < sf.size(); i += 2) sf.means[3 * i + 2] = -5.0f;
        const LinearLoss L = random_loss(cam, o.channels, 90 + std::uint32_t(round), {});
        RasterImageGrads<float> w;
        w.color.assign(L.w.color.begin(), L.w.color.end());
        w.alpha.assign(L.w.alpha.begin(), L.w.alpha.end());
        w.depth.assign(L.w.depth.begin(), L.w.depth.end());
        w.normal.assign(L.w.normal.begin(), L.w.normal.end());
        w.distortion.assign(L.w.distortion.begin(), L.w.distortion.end());
        RasterState<float> fresh_state;
        rasterize_forward_cpu(cam, sf, RasterSettings<float>{}, fresh_state);
        rasterize_forward_cpu(cam, sf, RasterSettings<float>{}, reused_state);
        const SurfelGrads<float> fresh = rasterize_backward_cpu(sf, fresh_state, w);
        rasterize_backward_cpu(sf, reused_state, w, reused);
        EXPECT_EQ(reused.means, fresh.means) << "round " << round;
        EXPECT_EQ(reused.quats, fresh.quats) << "round " << round;
        EXPECT_EQ(reused.scales, fresh.scales) << "round " << round;
        EXPECT_EQ(reused.opacities, fresh.opacities) << "round " << round;
        EXPECT_EQ(reused.colors, fresh.colors) << "round " << round;
        EXPECT_EQ(reused.mean2d, fresh.mean2d) << "round " << round;
        if (round >= 2) {
            ASSERT_EQ(reused_state.visible[0], 0);
            EXPECT_EQ(reused.means[0], 0.0f) << "an invisible surfel keeps a stale gradient";
        }
    }
}

}  // namespace
}  // namespace lumigauss
