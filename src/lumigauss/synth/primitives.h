#pragma once
// Analytic primitives of the synthetic landmarks and their ray intersection: axis-aligned boxes, vertical
// cylinders (with caps), spheres and the ground square at z = 0. Every primitive is a closed solid (the
// ground is only ever seen from above), so a ray from outside always meets an outward-facing surface.
#include <optional>

#include "lumigauss/math/vec.h"

namespace lumigauss::synth {

struct Ray {
    Vec3d origin;
    Vec3d dir;  // unit length
};

enum class Shape { kBox, kCylinder, kSphere, kGround };

struct Primitive {
    Shape shape = Shape::kBox;
    Vec3d lo, hi;  // axis-aligned bounds (for every shape; for a box they are the box)
    Vec3d center;  // cylinder: axis at (center.x, center.y), spanning lo.z..hi.z; sphere: centre
    double radius = 0;
    int material = 0;
    bool transient = false;  // a pedestrian: part of one photo only, not of the static scene
};

Primitive make_box(Vec3d lo, Vec3d hi, int material);
Primitive make_cylinder(double x, double y, double radius, double z0, double z1, int material);
Primitive make_sphere(Vec3d center, double radius, int material);
Primitive make_ground(double half_size, int material);

struct Hit {
    double t = 0;
    Vec3d normal;  // outward unit normal
    double u = 0;  // surface coordinates in metres (texture space)
    double v = 0;
};

// The nearest hit with t in (t_min, t_max), if any.
std::optional<Hit> intersect(const Primitive& p, const Ray& ray, double t_min, double t_max);

// Whether a point lies strictly inside the solid (never for the ground).
bool contains(const Primitive& p, Vec3d point);

// A point on the surface, uniformly distributed by area, for two uniforms a, b and a third c that picks a
// face; returns the position and the outward normal. The ground is not sampled here (it is infinite in
// effect; the point sampler draws it on a disc).
struct SurfaceSample {
    Vec3d position;
    Vec3d normal;
};
double surface_area(const Primitive& p);
SurfaceSample sample_surface(const Primitive& p, double a, double b, double c);

// The same surface as faces, each the image of the unit square under a map that is uniform by area and
// whose two parameters run along orthogonal directions: a box has six faces (-x, +x, -y, +y, -z, +z), a
// cylinder three (side: a = angle, b = height; bottom and top caps: a = squared radius, b = angle), a sphere
// one (a = height, b = angle). sample_surface(p, a, b, c) is sample_face(p, f, a, b) with face f picked by
// c in proportion to area. The ground has no faces.
int face_count(const Primitive& p);
double face_area(const Primitive& p, int face);
SurfaceSample sample_face(const Primitive& p, int face, double a, double b);
// Typical lengths (metres) of a face along its parameters a and b, to lay out strata of about square shape.
Vec2<double> face_extent(const Primitive& p, int face);

}  // namespace lumigauss::synth
