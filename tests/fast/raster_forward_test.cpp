// The tiled CPU rasterizer against the dense brute-force reference, plus the edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/util/error.h"
#include "support/random_surfels.h"
#include "support/raster_reference.h"

namespace lumigauss {
namespace {

using testing::convert_batch;
using testing::random_surfels;
using testing::RandomSceneOptions;
using testing::reference_render;
using testing::test_camera;

template <typename T>
RasterImages<T> render(const Camera& cam, const SurfelBatch<T>& s, std::vector<T> bg = {}) {
    RasterState<T> st;
    RasterSettings<T> settings;
    settings.background = std::move(bg);
    return rasterize_forward_cpu(cam, s, settings, st);
}

template <typename A, typename B>
double max_abs_diff(const std::vector<A>& a, const std::vector<B>& b) {
    EXPECT_EQ(a.size(), b.size());
    double m = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
        m = std::max(m, std::abs(double(a[i]) - double(b[i])));
    return m;
}

template <typename T>
void expect_matches_reference(const RasterImages<T>& got, const RasterImages<double>& ref, double tol) {
    EXPECT_LE(max_abs_diff(got.color, ref.color), tol) << "color";
    EXPECT_LE(max_abs_diff(got.alpha, ref.alpha), tol) << "alpha";
    EXPECT_LE(max_abs_diff(got.depth, ref.depth), tol * 10) << "depth";  // depths are ~5, relative 1e-5
    EXPECT_LE(max_abs_diff(got.median_depth, ref.median_depth), tol * 10) << "median depth";
    EXPECT_LE(max_abs_diff(got.normal, ref.normal), tol) << "normal";
    EXPECT_LE(max_abs_diff(got.distortion, ref.distortion), tol) << "distortion";
}

bool all_finite(const RasterImages<float>& img) {
    for (const auto* v :
         {&img.color, &img.alpha, &img.depth, &img.median_depth, &img.normal, &img.distortion})
        for (float x : *v)
            if (!std::isfinite(x)) return false;
    return true;
}

TEST(RasterForward, TiledMatchesDenseReferenceDouble) {
    const Camera cam = test_camera(53, 41);  // not a multiple of the tile size
    for (std::uint32_t seed = 1; seed <= 5; ++seed) {
        RandomSceneOptions o;
        o.count = 60;
        const auto s = random_surfels<double>(cam, seed, o);
        const auto ref = reference_render(cam, s, {0.2, 0.4, 0.1});
        expect_matches_reference(render(cam, s, {0.2, 0.4, 0.1}), ref, 1e-12);
    }
}

TEST(RasterForward, FloatTiledMatchesDenseReferenceTo1e5) {
    const Camera cam = test_camera(64, 48);
    for (std::uint32_t seed = 11; seed <= 15; ++seed) {
        RandomSceneOptions o;
        o.count = 80;
        // The reference sees exactly the float inputs, so only the arithmetic differs.
        const auto s = convert_batch<float>(random_surfels<double>(cam, seed, o));
        const auto ref = reference_render(cam, convert_batch<double>(s));
        expect_matches_reference(render(cam, s), ref, 1e-5);
    }
}

TEST(RasterForward, AnyChannelCountMatchesReference) {
    const Camera cam = test_camera(40, 30);
    for (int channels : {1, 2, 4, 6, 16}) {
        RandomSceneOptions o;
        o.channels = channels;
        o.count = 40;
        const auto s = random_surfels<double>(cam, 90 + std::uint32_t(channels), o);
        expect_matches_reference(render(cam, s), reference_render(cam, s), 1e-12);
    }
    RandomSceneOptions o;
    o.channels = 17;
    EXPECT_THROW(render(cam, random_surfels<double>(cam, 1, o)), Error);
}

TEST(RasterForward, SixChannelsRenderLikeTwoThreeChannelPasses) {
    const Camera cam = test_camera();
    RandomSceneOptions o;
    o.channels = 6;
    const auto s6 = random_surfels<double>(cam, 3, o);
    SurfelBatch<double> a = s6, b = s6;
    a.channels = b.channels = 3;
    a.colors.assign(s6.size() * 3, 0), b.colors.assign(s6.size() * 3, 0);
    for (std::size_t i = 0; i < s6.size(); ++i)
        for (int c = 0; c < 3; ++c)
            a.colors[i * 3 + c] = s6.colors[i * 6 + c], b.colors[i * 3 + c] = s6.colors[i * 6 + 3 + c];
    const auto i6 = render(cam, s6), ia = render(cam, a), ib = render(cam, b);
    for (std::size_t p = 0; p < i6.alpha.size(); ++p)
        for (int c = 0; c < 3; ++c) {
            EXPECT_DOUBLE_EQ(i6.color[p * 6 + c], ia.color[p * 3 + c]);
            EXPECT_DOUBLE_EQ(i6.color[p * 6 + 3 + c], ib.color[p * 3 + c]);
        }
}

TEST(RasterForward, InconsistentBatchIsAnErrorNamingTheArray) {
    const Camera cam = test_camera();
    SurfelBatch<float> s = convert_batch<float>(random_surfels<double>(cam, 4));
    RasterState<float> st;
    RasterImages<float> img;
    s.colors.pop_back();
    try {
        rasterize_forward_cpu(cam, s, RasterSettings<float>{}, st, img);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("colors"), std::string::npos) << e.what();
    }
    s = convert_batch<float>(random_surfels<double>(cam, 4));
    rasterize_forward_cpu(cam, s, RasterSettings<float>{}, st, img);
    s.quats.resize(3);
    RasterImageGrads<float> g;
    SurfelGrads<float> grads;
    EXPECT_THROW(rasterize_backward_cpu(s, st, g, grads), Error);
    RandomSceneOptions five;
    five.count = 5;
    s = convert_batch<float>(random_surfels<double>(cam, 4, five));
    EXPECT_THROW(rasterize_backward_cpu(s, st, g, grads), Error);  // not the forward's surfels
}

// The reduction starts each visible surfel's sum from its first (surfel, tile) slot. A state in which a
// visible surfel has none (here made by hand: the forward never leaves one) is reported, not read past.
TEST(RasterForward, BackwardOfAStateWithAVisibleSurfelWithoutSlotsIsAnError) {
    const Camera cam = test_camera();
    const SurfelBatch<float> s = convert_batch<float>(random_surfels<double>(cam, 11));
    RasterState<float> st;
    RasterImages<float> img;
    rasterize_forward_cpu(cam, s, RasterSettings<float>{}, st, img);
    std::size_t i = 0;
    while (i < s.size() && !st.visible[i]) ++i;
    ASSERT_LT(i, s.size()) << "no visible surfel";
    ASSERT_LT(st.emission_offset[i], st.emission_offset[i + 1]);
    RasterImageGrads<float> g;
    g.color.assign(img.color.size(), 0.01f);
    SurfelGrads<float> grads;
    rasterize_backward_cpu(s, st, g, grads);  // consistent: no error
    st.emission_offset[i + 1] = st.emission_offset[i];
    try {
        rasterize_backward_cpu(s, st, g, grads);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("reaches no tile"), std::string::npos) << e.what();
    }
}

TEST(RasterForward, EmptySceneIsBackground) {
    const Camera cam = test_camera();
    SurfelBatch<float> s;
    const auto img = render(cam, s, {0.25f, 0.5f, 1.0f});
    for (std::size_t p = 0; p < img.alpha.size(); ++p) {
        EXPECT_EQ(img.alpha[p], 0.0f);
        EXPECT_EQ(img.color[p * 3 + 2], 1.0f);
    }
}

// A single surfel facing the camera, `z` metres in front of it, in camera space.
SurfelBatch<double> one_surfel(const Camera& cam, Vec3d p_cam, double scale, double opacity,
                               Vec4<double> quat = {1, 0, 0, 0}) {
    SurfelBatch<double> s;
    s.resize(1);
    const Vec3d w = transpose(cam.rotation) * (p_cam - cam.translation);
    // Express the camera-space orientation `quat` in world space.
    const Mat3d R = transpose(cam.rotation) * rotation_from_unit_quaternion(normalize_quaternion(quat));
    const Vec4<double> qw = quaternion_from_rotation(R);
    for (int k = 0; k < 3; ++k) s.means[k] = w[k];
    for (int k = 0; k < 4; ++k) s.quats[k] = qw[k];
    s.scales = {scale, scale};
    s.opacities = {opacity};
    s.colors = {1, 0.5, 0.25};
    return s;
}

TEST(RasterForward, SurfelBehindCameraOrBeforeNearPlaneIsInvisible) {
    const Camera cam = test_camera();
    for (double z : {-3.0, 0.0, 0.1, 0.2}) {
        const auto img = render(cam, one_surfel(cam, {0, 0, z}, 0.5, 0.9));
        EXPECT_EQ(*std::max_element(img.alpha.begin(), img.alpha.end()), 0.0) << "z=" << z;
    }
    const auto img = render(cam, one_surfel(cam, {0, 0, 0.25}, 0.01, 0.9));
    EXPECT_GT(*std::max_element(img.alpha.begin(), img.alpha.end()), 0.0);
}

TEST(RasterForward, CentredSurfelPeaksAtItsProjection) {
    const Camera cam = test_camera();
    const auto img = render(cam, one_surfel(cam, {0, 0, 3}, 0.3, 0.8));
    // Centre pixel: the projected mean lies at (cx, cy).
    const int x = int(cam.cx), y = int(cam.cy);
    const double a = img.alpha[std::size_t(y) * cam.width + x];
    EXPECT_NEAR(a, 0.8, 0.05);
    EXPECT_NEAR(img.depth[std::size_t(y) * cam.width + x] / a, 3.0, 1e-6);
    EXPECT_NEAR(img.median_depth[std::size_t(y) * cam.width + x], 3.0, 1e-6);
    // Camera-facing normal (world space) points towards the camera.
    const Vec3d n{img.normal[3 * (std::size_t(y) * cam.width + x)],
                  img.normal[3 * (std::size_t(y) * cam.width + x) + 1],
                  img.normal[3 * (std::size_t(y) * cam.width + x) + 2]};
    const Vec3d n_cam = cam.rotation * (n / a);
    EXPECT_NEAR(n_cam.z, -1.0, 1e-9);
}

TEST(RasterForward, EdgeOnSurfelsStayFinite) {
    const Camera cam = test_camera();
    // Rotated 90 degrees about the camera's y axis: the disk is seen exactly edge-on at the centre.
    const double h = std::sqrt(0.5);
    for (Vec4<double> q :
         {Vec4<double>{h, 0, h, 0}, Vec4<double>{h, h, 0, 0}, Vec4<double>{0.7072, 0, 0.7070, 0}}) {
        auto s = one_surfel(cam, {0, 0, 3}, 0.5, 0.9, q);
        const auto img = render(cam, convert_batch<float>(s));
        EXPECT_TRUE(all_finite(img));
        expect_matches_reference(render(cam, s), reference_render(cam, s), 1e-12);
    }
}

TEST(RasterForward, PartlyOffScreenMatchesReference) {
    const Camera cam = test_camera();
    SurfelBatch<double> s = one_surfel(cam, {-1.9, 1.4, 3}, 0.6, 0.9);
    expect_matches_reference(render(cam, s), reference_render(cam, s), 1e-12);
    s = one_surfel(cam, {-2.5, 0, 3}, 0.6, 0.9);  // centre off-screen, its disk reaches into the image
    const auto img = render(cam, s);
    EXPECT_GT(*std::max_element(img.alpha.begin(), img.alpha.end()), 0.0);
    expect_matches_reference(img, reference_render(cam, s), 1e-12);
}

TEST(RasterForward, HugeSurfelCrossingTheCameraPlaneHasNoGarbageBox) {
    const Camera cam = test_camera();
    // A 20 m disk, 1 m in front, tilted so that its 3-sigma disk reaches behind the camera.
    const double c = std::cos(0.6), sn = std::sin(0.6);
    auto s = one_surfel(cam, {0, 0, 1.0}, 20.0, 0.7, {c, sn, 0, 0});
    const auto proj_ok = [&] {
        raster::ProjectedSurfel<double> p;
        const bool ok = raster::project_surfel(s.geometry(0), s.opacities[0], pinhole_view<double>(cam), p);
        EXPECT_TRUE(ok);
        EXPECT_FALSE(p.conic_center);  // took the crossing path
        EXPECT_EQ(p.rect.x0, 0);
        EXPECT_EQ(p.rect.x1, cam.width - 1);
        return ok;
    }();
    ASSERT_TRUE(proj_ok);
    const auto img = render(cam, s);
    // Every pixel whose ray meets the disk's plane in front of the near plane sees it; the others do not.
    const Vec3d mean_cam{0, 0, 1.0};
    const Vec3d n_cam = rotation_from_unit_quaternion(normalize_quaternion(Vec4<double>{c, sn, 0, 0})).col(2);
    int seen = 0;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            const Vec3d ray{(x + 0.5 - cam.cx) / cam.fx, (y + 0.5 - cam.cy) / cam.fy, 1.0};
            const double z_hit = dot(mean_cam, n_cam) / dot(ray, n_cam);  // ray parameter = depth
            const double a = img.alpha[std::size_t(y) * cam.width + x];
            if (z_hit > 0.25 && z_hit < 5) {
                EXPECT_GT(a, 0.5) << x << "," << y;
            }
            if (z_hit < 0.15) {
                EXPECT_EQ(a, 0.0) << x << "," << y;
            }
            seen += a > 0.5;
        }
    EXPECT_GT(seen, cam.width * cam.height / 4);
    expect_matches_reference(img, reference_render(cam, s), 1e-12);
    EXPECT_TRUE(all_finite(render(cam, convert_batch<float>(s))));
}

TEST(RasterForward, TinySurfelIsKeptVisibleByTheLowPassFilter) {
    const Camera cam = test_camera();
    const auto s = one_surfel(cam, {0.01, 0.02, 3}, 1e-6, 0.9);
    const auto img = render(cam, s);
    const double peak = *std::max_element(img.alpha.begin(), img.alpha.end());
    EXPECT_GT(peak, 0.3);  // about one pixel wide, from the screen filter
    expect_matches_reference(img, reference_render(cam, s), 1e-12);
}

TEST(RasterForward, ZeroOpacityContributesNothing) {
    const Camera cam = test_camera();
    const auto img = render(cam, one_surfel(cam, {0, 0, 3}, 0.5, 0.0));
    EXPECT_EQ(*std::max_element(img.alpha.begin(), img.alpha.end()), 0.0);
}

TEST(RasterForward, OpaqueStackStopsAtTransmittanceThreshold) {
    const Camera cam = test_camera();
    SurfelBatch<double> s;
    for (int i = 0; i < 8; ++i) {
        auto one = one_surfel(cam, {0, 0, 2.0 + 0.3 * i}, 2.0, 1.0);
        s.means.insert(s.means.end(), one.means.begin(), one.means.end());
        s.quats.insert(s.quats.end(), one.quats.begin(), one.quats.end());
        s.scales.insert(s.scales.end(), one.scales.begin(), one.scales.end());
        s.opacities.push_back(1.0);
        s.colors.insert(s.colors.end(), {double(i), 0, 0});
    }
    const auto img = render(cam, s);
    const std::size_t centre = std::size_t(cam.cy) * cam.width + std::size_t(cam.cx);
    // Two layers at the alpha clamp 0.99 leave T = 1e-4 exactly at the threshold; the third would go below.
    EXPECT_NEAR(img.alpha[centre], 1 - 1e-4, 1e-9);
    expect_matches_reference(img, reference_render(cam, s), 1e-12);
}

TEST(RasterProjection, IntersectionReprojectsToThePixel) {
    const Camera cam = test_camera();
    const auto s = random_surfels<double>(cam, 7);
    const auto view = pinhole_view<double>(cam);
    for (std::size_t i = 0; i < s.size(); ++i) {
        raster::ProjectedSurfel<double> p;
        if (!raster::project_surfel(s.geometry(i), 1.0, view, p)) continue;
        raster::SplatSample<double> smp;
        const auto g = raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, 1.0);
        const double px = 17.5, py = 9.5;
        if (!raster::evaluate_splat(g, px, py, smp)) continue;
        // The surface point at (u, v) projects back onto the pixel, at depth tw . (u, v, 1).
        const auto geo = s.geometry(i);
        const Mat3d R = rotation_from_unit_quaternion(normalize_quaternion(geo.quat));
        const Vec3d P = geo.mean + (geo.scale_u * smp.u) * R.col(0) + (geo.scale_v * smp.v) * R.col(1);
        const Vec3d pc = cam.world_to_camera(P);
        EXPECT_NEAR(cam.fx * pc.x / pc.z + cam.cx, px, 1e-9);
        EXPECT_NEAR(cam.fy * pc.y / pc.z + cam.cy, py, 1e-9);
        EXPECT_NEAR(p.tw.x * smp.u + p.tw.y * smp.v + p.tw.z, pc.z, 1e-9);
    }
}

TEST(RasterProjection, BoundingBoxHoldsEveryContributingPixel) {
    // Brute force: every pixel where the kernel says the surfel contributes lies inside its box, for
    // random surfels of every opacity, including ones whose box is clipped by the image border. The tile
    // kernels rely on it: they test no box per pixel, only per block, so the float kernel (the CPU tiles'
    // own evaluation) must not reach outside the box either.
    const Camera cam = test_camera(48, 40);
    RandomSceneOptions o;
    o.count = 200;
    o.min_opacity = 0.01, o.max_opacity = 1.0;
    o.min_scale = 0.001, o.max_scale = 0.8;
    const auto s = random_surfels<double>(cam, 8, o);
    const auto view = pinhole_view<double>(cam);
    int contributing = 0, contributing_float = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        raster::ProjectedSurfel<double> p;
        if (!raster::project_surfel(s.geometry(i), s.opacities[i], view, p)) continue;
        const auto g = raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, s.opacities[i]);
        raster::ProjectionVjpInputs<float> pf;
        raster::SplatGeometry<float> gf;  // as the backends store it
        SplatFootprint<float> ff;
        store_projected(p, s.opacities[i], pf, gf, ff);
        for (int y = 0; y < cam.height; ++y)
            for (int x = 0; x < cam.width; ++x) {
                const bool inside = x >= p.rect.x0 && x <= p.rect.x1 && y >= p.rect.y0 && y <= p.rect.y1;
                raster::SplatSample<double> smp;
                if (raster::evaluate_splat(g, x + 0.5, y + 0.5, smp)) {
                    ++contributing;
                    EXPECT_TRUE(inside) << "surfel " << i << " pixel " << x << "," << y;
                }
                raster::SplatSample<float> smp_float;
                if (raster::evaluate_splat(gf, float(x) + 0.5f, float(y) + 0.5f, smp_float)) {
                    ++contributing_float;
                    EXPECT_TRUE(inside) << "float: surfel " << i << " pixel " << x << "," << y;
                }
            }
    }
    EXPECT_GT(contributing, 1000);
    EXPECT_GT(contributing_float, 1000);
}

TEST(RasterProjection, OffScreenCullNeverDropsAContributingSurfel) {
    // project_surfel rejects surfels whose reachable sphere lies beyond a side of the view before computing
    // the exact box. Surfels are scattered in a band around the image, large and small, every opacity;
    // each is also projected into a view 200 pixels wider on every side (the same camera, cx and cy
    // shifted), where nothing is culled, and evaluated densely on the original image's pixels. Whenever
    // one of those pixels reaches alpha 1/255 there, the original view must keep the surfel.
    const Camera cam = test_camera(48, 40);
    Camera wide = cam;
    const int pad = 200;
    wide.width += 2 * pad, wide.height += 2 * pad, wide.cx += pad, wide.cy += pad;
    const auto view = pinhole_view<double>(cam), wide_view = pinhole_view<double>(wide);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> uni(0, 1);
    int culled = 0, contributing = 0;
    for (int i = 0; i < 3000; ++i) {
        const double z = 1.0 + 8 * uni(rng);
        // Centres within +-60 % of the image size beyond its edges.
        const double px = (uni(rng) * 2.2 - 0.6) * cam.width, py = (uni(rng) * 2.2 - 0.6) * cam.height;
        const double opacity = std::exp(std::log(1.0 / 250) * uni(rng));
        const double scale = std::exp(std::log(0.002) + (std::log(2.0) - std::log(0.002)) * uni(rng));
        auto s = one_surfel(cam, {(px - cam.cx) / cam.fx * z, (py - cam.cy) / cam.fy * z, z}, scale, opacity);
        if (i % 2) {  // half tilted at random and elongated, half facing the camera (the tightest case)
            for (int k = 0; k < 4; ++k) s.quats[std::size_t(k)] = uni(rng) - 0.5;
            s.scales[1] = scale * (0.2 + uni(rng));
        }
        raster::ProjectedSurfel<double> p, pw;
        const bool kept = raster::project_surfel(s.geometry(0), opacity, view, p);
        if (!raster::project_surfel(s.geometry(0), opacity, wide_view, pw)) continue;
        const auto g = raster::make_splat_geometry(pw.tu, pw.tv, pw.tw, pw.center, opacity);
        bool reaches = false;
        for (int y = 0; y < cam.height && !reaches; ++y)
            for (int x = 0; x < cam.width && !reaches; ++x) {
                raster::SplatSample<double> smp;
                reaches = raster::evaluate_splat(g, x + pad + 0.5, y + pad + 0.5, smp);
            }
        contributing += reaches;
        culled += !kept;
        if (reaches) {
            EXPECT_TRUE(kept) << "surfel " << i << " reaches the image but was culled";
        }
    }
    EXPECT_GT(contributing, 300);  // the test sees both kinds in numbers
    EXPECT_GT(culled, 300);
}

TEST(RasterProjection, RasterizerKeepsExactlyTheSurfelsTheProjectionKeeps) {
    // The CPU rasterizer culls in two steps: a first pass with a sphere that bounds a surfel of any opacity
    // up to 1, then the exact projection on what is left. Scattered surfels around and behind the view,
    // some too transparent, some fully opaque, a few with opacity above 1 (which the first pass must leave
    // to the exact test): the rasterizer must keep exactly those project_surfel keeps.
    const Camera cam = test_camera(48, 40);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> uni(0, 1);
    SurfelBatch<double> batch;
    batch.resize(3000);
    for (std::size_t i = 0; i < batch.size(); ++i) {
        const double z = -1.0 + 10 * uni(rng);  // some behind the camera or before the near plane
        const double px = (uni(rng) * 2.2 - 0.6) * cam.width, py = (uni(rng) * 2.2 - 0.6) * cam.height;
        const double u = uni(rng);
        const double opacity =
            u < 0.1 ? 1.0 : (u < 0.15 ? 1.0 + uni(rng) : std::exp(std::log(1.0 / 300) * uni(rng)));
        const double scale = std::exp(std::log(0.002) + (std::log(2.0) - std::log(0.002)) * uni(rng));
        auto one =
            one_surfel(cam, {(px - cam.cx) / cam.fx * z, (py - cam.cy) / cam.fy * z, z}, scale, opacity);
        if (i % 2) {
            for (int k = 0; k < 4; ++k) one.quats[std::size_t(k)] = uni(rng) - 0.5;
            one.scales[1] = scale * (0.2 + uni(rng));
        }
        for (int k = 0; k < 3; ++k) batch.means[3 * i + k] = one.means[std::size_t(k)];
        for (int k = 0; k < 4; ++k) batch.quats[4 * i + k] = one.quats[std::size_t(k)];
        for (int k = 0; k < 2; ++k) batch.scales[2 * i + k] = one.scales[std::size_t(k)];
        batch.opacities[i] = opacity;
        for (int c = 0; c < 3; ++c) batch.colors[3 * i + c] = 0.5;
    }
    RasterState<double> st;
    rasterize_forward_cpu(cam, batch, RasterSettings<double>{}, st);
    const auto view = pinhole_view<double>(cam);
    int kept = 0, dropped = 0;
    for (std::size_t i = 0; i < batch.size(); ++i) {
        raster::ProjectedSurfel<double> p;
        const bool exact = raster::project_surfel(batch.geometry(i), batch.opacities[i], view, p);
        EXPECT_EQ(st.visible[i] != 0, exact) << "surfel " << i << ", opacity " << batch.opacities[i];
        kept += exact, dropped += !exact;
    }
    EXPECT_GT(kept, 300);
    EXPECT_GT(dropped, 300);
}

TEST(RasterProjection, FirstCullIsTheExactTestAtOpacityOneAndBoundsItBelow) {
    // may_reach_view (the rasterizer's first cull) against project_surfel_lanes, on surfels placed so that
    // the opacity-1 bounding sphere lies within +-2 % of its radius from a side of the widened view or from
    // the near plane: there the sphere test decides. At opacity 1 the two must agree exactly; below, the
    // first cull may only keep more. A few NaN scales too (both then keep them).
    const Camera cam = test_camera(48, 40);
    const auto view = pinhole_view<double>(cam);
    const auto opaque = raster::opaque_reach<double>();
    const double margin = opaque.filter + 1;
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> uni(0, 1);
    int agree_kept = 0, agree_culled = 0, below_kept_more = 0;
    for (int i = 0; i < 4000; ++i) {
        const double su = std::exp(std::log(0.002) + (std::log(2.0) - std::log(0.002)) * uni(rng));
        const double sv = su * (0.2 + 0.8 * uni(rng));
        const double radius = std::sqrt(opaque.disk_rho) * su;
        const double delta = 0.04 * uni(rng) - 0.02;  // the sphere's distance beyond the plane: (1 + delta) r
        Vec3d c{(uni(rng) - 0.5) * 4, (uni(rng) - 0.5) * 4, 0.5 + 9.5 * uni(rng)};
        const int side = i % 5;
        if (side == 4) {
            c.z = raster::kNearPlane + radius * (1 + delta);
        } else {
            // Side planes through the camera centre, a.c >= 0 inside: a = (+-fx, 0, cx + m) or (0, +-fy, cy +
            // m).
            const bool horizontal = side < 2, low = side % 2 == 0;
            const double f = horizontal ? cam.fx : cam.fy;
            const double offset =
                horizontal ? (low ? cam.cx : cam.width - cam.cx) : (low ? cam.cy : cam.height - cam.cy);
            const double a_z = offset + margin, norm = std::sqrt(f * f + a_z * a_z);
            const double along = (-radius * (1 + delta) * norm - a_z * c.z) / f;  // a.c = -(1 + delta) r |a|
            (horizontal ? c.x : c.y) = low ? along : -along;
        }
        const double opacity = i % 2 ? 1.0 : std::exp(std::log(1.0 / 300) * uni(rng));
        auto s = one_surfel(cam, c, su, opacity);
        s.scales = {su, sv};
        if (i % 97 == 0) s.scales[std::size_t(i % 3 == 0)] = std::nan("");
        const auto g = s.geometry(0);
        const bool may = raster::may_reach_view(g.mean, g.scale_u, g.scale_v, opacity, view, opaque);
        raster::ProjectionLanes<double> lanes;
        const bool exact = raster::project_surfel_lanes(g, raster::reach_rho(opacity), view, lanes);
        if (exact) {
            EXPECT_TRUE(may) << "case " << i << ": the first cull dropped a surfel the exact test keeps";
        }
        if (opacity == 1.0 && !std::isnan(g.scale_u) && !std::isnan(g.scale_v)) {
            EXPECT_EQ(may, exact) << "case " << i << ", delta " << delta << ", side " << side;
            (exact ? agree_kept : agree_culled) += may == exact;
        }
        below_kept_more += opacity < 1 && may && !exact;
    }
    EXPECT_GT(agree_kept, 400);  // both outcomes occur at the boundary, in numbers
    EXPECT_GT(agree_culled, 400);
    EXPECT_GT(below_kept_more, 100);  // the bound is loose below opacity 1: the exact test still has work
}

TEST(RasterProjection, TooTransparentSurfelsAreCulled) {
    const Camera cam = test_camera();
    raster::ProjectedSurfel<double> p;
    const auto s = one_surfel(cam, {0, 0, 3}, 0.5, 1.0);
    EXPECT_TRUE(raster::project_surfel(s.geometry(0), 1.0 / 255 * 1.01, pinhole_view<double>(cam), p));
    EXPECT_FALSE(raster::project_surfel(s.geometry(0), 1.0 / 255 * 0.99, pinhole_view<double>(cam), p));
}

}  // namespace
}  // namespace lumigauss
