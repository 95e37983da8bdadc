// The forward's per-block culling (tile_blocks.h, splat_reach.h) drops the blocks of a splat's bounding box
// that its exact reachable region misses. Dropping a block that some pixel of it needs would change images
// silently wherever the dense-reference scenes do not happen to look, so it is checked here by brute force:
// for thousands of splats (thin and tilted, seen at grazing angles, tiny ones in the screen filter, large
// ones, every opacity), every pixel the kernel reaches must lie in a kept block.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "lumigauss/render/cpu/rasterizer_cpu.h"
#include "lumigauss/render/cpu/tile_blocks.h"
#include "lumigauss/render/surfel_kernel.h"
#include "support/random_surfels.h"

namespace lumigauss {
namespace {

using testing::test_camera;

struct CullingCounts {
    int splats = 0, refined = 0, blocks = 0, culled = 0, reached_pixels = 0;
};

// Checks every tile of one projected splat; T is the precision of the kernel geometry (float as in the
// renderer, double as in the reference path).
template <typename T>
void check_splat(const Camera& cam, const raster::ProjectedSurfel<double>& p, double opacity,
                 CullingCounts& n) {
    const auto gd = raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, opacity, p.reach);
    const raster::SplatGeometry<T> g{
        gd.pa.template cast<T>(), gd.pb.template cast<T>(),         gd.pd.template cast<T>(),
        gd.tw.template cast<T>(), {T(gd.center.x), T(gd.center.y)}, T(gd.opacity),
        T(gd.rho_cutoff)};
    const raster::SplatReach<T> reach = raster::make_splat_reach(g.pa, g.pb, g.pd, g.rho_cutoff);
    n.refined += reach.definite ? 1 : 0;
    const int tiles_x = (cam.width + raster::kTileSize - 1) / raster::kTileSize;
    for (int ty = p.rect.y0 / raster::kTileSize; ty <= p.rect.y1 / raster::kTileSize; ++ty)
        for (int tx = p.rect.x0 / raster::kTileSize; tx <= p.rect.x1 / raster::kTileSize; ++tx) {
            const raster::PixelRect tile =
                cpu::tile_pixels(ty * tiles_x + tx, tiles_x, cam.width, cam.height);
            const std::uint32_t box = cpu::block_mask(p.rect, tile);
            const std::uint32_t kept =
                reach.definite ? box & cpu::reach_block_mask(reach, g.center, tile) : box;
            n.blocks += __builtin_popcount(box);
            n.culled += __builtin_popcount(box & ~kept);
            for (int y = std::max(tile.y0, p.rect.y0); y <= std::min(tile.y1, p.rect.y1); ++y)
                for (int x = std::max(tile.x0, p.rect.x0); x <= std::min(tile.x1, p.rect.x1); ++x) {
                    raster::SplatSample<T> smp;
                    if (!raster::evaluate_splat(g, T(x) + T(0.5), T(y) + T(0.5), smp)) continue;
                    ++n.reached_pixels;
                    const int block = ((y - tile.y0) / cpu::kBlockHeight) * cpu::kBlocksX +
                                      (x - tile.x0) / cpu::kBlockWidth;
                    ASSERT_TRUE(kept >> block & 1u)
                        << "pixel (" << x << ", " << y << ") is reached but its block was culled";
                }
        }
}

template <typename T>
CullingCounts check_random_splats(std::uint32_t seed) {
    // A wide camera so that splats span many tiles.
    const Camera cam = test_camera(160, 96);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uni(0, 1);
    std::normal_distribution<double> gauss(0, 1);
    const auto view = pinhole_view<double>(cam);
    const Mat3d Rt = transpose(cam.rotation);
    CullingCounts n;
    for (int i = 0; i < 3000; ++i) {
        const double z = 0.5 + 30 * uni(rng) * uni(rng);
        const double px = (uni(rng) * 1.4 - 0.2) * cam.width, py = (uni(rng) * 1.4 - 0.2) * cam.height;
        const Vec3d p_cam{(px - cam.cx) / cam.fx * z, (py - cam.cy) / cam.fy * z, z};
        raster::SurfelGeometry<double> g;
        g.mean = Rt * (p_cam - cam.translation);
        g.quat = {gauss(rng), gauss(rng), gauss(rng), gauss(rng)};
        if (i % 3 == 0) {
            // Nearly edge-on: the surfel's normal close to perpendicular to the viewing ray, as ground seen
            // from a standing camera.
            const Vec3d ray = normalize(g.mean - Rt * (-cam.translation));
            Vec3d side = normalize(cross(ray, Vec3d{gauss(rng), gauss(rng), gauss(rng)}));
            const Vec3d normal = normalize(side + (0.02 + 0.2 * uni(rng)) * ray);
            const Vec3d u = normalize(cross(normal, Vec3d{0.3, 0.9, 0.1}));
            g.quat = quaternion_from_rotation(Mat3d::from_columns(u, cross(normal, u), normal));
        }
        // Scales from sub-pixel to metres, anisotropic.
        const double base = std::exp(std::log(0.002) + (std::log(3.0) - std::log(0.002)) * uni(rng));
        g.scale_u = base, g.scale_v = base * (0.05 + uni(rng));
        // Every opacity, including just above the 1/255 threshold (where the reach is tiny and the
        // ellipse's size is a small difference of large terms).
        const double opacity = i % 5 == 1 ? (1.0 / 255) * (1 + std::pow(10.0, -6 + 4 * uni(rng)))
                                          : std::exp(std::log(1.0 / 240) * uni(rng));
        raster::ProjectedSurfel<double> p;
        if (!raster::project_surfel(g, opacity, view, p)) continue;
        ++n.splats;
        check_splat<T>(cam, p, opacity, n);
        if (::testing::Test::HasFatalFailure()) {
            ADD_FAILURE() << "splat " << i;
            return n;
        }
    }
    return n;
}

TEST(RasterBlockCulling, EveryReachedPixelKeepsItsBlockInFloat) {
    const CullingCounts n = check_random_splats<float>(1);
    // The test sees real work: most splats refined, many blocks culled, many pixels checked.
    EXPECT_GT(n.splats, 1500);
    EXPECT_GT(n.refined, n.splats / 2);
    EXPECT_GT(n.culled, n.blocks / 10) << n.culled << " of " << n.blocks;
    EXPECT_GT(n.reached_pixels, 100000);
    std::printf("%d splats (%d refined), %d of %d blocks culled, %d reached pixels checked\n", n.splats,
                n.refined, n.culled, n.blocks, n.reached_pixels);
}

TEST(RasterBlockCulling, EveryReachedPixelKeepsItsBlockInDouble) {
    const CullingCounts n = check_random_splats<double>(2);
    EXPECT_GT(n.culled, n.blocks / 10) << n.culled << " of " << n.blocks;
}

// Opacity just above the threshold: the kernel then reaches only the pixels next to the projected mean
// (where u = v = 0) and the filter's tiny disk, which for a large, close, tilted surfel is centred
// elsewhere (the 3-sigma box's centre). With the mean projected onto a pixel centre, that pixel is reached
// and its block must stay, although the ellipse's size is then a tiny difference of large terms.
TEST(RasterBlockCulling, BarelyOpaqueSurfelKeepsThePixelOfItsMean) {
    const Camera cam = test_camera(160, 96);
    const auto view = pinhole_view<double>(cam);
    const Mat3d Rt = transpose(cam.rotation);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uni(0, 1);
    int checked = 0;
    for (int i = 0; i < 400; ++i) {
        const double z = 0.6 + 3 * uni(rng);
        const int px = 20 + int(120 * uni(rng)), py = 10 + int(76 * uni(rng));
        const Vec3d p_cam{(px + 0.5 - cam.cx) / cam.fx * z, (py + 0.5 - cam.cy) / cam.fy * z, z};
        raster::SurfelGeometry<double> g;
        g.mean = Rt * (p_cam - cam.translation);
        const double tilt = 0.3 + 1.1 * uni(rng), turn = 6.283 * uni(rng);
        const Vec3d axis{std::cos(turn), std::sin(turn), 0};
        g.quat = {std::cos(tilt / 2), axis.x * std::sin(tilt / 2), axis.y * std::sin(tilt / 2), 0};
        g.scale_u = 0.2 + 1.5 * uni(rng), g.scale_v = 0.05 + 0.5 * uni(rng);
        const double opacity = (1.0 / 255) * (1 + std::pow(10.0, -7 + 3 * uni(rng)));
        raster::ProjectedSurfel<double> p;
        if (!raster::project_surfel(g, opacity, view, p)) continue;
        CullingCounts n;
        check_splat<float>(cam, p, opacity, n);
        ASSERT_FALSE(HasFatalFailure()) << "surfel " << i << ", opacity - 1/255 = " << opacity - 1.0 / 255;
        checked += n.reached_pixels > 0;
    }
    EXPECT_GT(checked, 100);  // the mean's pixel is reached in float for most of them
}

// The same property through the real forward (the per-instruction-set clones, eight entries' regions per
// pack): in every block, every entry that clearly reaches a pixel before the pixel's last contributor
// (alpha well above the threshold, so that the scalar evaluation here and the vector one there cannot
// disagree) must be among the entries the forward composited into the block.
TEST(RasterBlockCulling, ForwardCompositesEveryClearlyReachedPair) {
    const Camera cam = test_camera(160, 96);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> uni(0, 1);
    std::normal_distribution<double> gauss(0, 1);
    const Mat3d Rt = transpose(cam.rotation);
    const Vec3d eye = Rt * (-cam.translation);
    SurfelBatch<float> s;
    s.resize(2500);
    for (std::size_t i = 0; i < s.size(); ++i) {
        const double z = 1 + 20 * uni(rng);
        const Vec3d p_cam{(uni(rng) * 1.2 - 0.6) * cam.width / cam.fx * z,
                          (uni(rng) * 1.2 - 0.6) * cam.height / cam.fy * z, z};
        const Vec3d mean = Rt * (p_cam - cam.translation);
        // Mostly nearly edge-on, as ground at a grazing angle.
        const Vec3d ray = normalize(mean - eye);
        const Vec3d side = normalize(cross(ray, Vec3d{gauss(rng), gauss(rng), gauss(rng)}));
        const Vec3d normal = normalize(side + (0.03 + 0.5 * uni(rng) * uni(rng)) * ray);
        const Vec3d u = normalize(cross(normal, Vec3d{0.3, 0.9, 0.1}));
        const Vec4<double> q = quaternion_from_rotation(Mat3d::from_columns(u, cross(normal, u), normal));
        for (int k = 0; k < 3; ++k) s.means[3 * i + k] = float(mean[k]);
        for (int k = 0; k < 4; ++k) s.quats[4 * i + k] = float(q[k]);
        s.scales[2 * i] = float(0.02 + 0.6 * uni(rng)), s.scales[2 * i + 1] = float(0.01 + 0.1 * uni(rng));
        s.opacities[i] = float(0.02 + 0.4 * uni(rng));
        for (int c = 0; c < 3; ++c) s.colors[3 * i + c] = float(uni(rng));
    }
    RasterState<float> st;
    rasterize_forward_cpu(cam, s, RasterSettings<float>{}, st);
    int pairs = 0;
    for (int t = 0; t < st.tiles_x * st.tiles_y; ++t) {
        const raster::PixelRect tile = cpu::tile_pixels(t, st.tiles_x, cam.width, cam.height);
        const std::vector<std::uint32_t>& kept = st.block_entries[std::size_t(t)];
        const std::uint32_t* start = &st.block_start[std::size_t(t) * (cpu::kTileBlocks + 1)];
        for (int b = 0; b < cpu::kTileBlocks; ++b) {
            const std::set<std::uint32_t> composited(kept.begin() + start[b], kept.begin() + start[b + 1]);
            for (int i = 0; i < cpu::kLanes; ++i) {
                const int x = cpu::block_x0(tile, b) + i % cpu::kBlockWidth;
                const int y = cpu::block_y0(tile, b) + i / cpu::kBlockWidth;
                if (x > tile.x1 || y > tile.y1) continue;
                const std::uint32_t last = st.contributors[std::size_t(y) * cam.width + x];
                for (std::uint32_t k = 0; k + 1 <= last; ++k) {
                    const std::uint32_t e = st.tile_start[std::size_t(t)] + k;
                    const raster::PixelRect& r = st.entry_footprint[e].rect;
                    if (x < r.x0 || x > r.x1 || y < r.y0 || y > r.y1) continue;
                    raster::SplatSample<float> smp;
                    if (!raster::evaluate_splat(st.entry_splat[e], float(x) + 0.5f, float(y) + 0.5f, smp))
                        continue;
                    if (smp.alpha < 1.5f / 255 || smp.z < float(raster::kNearPlane) + 0.01f) continue;
                    ++pairs;
                    ASSERT_TRUE(composited.count(k))
                        << "tile " << t << ", pixel (" << x << ", " << y << "): entry " << k
                        << " reaches it but the forward did not composite it";
                }
            }
        }
    }
    EXPECT_GT(pairs, 50000);
}

// The x-extent of the region in a band of rows, against the region itself sampled densely: nothing
// reached lies outside it, and it is not loose for an ellipse (within a pixel of the sampled extent).
TEST(RasterBlockCulling, BandExtentIsTightForAnEllipse) {
    const Camera cam = test_camera(160, 96);
    const auto view = pinhole_view<double>(cam);
    raster::SurfelGeometry<double> g;
    g.mean = transpose(cam.rotation) * (Vec3d{0.4, 0.2, 8} - cam.translation);
    g.quat = normalize_quaternion(Vec4<double>{0.8, 0.5, 0.3, -0.2});  // tilted
    g.scale_u = 1.2, g.scale_v = 0.15;
    raster::ProjectedSurfel<double> p;
    ASSERT_TRUE(raster::project_surfel(g, 0.9, view, p));
    const auto sg = raster::make_splat_geometry(p.tu, p.tv, p.tw, p.center, 0.9, p.reach);
    const auto reach = raster::make_splat_reach(sg.pa, sg.pb, sg.pd, sg.rho_cutoff);
    ASSERT_TRUE(reach.definite);
    int bands = 0;
    for (double dy0 = -40; dy0 < 40; dy0 += 0.9) {
        const double dy1 = dy0 + 1;
        double lo = 0, hi = 0;
        const bool any = raster::reach_in_band(reach, dy0, dy1, lo, hi);
        double seen_lo = 1e9, seen_hi = -1e9;
        for (double dy = dy0; dy <= dy1 + 1e-12; dy += 1.0 / 64)
            for (double dx = -200; dx <= 200; dx += 1.0 / 16) {
                raster::SplatSample<double> smp;
                const double px = sg.center.x + dx, py = sg.center.y + dy;
                if (!raster::evaluate_splat(sg, px, py, smp)) continue;
                seen_lo = std::min(seen_lo, dx), seen_hi = std::max(seen_hi, dx);
            }
        if (seen_lo > seen_hi) continue;  // nothing reached in this band
        ++bands;
        ASSERT_TRUE(any) << "band " << dy0;
        EXPECT_LE(lo, seen_lo) << "band " << dy0;
        EXPECT_GE(hi, seen_hi) << "band " << dy0;
        EXPECT_GT(lo, seen_lo - 1.0) << "band " << dy0;
        EXPECT_LT(hi, seen_hi + 1.0) << "band " << dy0;
    }
    EXPECT_GT(bands, 10);
}

}  // namespace
}  // namespace lumigauss
