#pragma once
// The dense brute-force reference of the surfel rasterizer: every pixel against every surfel, no tiles,
// no binning, double precision. It shares only the per-surfel projection and the per-pixel kernel
// (surfel_projection.h, surfel_kernel.h) with the real backends; visibility, ordering and compositing
// are written here again, plainly, so that the tiled renderer's bookkeeping is checked against it.
#include <algorithm>
#include <numeric>

#include "lumigauss/render/raster_types.h"
#include "lumigauss/render/surfel_kernel.h"

namespace lumigauss::testing {

inline RasterImages<double> reference_render(const Camera& cam, const SurfelBatch<double>& s,
                                             const std::vector<double>& background = {}) {
    using namespace raster;
    const PinholeView<double> view = pinhole_view<double>(cam);
    const int C = s.channels;
    std::vector<ProjectedSurfel<double>> proj(s.size());
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (project_surfel(s.geometry(i), s.opacities[i], view, proj[i])) order.push_back(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](auto a, auto b) { return proj[a].depth < proj[b].depth; });

    RasterImages<double> img;
    const std::size_t np = std::size_t(cam.width) * cam.height;
    img.width = cam.width, img.height = cam.height, img.channels = C;
    img.color.assign(np * C, 0), img.alpha.assign(np, 0), img.depth.assign(np, 0);
    img.median_depth.assign(np, 0), img.normal.assign(np * 3, 0), img.distortion.assign(np, 0);
    for (int y = 0; y < cam.height; ++y) {
        for (int x = 0; x < cam.width; ++x) {
            const std::size_t pix = std::size_t(y) * cam.width + x;
            double trans = 1, m1 = 0, m2 = 0;
            for (std::size_t i : order) {
                const PixelRect& r = proj[i].rect;
                if (x < r.x0 || x > r.x1 || y < r.y0 || y > r.y1) continue;
                SplatSample<double> smp;
                const SplatGeometry<double> g =
                    make_splat_geometry(proj[i].tu, proj[i].tv, proj[i].tw, proj[i].center, s.opacities[i]);
                if (!evaluate_splat(g, x + 0.5, y + 0.5, smp)) continue;
                const double next = trans * (1 - smp.alpha);
                if (next < kTransmittanceMin) break;
                const double w = smp.alpha * trans;
                for (int c = 0; c < C; ++c) img.color[pix * C + c] += w * s.colors[i * C + c];
                img.depth[pix] += w * smp.z;
                for (int k = 0; k < 3; ++k) img.normal[pix * 3 + k] += w * proj[i].normal[k];
                const double m = distortion_depth(smp.z);
                // Sum over earlier contributions j of w w_j (m - m_j)^2, expanded.
                img.distortion[pix] += w * (m * m * (1 - trans) + m2 - 2 * m * m1);
                m1 += w * m, m2 += w * m * m;
                if (trans > 0.5) img.median_depth[pix] = smp.z;
                trans = next;
            }
            img.alpha[pix] = 1 - trans;
            for (int c = 0; c < C; ++c)
                img.color[pix * C + c] += trans * (background.empty() ? 0.0 : background[c]);
        }
    }
    return img;
}

}  // namespace lumigauss::testing
