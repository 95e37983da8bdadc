#include "lumigauss/synth/gt_surfels.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/synth/sfm_points.h"

namespace lumigauss::synth {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kSh0 = 0.28209479177387814;  // Y_00: colour = 0.5 + kSh0 * f_dc
// The ground's cells keep their size out to this multiple of the farthest camera's distance from the
// landmark's centre (the radius points3D are drawn within).
constexpr double kNearRadiusPerCamera = 1.3;
// The share of the surfels on the landmark (the rest are on the ground).
constexpr double kLandmarkShare = 0.5;
// The pilot layout has about this fraction of the target's surfels per area; at most kMaxFits fits follow
// it, until the counts are within kCountTolerance of the target's shares.
constexpr double kPilotDensity = 0.25;
constexpr int kMaxFits = 3;
constexpr double kCountTolerance = 0.04;

// A cell of the grid over a face of primitive `prim`: parameters [a0, a1] x [b0, b1] of its face map, or
// for the ground (face -1) squared radius [a0, a1] and angle [b0, b1] about the landmark's centre.
struct Cell {
    int prim = 0, face = 0;
    double a0 = 0, a1 = 0, b0 = 0, b1 = 0;
};

// A surfel before colouring: the centre of a cell with its frame and extent.
struct Candidate {
    Cell cell;
    Vec3d position, normal;
    Vec3d tangent;  // unit, in the surface: the axis of scale_u
    double scale_u = 0, scale_v = 0;
};

struct Layout {
    double cell = 0, ground_cell = 0, near_radius = 0;
    Vec3d centre;
};

// The point at fractions (s, t) of a cell.
SurfaceSample cell_point(const Landmark& l, const Vec3d& centre, const Cell& c, double s, double t) {
    const double a = c.a0 + s * (c.a1 - c.a0), b = c.b0 + t * (c.b1 - c.b0);
    if (c.face >= 0) return sample_face(l.world.prims[std::size_t(c.prim)], c.face, a, b);
    const double r = std::sqrt(a);
    return {{centre.x + r * std::cos(b), centre.y + r * std::sin(b), 0.0}, {0.0, 0.0, 1.0}};
}

// Length of the curve t -> at(t) for t in [0, 1], as a polyline (exact on straight edges).
template <typename F>
double curve_length(const F& at) {
    constexpr int kSegments = 8;
    double sum = 0;
    Vec3d prev = at(0.0);
    for (int k = 1; k <= kSegments; ++k) {
        const Vec3d next = at(double(k) / kSegments);
        sum += length(next - prev);
        prev = next;
    }
    return sum;
}

// `d` projected into the plane of unit normal n, normalised (any tangent if d is along n).
Vec3d tangent_along(Vec3d d, Vec3d n) {
    d = d - dot(d, n) * n;
    if (length(d) > 1e-12) return normalize(d);
    const Vec3d helper = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    return normalize(cross(n, helper));
}

// The surfel of a cell: at its centre, in the surface, its scales the cell's side lengths through the
// centre (the two parameters run along orthogonal directions) times kScalePerCell.
Candidate make_candidate(const Landmark& l, const Vec3d& centre, const Cell& cell) {
    const auto at = [&](double s, double t) { return cell_point(l, centre, cell, s, t).position; };
    const SurfaceSample mid = cell_point(l, centre, cell, 0.5, 0.5);
    Candidate c;
    c.cell = cell;
    c.position = mid.position, c.normal = mid.normal;
    c.tangent = tangent_along(at(0.5 + 1e-6, 0.5) - at(0.5 - 1e-6, 0.5), mid.normal);
    c.scale_u = kScalePerCell * curve_length([&](double s) { return at(s, 0.5); });
    c.scale_v = kScalePerCell * curve_length([&](double t) { return at(0.5, t); });
    return c;
}

// An na x nb grid over each face of each static primitive, na and nb such that cells are about `size`
// metres on a side.
void sample_faces(const Landmark& l, const Vec3d& centre, double size, std::vector<Candidate>& out) {
    for (int pi = 0; pi < int(l.world.prims.size()); ++pi) {
        const Primitive& p = l.world.prims[std::size_t(pi)];
        if (p.transient) continue;
        for (int f = 0; f < face_count(p); ++f) {
            const Vec2<double> extent = face_extent(p, f);
            const int na = std::max(1, int(std::lround(extent.x / size)));
            const int nb = std::max(1, int(std::lround(extent.y / size)));
            for (int i = 0; i < na; ++i)
                for (int j = 0; j < nb; ++j) {
                    const Cell cell{
                        pi, f, double(i) / na, double(i + 1) / na, double(j) / nb, double(j + 1) / nb};
                    out.push_back(make_candidate(l, centre, cell));
                }
        }
    }
}

// Rings of cells around the landmark's centre: `ground_cell` wide out to `near_radius`, then growing with
// the cube of the radius; each ring divided into cells about as long as they are wide. Cells whose
// centre is off the ground are left out.
void sample_ground(const Landmark& l, const Layout& layout, std::vector<Candidate>& out) {
    for (int gi = 0; gi < int(l.world.prims.size()); ++gi) {
        const Primitive& g = l.world.prims[std::size_t(gi)];
        if (g.shape != Shape::kGround) continue;
        const Vec3d c = layout.centre;
        const double r_max =
            std::hypot(std::max(c.x - g.lo.x, g.hi.x - c.x), std::max(c.y - g.lo.y, g.hi.y - c.y));
        for (double r0 = 0; r0 < r_max;) {
            const double growth = std::max(1.0, r0 / layout.near_radius);
            const double width = layout.ground_cell * growth * growth * growth, r1 = r0 + width;
            const int n = std::max(3, int(std::lround(kPi * (r0 + r1) / width)));
            for (int j = 0; j < n; ++j) {
                const Cell cell{gi, -1, r0 * r0, r1 * r1, 2 * kPi * j / n, 2 * kPi * (j + 1) / n};
                const Candidate s = make_candidate(l, c, cell);
                if (s.position.x >= g.lo.x && s.position.x <= g.hi.x && s.position.y >= g.lo.y &&
                    s.position.y <= g.hi.y)
                    out.push_back(s);
            }
            r0 = r1;
        }
    }
}

// Whether a camera sees a surface point: facing it, projecting into the frame widened by `reach_m` metres
// (the surfel's reach), and unoccluded by the static scene.
bool sees(const World& world, const Camera& cam, const SurfaceSample& s, double reach_m) {
    const Vec3d eye = cam.center();
    if (dot(s.normal, eye - s.position) <= 0) return false;
    const Vec3d q = project(cam, s.position);
    if (q.z <= 0) return false;
    const double reach = reach_m * std::max(cam.fx, cam.fy) / q.z;
    if (q.x < -reach || q.y < -reach || q.x > cam.width + reach || q.y > cam.height + reach) return false;
    const Vec3d start = s.position + kRayEpsilon * s.normal;
    return !occluded(world, Ray{start, normalize(eye - start)}, length(eye - start));
}

// Whether a surface point is inside another solid (a face in contact with another primitive, the lower half
// of a dome in its drum): no camera sees it, and the test is much cheaper than tracing towards each camera.
bool buried(const World& world, const SurfaceSample& s) {
    const Vec3d lifted = s.position + kRayEpsilon * s.normal;
    for (const Primitive& p : world.prims)
        if (!p.transient && contains(p, lifted)) return true;
    return false;
}

// Whether some camera sees some of the candidate's cell: its centre or a point near one of its corners (so
// that cells cut by an occluder, the foot of a wall say, are kept).
bool seen(const Landmark& l, const Vec3d& centre, const std::vector<Camera>& cameras, const Candidate& c) {
    constexpr double kProbes[5][2] = {{0.5, 0.5}, {0.1, 0.1}, {0.9, 0.1}, {0.1, 0.9}, {0.9, 0.9}};
    const double reach = 3 * std::max(c.scale_u, c.scale_v);
    for (const auto& probe : kProbes) {
        const SurfaceSample s = cell_point(l, centre, c.cell, probe[0], probe[1]);
        if (buried(l.world, s)) continue;
        for (const Camera& cam : cameras)
            if (sees(l.world, cam, s, reach)) return true;
    }
    return false;
}

std::vector<Candidate> visible_candidates(const Landmark& l, const std::vector<Camera>& cameras,
                                          const Layout& layout) {
    std::vector<Candidate> all;
    sample_faces(l, layout.centre, layout.cell, all);
    sample_ground(l, layout, all);
    std::vector<std::uint8_t> keep(all.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, all.size()), [&](const auto& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) keep[i] = seen(l, layout.centre, cameras, all[i]);
    });
    std::vector<Candidate> kept;
    for (std::size_t i = 0; i < all.size(); ++i)
        if (keep[i]) kept.push_back(all[i]);
    return kept;
}

Layout make_layout(const Landmark& l, const std::vector<Camera>& cameras, double cell, double ground_cell) {
    Layout layout;
    layout.cell = cell;
    layout.ground_cell = ground_cell;
    layout.centre = 0.5 * (l.bbox_lo + l.bbox_hi);
    double farthest = 0;
    for (const Camera& cam : cameras) {
        const Vec3d e = cam.center();
        farthest = std::max(farthest, std::hypot(e.x - layout.centre.x, e.y - layout.centre.y));
    }
    layout.near_radius = std::max(kNearRadiusPerCamera * farthest, 0.5 * length(l.bbox_hi - l.bbox_lo));
    return layout;
}

// The true albedo at a surface point of primitive `prim`, where a ray along -normal meets it (the ray
// tracer's own texture coordinates), or nothing if it misses.
std::optional<Vec3d> albedo_at_point(const Landmark& l, int prim, const SurfaceSample& s) {
    constexpr double kLift = 1e-3;
    const Primitive& p = l.world.prims[std::size_t(prim)];
    const auto hit = intersect(p, Ray{s.position + kLift * s.normal, -s.normal}, 0.0, 2 * kLift);
    if (!hit) return std::nullopt;
    return albedo_at(l.world.materials[std::size_t(p.material)], hit->u, hit->v);
}

// The mean albedo over a cell (kAlbedoSamples x kAlbedoSamples cell centres): the texture as a surfel of
// that size can show it, without the aliasing of a point sample.
std::optional<Vec3d> cell_albedo(const Landmark& l, const Vec3d& centre, const Cell& cell) {
    Vec3d sum;
    int n = 0;
    for (int i = 0; i < kAlbedoSamples; ++i)
        for (int j = 0; j < kAlbedoSamples; ++j) {
            const double s = (i + 0.5) / kAlbedoSamples, t = (j + 0.5) / kAlbedoSamples;
            if (const auto a = albedo_at_point(l, cell.prim, cell_point(l, centre, cell, s, t)))
                sum += *a, ++n;
        }
    if (n == 0) return std::nullopt;
    return sum / double(n);
}

ViewDependentSurfels to_model(const Landmark& l, const Vec3d& centre,
                              const std::vector<Candidate>& candidates) {
    ViewDependentSurfels m;
    m.sh_degree = 0;
    m.surfels.channels = 3;
    SurfelBatch<float>& s = m.surfels;
    for (const Candidate& c : candidates) {
        const auto albedo = cell_albedo(l, centre, c.cell);
        if (!albedo) continue;
        const Vec3d v = cross(c.normal, c.tangent);
        const Vec4<double> q =
            lumigauss::quaternion_from_rotation(Mat3d::from_columns(c.tangent, v, c.normal));
        for (int k = 0; k < 3; ++k) s.means.push_back(float(c.position[k]));
        for (int k = 0; k < 4; ++k) s.quats.push_back(float(q[k]));
        s.scales.push_back(float(c.scale_u));
        s.scales.push_back(float(c.scale_v));
        s.opacities.push_back(float(kOpacity));
        for (int k = 0; k < 3; ++k) m.sh.push_back(float(((*albedo)[k] - 0.5) / kSh0));
    }
    s.colors.assign(3 * s.size(), 0.0f);
    return m;
}

}  // namespace

GtSurfels make_gt_surfels(const Landmark& landmark, const std::vector<Camera>& cameras,
                          const GtSurfelOptions& options) {
    GtSurfels out;
    out.model.surfels.channels = 3;
    if (options.target_count <= 0 || cameras.empty()) return out;
    // A pilot run at known cell sizes counts what is kept on the landmark and on the ground; each count
    // scales about as 1 / cell^2, which fits the cell sizes that share the target between them. A fit
    // off by more than kCountTolerance (the grids round to whole cells, partly seen cells are kept) is
    // refitted from its own counts.
    double landmark_area = 0;
    for (const Primitive& p : landmark.world.prims)
        if (!p.transient) landmark_area += surface_area(p);
    const double near_radius = make_layout(landmark, cameras, 1.0, 1.0).near_radius;
    const double pilot_density = kPilotDensity * options.target_count;
    Layout layout =
        make_layout(landmark, cameras, std::sqrt(landmark_area / (kLandmarkShare * pilot_density)),
                    std::sqrt(kPi * near_radius * near_radius / ((1 - kLandmarkShare) * pilot_density)));
    std::vector<Candidate> kept;
    for (int fit = 0; fit <= kMaxFits; ++fit) {
        kept = visible_candidates(landmark, cameras, layout);
        std::size_t on_landmark = 0;
        for (const Candidate& c : kept) on_landmark += c.cell.face >= 0;
        const double landmark_ratio =
            double(std::max<std::size_t>(on_landmark, 1)) / (kLandmarkShare * options.target_count);
        const double ground_ratio = double(std::max<std::size_t>(kept.size() - on_landmark, 1)) /
                                    ((1 - kLandmarkShare) * options.target_count);
        if (fit > 0 && std::abs(landmark_ratio - 1) < kCountTolerance &&
            std::abs(ground_ratio - 1) < kCountTolerance)
            break;
        if (fit == kMaxFits) break;
        layout = make_layout(landmark, cameras, layout.cell * std::sqrt(landmark_ratio),
                             layout.ground_cell * std::sqrt(ground_ratio));
    }
    out.model = to_model(landmark, layout.centre, kept);
    out.cell = layout.cell, out.ground_cell = layout.ground_cell, out.near_radius = layout.near_radius;
    return out;
}

}  // namespace lumigauss::synth
