#include "lumigauss/synth/primitives.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lumigauss::synth {

namespace {

constexpr double kPi = std::numbers::pi;

// Slab test against the bounds; returns the entry and exit distances.
bool slab(const Vec3d& lo, const Vec3d& hi, const Ray& ray, double& t0, double& t1, int& axis0) {
    t0 = -1e300, t1 = 1e300, axis0 = -1;
    for (int a = 0; a < 3; ++a) {
        const double o = ray.origin[a], d = ray.dir[a];
        if (std::abs(d) < 1e-300) {
            if (o < lo[a] || o > hi[a]) return false;
            continue;
        }
        double ta = (lo[a] - o) / d, tb = (hi[a] - o) / d;
        if (ta > tb) std::swap(ta, tb);
        if (ta > t0) t0 = ta, axis0 = a;
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    return true;
}

// Texture coordinates on an axis-aligned face: the two world axes spanning it.
void face_uv(int axis, const Vec3d& p, Hit& h) {
    if (axis == 0)
        h.u = p.y, h.v = p.z;
    else if (axis == 1)
        h.u = p.x, h.v = p.z;
    else
        h.u = p.x, h.v = p.y;
}

std::optional<Hit> intersect_box(const Primitive& b, const Ray& ray, double t_min, double t_max) {
    double t0, t1;
    int axis;
    if (!slab(b.lo, b.hi, ray, t0, t1, axis)) return std::nullopt;
    Hit h;
    if (t0 > t_min && t0 < t_max && axis >= 0) {
        h.t = t0;
        h.normal[axis] = ray.dir[axis] > 0 ? -1.0 : 1.0;
    } else if (t0 <= t_min && t1 > t_min && t1 < t_max) {
        // The ray starts inside the box (only shadow and visibility rays grazing a contact can): report the
        // exit so that the ray counts as blocked.
        h.t = t1;
        h.normal = -ray.dir;
        axis = 2;
    } else {
        return std::nullopt;
    }
    face_uv(axis, ray.origin + h.t * ray.dir, h);
    return h;
}

std::optional<Hit> intersect_cylinder(const Primitive& c, const Ray& ray, double t_min, double t_max) {
    std::optional<Hit> best;
    const double ox = ray.origin.x - c.center.x, oy = ray.origin.y - c.center.y;
    const double dx = ray.dir.x, dy = ray.dir.y;
    const double a = dx * dx + dy * dy;
    if (a > 1e-18) {
        const double b = ox * dx + oy * dy, cc = ox * ox + oy * oy - c.radius * c.radius;
        const double disc = b * b - a * cc;
        if (disc >= 0) {
            const double s = std::sqrt(disc);
            for (double t : {(-b - s) / a, (-b + s) / a}) {
                if (t <= t_min || t >= t_max) continue;
                const double z = ray.origin.z + t * ray.dir.z;
                if (z < c.lo.z || z > c.hi.z) continue;
                const double px = ox + t * dx, py = oy + t * dy;
                Hit h;
                h.t = t;
                h.normal = {px / c.radius, py / c.radius, 0.0};
                h.u = c.radius * std::atan2(py, px);
                h.v = z;
                best = h;
                break;
            }
        }
    }
    if (std::abs(ray.dir.z) > 1e-18) {
        for (double zc : {c.lo.z, c.hi.z}) {
            const double t = (zc - ray.origin.z) / ray.dir.z;
            if (t <= t_min || t >= t_max || (best && t >= best->t)) continue;
            const double px = ox + t * dx, py = oy + t * dy;
            if (px * px + py * py > c.radius * c.radius) continue;
            Hit h;
            h.t = t;
            h.normal = {0.0, 0.0, zc == c.hi.z ? 1.0 : -1.0};
            h.u = ray.origin.x + t * dx, h.v = ray.origin.y + t * dy;
            best = h;
        }
    }
    return best;
}

std::optional<Hit> intersect_sphere(const Primitive& s, const Ray& ray, double t_min, double t_max) {
    const Vec3d o = ray.origin - s.center;
    const double b = dot(o, ray.dir), c = dot(o, o) - s.radius * s.radius;
    const double disc = b * b - c;
    if (disc < 0) return std::nullopt;
    const double r = std::sqrt(disc);
    for (double t : {-b - r, -b + r}) {
        if (t <= t_min || t >= t_max) continue;
        Hit h;
        h.t = t;
        h.normal = (o + t * ray.dir) / s.radius;
        h.u = s.radius * std::atan2(h.normal.y, h.normal.x);
        h.v = s.radius * std::asin(std::clamp(h.normal.z, -1.0, 1.0));
        return h;
    }
    return std::nullopt;
}

std::optional<Hit> intersect_ground(const Primitive& g, const Ray& ray, double t_min, double t_max) {
    if (ray.dir.z >= 0 || ray.origin.z <= 0) return std::nullopt;
    const double t = -ray.origin.z / ray.dir.z;
    if (t <= t_min || t >= t_max) return std::nullopt;
    const double x = ray.origin.x + t * ray.dir.x, y = ray.origin.y + t * ray.dir.y;
    if (x < g.lo.x || x > g.hi.x || y < g.lo.y || y > g.hi.y) return std::nullopt;
    Hit h;
    h.t = t;
    h.normal = {0.0, 0.0, 1.0};
    h.u = x, h.v = y;
    return h;
}

}  // namespace

Primitive make_box(Vec3d lo, Vec3d hi, int material) {
    Primitive p;
    p.shape = Shape::kBox;
    p.lo = lo, p.hi = hi, p.center = 0.5 * (lo + hi);
    p.material = material;
    return p;
}

Primitive make_cylinder(double x, double y, double radius, double z0, double z1, int material) {
    Primitive p;
    p.shape = Shape::kCylinder;
    p.lo = {x - radius, y - radius, z0}, p.hi = {x + radius, y + radius, z1};
    p.center = {x, y, 0.5 * (z0 + z1)};
    p.radius = radius;
    p.material = material;
    return p;
}

Primitive make_sphere(Vec3d center, double radius, int material) {
    Primitive p;
    p.shape = Shape::kSphere;
    p.lo = center - Vec3d{radius, radius, radius}, p.hi = center + Vec3d{radius, radius, radius};
    p.center = center, p.radius = radius;
    p.material = material;
    return p;
}

Primitive make_ground(double half_size, int material) {
    Primitive p;
    p.shape = Shape::kGround;
    p.lo = {-half_size, -half_size, 0.0}, p.hi = {half_size, half_size, 0.0};
    p.material = material;
    return p;
}

std::optional<Hit> intersect(const Primitive& p, const Ray& ray, double t_min, double t_max) {
    switch (p.shape) {
        case Shape::kBox:
            return intersect_box(p, ray, t_min, t_max);
        case Shape::kCylinder:
            return intersect_cylinder(p, ray, t_min, t_max);
        case Shape::kSphere:
            return intersect_sphere(p, ray, t_min, t_max);
        case Shape::kGround:
            return intersect_ground(p, ray, t_min, t_max);
    }
    return std::nullopt;
}

bool contains(const Primitive& p, Vec3d q) {
    const auto in_open = [](double v, double lo, double hi) { return v > lo && v < hi; };
    switch (p.shape) {
        case Shape::kBox:
            return in_open(q.x, p.lo.x, p.hi.x) && in_open(q.y, p.lo.y, p.hi.y) &&
                   in_open(q.z, p.lo.z, p.hi.z);
        case Shape::kCylinder: {
            const double dx = q.x - p.center.x, dy = q.y - p.center.y;
            return in_open(q.z, p.lo.z, p.hi.z) && dx * dx + dy * dy < p.radius * p.radius;
        }
        case Shape::kSphere:
            return length(q - p.center) < p.radius;
        case Shape::kGround:
            return false;
    }
    return false;
}

namespace {

double box_face_area(const Primitive& b, int axis) {
    const Vec3d e = b.hi - b.lo;
    return axis == 0 ? e.y * e.z : (axis == 1 ? e.x * e.z : e.x * e.y);
}

// Face 2 * axis + high: the face at lo[axis] (high = 0) or hi[axis], spanned by the next two axes.
SurfaceSample sample_box_face(const Primitive& b, int face, double a, double bb) {
    const int axis = face / 2;
    const bool high = face % 2 == 1;
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    SurfaceSample s;
    s.position[axis] = high ? b.hi[axis] : b.lo[axis];
    s.position[ua] = b.lo[ua] + a * (b.hi[ua] - b.lo[ua]);
    s.position[va] = b.lo[va] + bb * (b.hi[va] - b.lo[va]);
    s.normal[axis] = high ? 1.0 : -1.0;
    return s;
}

// Face 0 the side, 1 the bottom cap, 2 the top cap.
SurfaceSample sample_cylinder_face(const Primitive& cy, int face, double a, double b) {
    SurfaceSample s;
    if (face == 0) {
        const double phi = 2 * kPi * a;
        s.normal = {std::cos(phi), std::sin(phi), 0.0};
        s.position = {cy.center.x + cy.radius * s.normal.x, cy.center.y + cy.radius * s.normal.y,
                      cy.lo.z + b * (cy.hi.z - cy.lo.z)};
    } else {
        const bool top = face == 2;
        const double r = cy.radius * std::sqrt(a), phi = 2 * kPi * b;
        s.normal = {0.0, 0.0, top ? 1.0 : -1.0};
        s.position = {cy.center.x + r * std::cos(phi), cy.center.y + r * std::sin(phi),
                      top ? cy.hi.z : cy.lo.z};
    }
    return s;
}

SurfaceSample sample_sphere(const Primitive& sp, double a, double b) {
    const double z = 1 - 2 * a, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * b;
    SurfaceSample s;
    s.normal = {r * std::cos(phi), r * std::sin(phi), z};
    s.position = sp.center + sp.radius * s.normal;
    return s;
}

}  // namespace

int face_count(const Primitive& p) {
    switch (p.shape) {
        case Shape::kBox:
            return 6;
        case Shape::kCylinder:
            return 3;
        case Shape::kSphere:
            return 1;
        case Shape::kGround:
            return 0;
    }
    return 0;
}

double face_area(const Primitive& p, int face) {
    switch (p.shape) {
        case Shape::kBox:
            return box_face_area(p, face / 2);
        case Shape::kCylinder:
            return face == 0 ? 2 * kPi * p.radius * (p.hi.z - p.lo.z) : kPi * p.radius * p.radius;
        case Shape::kSphere:
            return 4 * kPi * p.radius * p.radius;
        case Shape::kGround:
            return 0.0;
    }
    return 0.0;
}

Vec2<double> face_extent(const Primitive& p, int face) {
    switch (p.shape) {
        case Shape::kBox: {
            const int axis = face / 2;
            return {p.hi[(axis + 1) % 3] - p.lo[(axis + 1) % 3], p.hi[(axis + 2) % 3] - p.lo[(axis + 2) % 3]};
        }
        case Shape::kCylinder:  // a cap: the radius, and the circumference halfway out by area
            return face == 0 ? Vec2<double>{2 * kPi * p.radius, p.hi.z - p.lo.z}
                             : Vec2<double>{p.radius, std::sqrt(2.0) * kPi * p.radius};
        case Shape::kSphere:  // a meridian, and the mean circumference of a parallel
            return {kPi * p.radius, 0.5 * kPi * kPi * p.radius};
        case Shape::kGround:
            break;
    }
    return {0.0, 0.0};
}

SurfaceSample sample_face(const Primitive& p, int face, double a, double b) {
    switch (p.shape) {
        case Shape::kBox:
            return sample_box_face(p, face, a, b);
        case Shape::kCylinder:
            return sample_cylinder_face(p, face, a, b);
        case Shape::kSphere:
            return sample_sphere(p, a, b);
        case Shape::kGround:
            break;
    }
    return {{a, b, 0.0}, {0.0, 0.0, 1.0}};
}

double surface_area(const Primitive& p) {
    double total = 0;
    for (int f = 0; f < face_count(p); ++f) total += face_area(p, f);
    return total;
}

SurfaceSample sample_surface(const Primitive& p, double a, double b, double c) {
    const int n = face_count(p);
    if (n == 0) return sample_face(p, 0, a, b);
    double pick = c * surface_area(p);
    int face = 0;
    while (face + 1 < n && pick >= face_area(p, face)) pick -= face_area(p, face++);
    return sample_face(p, face, a, b);
}

}  // namespace lumigauss::synth
