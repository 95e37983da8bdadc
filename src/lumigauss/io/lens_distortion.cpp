#include "lumigauss/io/lens_distortion.h"

#include <algorithm>
#include <cmath>

namespace lumigauss {

namespace {

double radial_factor(const LensDistortion& d, double r2) {
    const double numerator = 1 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
    const double denominator = 1 + r2 * (d.k4 + r2 * (d.k5 + r2 * d.k6));
    return numerator / denominator;
}

// theta_d / theta of the fisheye polynomial.
double fisheye_factor(const LensDistortion& d, double theta) {
    const double t2 = theta * theta;
    return 1 + t2 * (d.k1 + t2 * (d.k2 + t2 * (d.k3 + t2 * d.k4)));
}

// How far from the centre the lens puts a ray of radius r (radial terms only).
double image_radius(const LensDistortion& d, double r) {
    if (!d.fisheye) return r * radial_factor(d, r * r);
    const double theta = std::atan(r);
    return theta * fisheye_factor(d, theta);
}

// The pinhole image's normalized point at the centre of pixel (x, y) (centres at +0.5).
Vec2<double> pixel_ray(const Camera& c, int x, int y) {
    return {(x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy};
}

// Where the image radius of the lens stops growing with the ray's radius (the polynomial folds back: rays
// beyond it land on pixels that already hold nearer rays), searched up to well past the image's corners;
// infinity when it grows over the whole range. Radial terms only; the tangential terms are checked per pixel
// by the Jacobian.
double fold_radius(const Camera& c, const LensDistortion& d) {
    double reach = 0;
    for (const auto& [x, y] :
         {std::pair{0, 0}, std::pair{c.width, 0}, std::pair{0, c.height}, std::pair{c.width, c.height}})
        reach = std::max(reach, std::hypot((x - c.cx) / c.fx, (y - c.cy) / c.fy));
    const int steps = 4000;
    const double dr = 2 * reach / steps;
    double previous = 0;
    for (int i = 1; i <= steps; ++i) {
        const double r = i * dr;
        const double radius = image_radius(d, r);
        if (!(radius > previous)) return (i - 1) * dr;
        previous = radius;
    }
    return INFINITY;
}

// True when the lens map keeps orientation at `p` (positive Jacobian determinant, by central differences).
bool locally_one_to_one(const LensDistortion& d, Vec2<double> p, double h) {
    const Vec2<double> du = d.distort({p.x + h, p.y}) - d.distort({p.x - h, p.y});
    const Vec2<double> dv = d.distort({p.x, p.y + h}) - d.distort({p.x, p.y - h});
    return du.x * dv.y - du.y * dv.x > 0;
}

// The photo position (array coordinates, pixel centres at integers) of the pinhole pixel (x, y), or false
// when the photo does not hold that ray.
bool source_position(const Camera& c, const LensDistortion& d, double fold, int x, int y, double& sx,
                     double& sy) {
    const Vec2<double> p = pixel_ray(c, x, y);
    if (!(std::hypot(p.x, p.y) < fold)) return false;
    if (!locally_one_to_one(d, p, 0.5 / std::max(c.fx, c.fy))) return false;
    const Vec2<double> q = d.distort(p);
    sx = c.fx * q.x + c.cx - 0.5, sy = c.fy * q.y + c.cy - 0.5;
    return sx >= -0.5 && sx <= c.width - 0.5 && sy >= -0.5 && sy <= c.height - 0.5;
}

}  // namespace

bool LensDistortion::is_identity() const {
    return !fisheye && k1 == 0 && k2 == 0 && k3 == 0 && k4 == 0 && k5 == 0 && k6 == 0 && p1 == 0 && p2 == 0;
}

Vec2<double> LensDistortion::distort(Vec2<double> p) const {
    if (fisheye) {
        const double r = std::hypot(p.x, p.y);
        if (!(r > 1e-12)) return p;  // the centre, where theta_d / r -> 1
        const double theta = std::atan(r);
        return (theta * fisheye_factor(*this, theta) / r) * p;
    }
    const double u = p.x, v = p.y, r2 = u * u + v * v;
    const double R = radial_factor(*this, r2);
    return {u * R + 2 * p1 * u * v + p2 * (r2 + 2 * u * u), v * R + 2 * p2 * u * v + p1 * (r2 + 2 * v * v)};
}

bool colmap_lens_distortion(const std::string& model, const std::vector<double>& params,
                            LensDistortion& out) {
    out = {};
    const auto at = [&](std::size_t i) { return i < params.size() ? params[i] : 0.0; };
    if (model == "SIMPLE_PINHOLE" || model == "PINHOLE") return true;
    if (model == "SIMPLE_RADIAL") {
        out.k1 = at(3);
    } else if (model == "RADIAL") {
        out.k1 = at(3), out.k2 = at(4);
    } else if (model == "OPENCV" || model == "FULL_OPENCV") {
        out.k1 = at(4), out.k2 = at(5), out.p1 = at(6), out.p2 = at(7);
        if (model == "FULL_OPENCV") out.k3 = at(8), out.k4 = at(9), out.k5 = at(10), out.k6 = at(11);
    } else if (model == "SIMPLE_RADIAL_FISHEYE" || model == "RADIAL_FISHEYE") {
        out.fisheye = true;
        out.k1 = at(3);
        if (model == "RADIAL_FISHEYE") out.k2 = at(4);
    } else if (model == "OPENCV_FISHEYE") {
        out.fisheye = true;
        out.k1 = at(4), out.k2 = at(5), out.k3 = at(6), out.k4 = at(7);
    } else {
        return false;
    }
    return true;
}

Image undistort_validity(const Camera& camera, const LensDistortion& lens) {
    Image valid(camera.width, camera.height, 1, 0.0f);
    const double fold = fold_radius(camera, lens);
    double sx = 0, sy = 0;
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x)
            valid.at(x, y, 0) = source_position(camera, lens, fold, x, y, sx, sy) ? 1.0f : 0.0f;
    return valid;
}

Image undistort_image(const Image& distorted, const Camera& camera, const LensDistortion& lens) {
    Image out(camera.width, camera.height, distorted.channels, 0.0f);
    const double fold = fold_radius(camera, lens);
    const int w = distorted.width, h = distorted.height;
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            double sx = 0, sy = 0;
            if (!source_position(camera, lens, fold, x, y, sx, sy)) continue;
            // Bilinear between the four nearest pixel centres, clamped to the photo's edge pixels.
            sx = std::clamp(sx, 0.0, double(w - 1)), sy = std::clamp(sy, 0.0, double(h - 1));
            const int x0 = std::min(int(sx), w - 1), y0 = std::min(int(sy), h - 1);
            const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
            const float fx = float(sx - x0), fy = float(sy - y0);
            for (int c = 0; c < out.channels; ++c) {
                const float top = distorted.at(x0, y0, c) * (1 - fx) + distorted.at(x1, y0, c) * fx;
                const float bottom = distorted.at(x0, y1, c) * (1 - fx) + distorted.at(x1, y1, c) * fx;
                out.at(x, y, c) = top * (1 - fy) + bottom * fy;
            }
        }
    return out;
}

}  // namespace lumigauss
