#include "lumigauss/synth/sfm_points.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "lumigauss/synth/rng.h"

namespace lumigauss::synth {

namespace {

// Cosine of the largest angle between the normal and the direction to a camera that still counts as seen.
const double kMinViewCos = std::cos(87.0 * std::numbers::pi / 180.0);

// A candidate: half the candidates on the landmark (area-weighted over its primitives), half on a disc of
// ground around it (uniform by area), so the building is not starved by the much larger ground.
SurfaceSample sample_candidate(const Landmark& l, const std::vector<double>& cumulative_area,
                               double ground_radius, Rng& rng) {
    if (rng.bernoulli(0.5)) {
        const Vec3d c = 0.5 * (l.bbox_lo + l.bbox_hi);
        const double r = ground_radius * std::sqrt(rng.uniform()), phi = 2 * std::numbers::pi * rng.uniform();
        return {{c.x + r * std::cos(phi), c.y + r * std::sin(phi), 0.0}, {0.0, 0.0, 1.0}};
    }
    const double pick = rng.uniform() * cumulative_area.back();
    std::size_t i = 0;
    while (i + 1 < cumulative_area.size() && pick >= cumulative_area[i]) ++i;
    const double a = rng.uniform(), b = rng.uniform(), c = rng.uniform();
    return sample_surface(l.world.prims[i], a, b, c);
}

std::optional<Observation> observe(const TrainingView& v, int index, const SurfaceSample& s) {
    const Camera& cam = *v.camera;
    const Vec3d eye = cam.center();
    const Vec3d to_eye = eye - s.position;
    const double dist = length(to_eye);
    if (dot(s.normal, to_eye) < kMinViewCos * dist) return std::nullopt;
    const Vec3d q = project(cam, s.position);
    if (q.z <= 0 || q.x < 0 || q.y < 0 || q.x >= cam.width || q.y >= cam.height) return std::nullopt;
    const Vec3d start = s.position + kRayEpsilon * s.normal;
    const Vec3d dir = normalize(eye - start);
    if (occluded(*v.world, Ray{start, dir}, length(eye - start))) return std::nullopt;
    return Observation{index, q.x, q.y};
}

void finish_point(SfmPoint& p, const std::vector<TrainingView>& views, double sigma, Rng& rng) {
    p.position = p.surface + sigma * Vec3d{rng.normal(), rng.normal(), rng.normal()};
    double sq = 0;
    double rgb[3] = {0, 0, 0};
    for (const Observation& o : p.track) {
        const TrainingView& v = views[o.view];
        const Vec3d q = project(*v.camera, p.position);
        sq += (q.x - o.x) * (q.x - o.x) + (q.y - o.y) * (q.y - o.y);
        const std::size_t px = (std::size_t(o.y) * v.camera->width + std::size_t(o.x)) * 3;
        for (int c = 0; c < 3; ++c) rgb[c] += (*v.rgb8)[px + c];
    }
    const double n = double(p.track.size());
    p.error = std::sqrt(sq / n);
    for (int c = 0; c < 3; ++c) p.rgb[c] = std::uint8_t(std::lround(rgb[c] / n));
}

}  // namespace

Vec3d project(const Camera& camera, Vec3d p) {
    const Vec3d c = camera.world_to_camera(p);
    return {camera.fx * c.x / c.z + camera.cx, camera.fy * c.y / c.z + camera.cy, c.z};
}

std::vector<SfmPoint> sample_sfm_points(const Landmark& landmark, const std::vector<TrainingView>& views,
                                        const SfmSamplingOptions& options) {
    std::vector<double> cumulative;
    double total = 0;
    for (const Primitive& p : landmark.world.prims) cumulative.push_back(total += surface_area(p));

    // Candidates are independent: each draws from its own stream, so the result is thread-count free.
    std::vector<std::optional<SfmPoint>> found(std::size_t(options.candidates));
    tbb::parallel_for(tbb::blocked_range<int>(0, options.candidates), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i < r.end(); ++i) {
            Rng rng(options.seed, Stream::kPoint, std::uint64_t(i));
            const SurfaceSample s = sample_candidate(landmark, cumulative, options.ground_radius, rng);
            SfmPoint p;
            p.surface = s.position, p.normal = s.normal;
            for (int v = 0; v < int(views.size()); ++v)
                if (auto o = observe(views[v], v, s)) p.track.push_back(*o);
            if (p.track.size() < 2) continue;
            finish_point(p, views, options.noise_sigma, rng);
            found[std::size_t(i)] = std::move(p);
        }
    });
    std::vector<SfmPoint> points;
    for (auto& f : found)
        if (f) points.push_back(std::move(*f));
    return points;
}

}  // namespace lumigauss::synth
