// The surfel shadow tracer (model/surfel_occlusion.h) against a brute-force product over every surfel, with
// known answers for one and two disks, and the transfer baked from it (model/visibility_transfer.h): an open
// surfel gets the clamped-cosine lobe, a covered one almost nothing, one beside a wall is dark only when
// the light comes from behind the wall.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/surfel_occlusion.h"
#include "lumigauss/model/visibility_transfer.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {
namespace {

struct Disk {
    Vec3d centre;
    Vec3d normal;
    double scale_u, scale_v;  // metres
    double opacity;           // activated
};

Mat3d frame_of(Vec3d normal) {
    const Vec3d n = normalize(normal);
    const Vec3d helper = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    const Vec3d u = normalize(cross(helper, n)), v = cross(n, u);
    return Mat3d::from_columns(u, v, n);
}

SurfelModel model_of(const std::vector<Disk>& disks) {
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (const Disk& d : disks) {
        const Vec4<double> q = quaternion_from_rotation(frame_of(d.normal));
        for (int k = 0; k < 3; ++k) raw[int(ModelParam::Xyz)].push_back(float(d.centre[k]));
        for (int k = 0; k < 4; ++k) raw[int(ModelParam::Rotation)].push_back(float(q[k]));
        raw[int(ModelParam::Scaling)].push_back(float(std::log(d.scale_u)));
        raw[int(ModelParam::Scaling)].push_back(float(std::log(d.scale_v)));
        raw[int(ModelParam::Opacity)].push_back(inverse_sigmoid(float(d.opacity)));
        for (int c = 0; c < 3; ++c) raw[int(ModelParam::Albedo)].push_back(0.0f);
        for (int k = 0; k < kTransferStored; ++k) {
            raw[int(ModelParam::TransferPositive)].push_back(0.0f);
            raw[int(ModelParam::TransferNegative)].push_back(0.0f);
        }
    }
    return SurfelModel::from_raw(std::move(raw));
}

// The light one disk lets through where the ray crosses its plane, written independently of the tracer:
// 1 - min(0.99, opacity * Gaussian) inside three sigmas, 1 elsewhere and behind t_min.
double brute_force_transmittance(const std::vector<Disk>& disks, Vec3d o, Vec3d d, double t_min, int self) {
    double light = 1.0;
    for (int k = 0; k < int(disks.size()); ++k) {
        if (k == self) continue;
        const Mat3d f = frame_of(disks[k].normal);
        const double along = dot(d, f.col(2));
        if (std::abs(along) < 1e-9) continue;
        const double t = dot(disks[k].centre - o, f.col(2)) / along;
        if (t <= t_min) continue;
        const Vec3d x = o + d * t - disks[k].centre;
        const double u = dot(x, f.col(0)) / disks[k].scale_u, v = dot(x, f.col(1)) / disks[k].scale_v;
        if (u * u + v * v > 9.0) continue;
        const double alpha = std::min(0.99, disks[k].opacity * std::exp(-0.5 * (u * u + v * v)));
        if (alpha >= 1.0 / 255.0) light *= 1.0 - alpha;
    }
    return light;
}

// Small disks standing edge-on to every ray of a test, far off: they give the scene (and its grid) a size.
void add_scene_corners(std::vector<Disk>& disks) {
    for (const double x : {-10.0, 10.0})
        for (const double y : {-10.0, 10.0}) disks.push_back({{x, y, -1}, {1, 0, 0}, 0.01, 0.01, 0.9});
}

TEST(SurfelOcclusion, OneAndTwoDisksKnownAnswers) {
    std::vector<Disk> disks = {{{0, 0, 1}, {0, 0, 1}, 1.0, 1.0, 0.5}, {{0, 0, 2}, {0, 0, 1}, 1.0, 1.0, 0.5}};
    add_scene_corners(disks);
    const SurfelModel model = model_of(disks);
    const SurfelOcclusion occlusion(model);
    auto scratch = occlusion.scratch();
    const std::size_t none = model.size();
    // Straight up through both centres: (1 - 0.5)^2.
    EXPECT_NEAR(occlusion.transmittance({{0, 0, 0}, {0, 0, 1}, 1e-6, none}, scratch), 0.25, 1e-6);
    // One sigma off the axis: each lets 1 - 0.5 exp(-1/2) through (the disks' u axis is any unit vector
    // in their plane; a radial offset is what counts).
    const double one = 1.0 - 0.5 * std::exp(-0.5);
    EXPECT_NEAR(occlusion.transmittance({{1, 0, 0}, {0, 0, 1}, 1e-6, none}, scratch), one * one, 1e-6);
    // Beyond three sigmas, downwards, or from above both: nothing in the way.
    EXPECT_DOUBLE_EQ(occlusion.transmittance({{3.5, 0, 0}, {0, 0, 1}, 1e-6, none}, scratch), 1.0);
    EXPECT_DOUBLE_EQ(occlusion.transmittance({{0, 0, 0}, {0, 0, -1}, 1e-6, none}, scratch), 1.0);
    EXPECT_DOUBLE_EQ(occlusion.transmittance({{0, 0, 3}, {0, 0, 1}, 1e-6, none}, scratch), 1.0);
    // A surfel does not shade itself; a crossing nearer than t_min does not count.
    EXPECT_NEAR(occlusion.transmittance({{0, 0, 1}, {0, 0, 1}, 1e-6, 0}, scratch), 0.5, 1e-6);
    EXPECT_NEAR(occlusion.transmittance({{0, 0, 0.5}, {0, 0, 1}, 0.9, none}, scratch), 0.5, 1e-6);
}

TEST(SurfelOcclusion, MatchesTheProductOverEverySurfel) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(-5.0, 5.0), unit(-1.0, 1.0), scale(0.05, 1.5), opac(0.0, 1.0);
    std::vector<Disk> disks;
    for (int k = 0; k < 400; ++k) {
        Vec3d n{unit(rng), unit(rng), unit(rng)};
        if (length(n) < 1e-3) n = {0, 0, 1};
        disks.push_back({{pos(rng), pos(rng), pos(rng)}, normalize(n), scale(rng), scale(rng), opac(rng)});
    }
    disks.push_back({{0, 0, 0}, {0, 0, 1}, 3.0, 2.5, 0.9});    // reaches beyond the other centres' box
    disks.push_back({{400, 0, 0}, {1, 0, 0}, 1.0, 1.0, 0.9});  // a far floater: outside the grid, no shadow
    const SurfelModel model = model_of(disks);
    const SurfelOcclusion occlusion(model);
    auto scratch = occlusion.scratch();
    std::vector<Disk> inside(disks.begin(), disks.end() - 1);
    for (int r = 0; r < 300; ++r) {
        Vec3d d{unit(rng), unit(rng), unit(rng)};
        if (length(d) < 1e-3) d = {1, 0, 0};
        d = normalize(d);
        const int self = r % 5 == 0 ? r % 400 : -1;
        const Vec3d o = self >= 0 ? disks[std::size_t(self)].centre : Vec3d{pos(rng), pos(rng), pos(rng)};
        const double expected = brute_force_transmittance(inside, o, d, 1e-4, self);
        const std::size_t from = self >= 0 ? std::size_t(self) : model.size();
        const double got = occlusion.transmittance({o, d, 1e-4, from}, scratch, 0.0);
        ASSERT_NEAR(got, expected, 1e-5) << "ray " << r;  // the model stores floats
    }
}

double shade(const SurfelModel& model, std::size_t i, bool positive, Vec3d light_dir) {
    // A light of SH degree 2 concentrated towards light_dir: the basis itself, unnormalised.
    double l[kShCount], t[kTransferCoeffs];
    sh_basis(light_dir, l);
    float stored[kTransferCoeffs];
    model.transfer_channel0(positive, i, stored);
    double s = 0.0;
    for (int j = 0; j < kShCount; ++j) {
        t[j] = stored[j];
        s += t[j] * l[j];
    }
    return s;
}

SurfelModel baked(const std::vector<Disk>& disks, double bounce = 0.0) {
    SurfelModel model = model_of(disks);
    VisibilityTransferOptions options;
    options.direction_rows = 24;
    options.bounce = bounce;
    bake_visibility_transfer(model, options);
    return model;
}

// Both transfer sets of surfel 0 (facing up: +z), and the clamped-cosine lobes of +z and -z.
struct UpAndDown {
    float up[kTransferCoeffs], down[kTransferCoeffs];
    double lobe_up[kShCount], lobe_down[kShCount];
};
UpAndDown up_and_down(const SurfelModel& model) {
    UpAndDown r;
    model.transfer_channel0(true, 0, r.up);
    model.transfer_channel0(false, 0, r.down);
    cosine_lobe_sh(Vec3d{0, 0, 1}, r.lobe_up);
    cosine_lobe_sh(Vec3d{0, 0, -1}, r.lobe_down);
    return r;
}

TEST(VisibilityTransfer, AnOpenSurfelGetsTheClampedCosineLobe) {
    std::vector<Disk> disks = {{{0, 0, 0}, {0, 0, 1}, 0.1, 0.1, 0.9}, {{5, 0, 0}, {0, 0, 1}, 1.0, 1.0, 0.9}};
    const UpAndDown t = up_and_down(baked(disks));
    for (int j = 0; j < kShCount; ++j) {
        EXPECT_NEAR(t.up[j], t.lobe_up[j], 1e-6) << j;  // exact: nothing is subtracted
        EXPECT_NEAR(t.down[j], t.lobe_down[j], 1e-6) << j;
    }
}

TEST(VisibilityTransfer, ARoofLetsItsTransmittanceThrough) {
    std::vector<Disk> disks = {{{0, 0, 0}, {0, 0, 1}, 0.1, 0.1, 0.9},
                               {{0, 0, 1}, {0, 0, 1}, 200.0, 200.0, 1.0}};
    add_scene_corners(disks);
    const UpAndDown t = up_and_down(baked(disks));
    for (int j = 0; j < kShCount; ++j) {
        // Opacity is capped at 0.99: 1 % passes (and a little more at grazing angles beyond the grid).
        EXPECT_NEAR(t.up[j], 0.01 * t.lobe_up[j], 0.01) << j;
        EXPECT_NEAR(t.down[j], t.lobe_down[j], 1e-6) << j;  // nothing below but the corners, edge-on
    }
}

TEST(VisibilityTransfer, TheBounceReturnsItsShareOfTheBlockedLight) {
    std::vector<Disk> disks = {{{0, 0, 0}, {0, 0, 1}, 0.1, 0.1, 0.9},
                               {{0, 0, 1}, {0, 0, 1}, 200.0, 200.0, 1.0}};
    add_scene_corners(disks);
    double lobe_up[kShCount];
    cosine_lobe_sh(Vec3d{0, 0, 1}, lobe_up);
    for (const double bounce : {0.5, 1.0}) {
        const SurfelModel model = baked(disks, bounce);
        float up[kTransferCoeffs];
        model.transfer_channel0(true, 0, up);
        // 0.99 of the light is blocked, and `bounce` of that comes back.
        const double arrives = 1.0 - 0.99 * (1.0 - bounce);
        for (int j = 0; j < kShCount; ++j)
            EXPECT_NEAR(up[j], arrives * lobe_up[j], 0.01) << bounce << " " << j;
    }
}

TEST(VisibilityTransfer, BesideAWallTheLightFromBehindItIsBlocked) {
    std::vector<Disk> disks = {{{0, 0, 0}, {0, 0, 1}, 0.1, 0.1, 0.9},
                               {{0.5, 0, 0}, {1, 0, 0}, 50.0, 50.0, 1.0}};
    add_scene_corners(disks);
    const SurfelModel model = baked(disks);
    const Vec3d from_wall = normalize(Vec3d{1, 0, 0.3}), from_open = normalize(Vec3d{-1, 0, 0.3});
    const double behind = shade(model, 0, true, from_wall), open = shade(model, 0, true, from_open);
    EXPECT_GT(open, 0.0);
    EXPECT_LT(behind, 0.5 * open);
}

}  // namespace
}  // namespace lumigauss
