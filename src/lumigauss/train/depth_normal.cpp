#include "lumigauss/train/depth_normal.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lumigauss/train/row_parallel.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// torch.nn.functional.normalize's floor on the norm.
constexpr double kNormalizeEps = 1e-12;

void require(bool ok, const char* what) {
    if (!ok) throw Error(std::string("depth/normal loss: ") + what);
}

using train_detail::for_each_row;
using train_detail::sum_in_order;

template <typename T>
Vec3<T> load3(std::span<const T> v, std::size_t p) {
    return {v[3 * p], v[3 * p + 1], v[3 * p + 2]};
}
template <typename T>
void add3(std::span<T> v, std::size_t p, Vec3<T> a) {
    v[3 * p] += a.x, v[3 * p + 1] += a.y, v[3 * p + 2] += a.z;
}

// World-space direction of the unnormalised ray through pixel centre (x + 0.5, y + 0.5), with z_cam = 1,
// so that P = centre + depth * ray for a z-depth.
template <typename T>
struct PixelRays {
    Mat3<T> cam_to_world;
    T fx, fy, cx, cy;
    int width, height;

    explicit PixelRays(const Camera& c)
        : cam_to_world(transpose(c.rotation).template cast<T>()),
          fx(T(c.fx)),
          fy(T(c.fy)),
          cx(T(c.cx)),
          cy(T(c.cy)),
          width(c.width),
          height(c.height) {}

    Vec3<T> ray(int x, int y) const {
        return cam_to_world * Vec3<T>{(T(x) + T(0.5) - cx) / fx, (T(y) + T(0.5) - cy) / fy, T(1)};
    }
    // P relative to the camera centre: the centre cancels in every difference below, and leaving it out
    // keeps float differences from losing digits to a large world offset.
    Vec3<T> point(std::span<const T> depth, int x, int y) const {
        return depth[std::size_t(y) * width + x] * ray(x, y);
    }
    bool interior(int x, int y) const { return x > 0 && y > 0 && x + 1 < width && y + 1 < height; }
    // Central differences over two pixels: along rows (y) and along columns (x).
    Vec3<T> diff_rows(std::span<const T> d, int x, int y) const {
        return point(d, x, y + 1) - point(d, x, y - 1);
    }
    Vec3<T> diff_cols(std::span<const T> d, int x, int y) const {
        return point(d, x + 1, y) - point(d, x - 1, y);
    }
};

template <typename T>
void check_map(std::span<const T> v, std::size_t pixels, std::size_t per_pixel, const char* what) {
    require(v.size() == pixels * per_pixel, what);
}

template <typename T>
void ensure_size(std::vector<T>& v, std::size_t n) {
    if (v.empty()) v.assign(n, T(0));
    require(v.size() == n, "gradient map size does not match the image");
}

}  // namespace

template <typename T>
void expected_depth(std::span<const T> depth, std::span<const T> alpha, std::span<T> out) {
    require(depth.size() == alpha.size() && out.size() == depth.size(), "expected depth: sizes differ");
    for (std::size_t p = 0; p < depth.size(); ++p) {
        const T e = depth[p] / alpha[p];
        out[p] = std::isfinite(e) ? e : T(0);  // torch.nan_to_num(e, 0, 0)
    }
}

template <typename T>
void expected_depth_backward(std::span<const T> depth, std::span<const T> alpha,
                             std::span<const T> grad_expected, std::span<T> grad_depth,
                             std::span<T> grad_alpha) {
    require(depth.size() == alpha.size() && grad_expected.size() == depth.size(),
            "expected depth backward: sizes differ");
    require(grad_depth.size() == depth.size() && grad_alpha.size() == depth.size(),
            "expected depth backward: gradient sizes differ");
    for (std::size_t p = 0; p < depth.size(); ++p) {
        const T e = depth[p] / alpha[p];
        if (!std::isfinite(e)) continue;  // nan_to_num passes no gradient where it replaced the value
        grad_depth[p] += grad_expected[p] / alpha[p];
        grad_alpha[p] -= grad_expected[p] * e / alpha[p];
    }
}

template <typename T>
void depth_to_normal(const Camera& camera, std::span<const T> depth, std::span<T> normal) {
    const PixelRays<T> rays(camera);
    const std::size_t pixels = std::size_t(camera.width) * camera.height;
    require(depth.size() == pixels && normal.size() == 3 * pixels, "depth_to_normal: map sizes differ");
    for_each_row(camera.height, [&](int y) {
        for (int x = 0; x < camera.width; ++x) {
            Vec3<T> n{};
            if (rays.interior(x, y)) {
                const Vec3<T> c = cross(rays.diff_rows(depth, x, y), rays.diff_cols(depth, x, y));
                n = c / std::max(length(c), T(kNormalizeEps));
            }
            const std::size_t p = std::size_t(y) * camera.width + x;
            normal[3 * p] = n.x, normal[3 * p + 1] = n.y, normal[3 * p + 2] = n.z;
        }
    });
}

template <typename T>
void depth_to_normal_backward(const Camera& camera, std::span<const T> depth, std::span<const T> grad_normal,
                              std::span<T> grad_depth) {
    const PixelRays<T> rays(camera);
    const int w = camera.width, h = camera.height;
    const std::size_t pixels = std::size_t(w) * h;
    require(depth.size() == pixels && grad_normal.size() == 3 * pixels && grad_depth.size() == pixels,
            "depth_to_normal backward: map sizes differ");

    // Per interior pixel: gradients of its two difference vectors a (rows) and b (columns).
    std::vector<Vec3<T>> grad_a(pixels), grad_b(pixels);
    for_each_row(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            if (!rays.interior(x, y)) continue;
            const std::size_t p = std::size_t(y) * w + x;
            const Vec3<T> a = rays.diff_rows(depth, x, y), b = rays.diff_cols(depth, x, y);
            const Vec3<T> c = cross(a, b);
            const T len = length(c);
            const Vec3<T> gn = load3(grad_normal, p);
            Vec3<T> gc;
            if (len > T(kNormalizeEps)) {  // d(c/|c|) = (I - n n^T) dc / |c|
                const Vec3<T> n = c / len;
                gc = (gn - dot(n, gn) * n) / len;
            } else {
                gc = gn / T(kNormalizeEps);
            }
            grad_a[p] = cross(b, gc);  // d(gc . a x b)/da = b x gc
            grad_b[p] = cross(gc, a);  // d(gc . a x b)/db = gc x a
        }
    });
    // Gather, rather than scatter, so each pixel's gradient is summed by one thread in a fixed order:
    // P[y,x] enters a at (x, y-1) with + and at (x, y+1) with -, and b at (x-1, y) and (x+1, y) likewise.
    for_each_row(h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            Vec3<T> gp{};
            const std::size_t p = std::size_t(y) * w + x;
            if (y > 0) gp = gp + grad_a[p - w];
            if (y + 1 < h) gp = gp - grad_a[p + w];
            if (x > 0) gp = gp + grad_b[p - 1];
            if (x + 1 < w) gp = gp - grad_b[p + 1];
            grad_depth[p] += dot(rays.ray(x, y), gp);
        }
    });
}

template <typename T>
T normal_consistency_loss(const Camera& camera, const RasterImages<T>& images, std::span<const T> mask,
                          T weight, RasterImageGrads<T>* grads) {
    const int w = images.width, h = images.height;
    const std::size_t pixels = std::size_t(w) * h;
    require(camera.width == w && camera.height == h, "normal loss: camera and image sizes differ");
    check_map<T>(images.depth, pixels, 1, "normal loss: depth map size");
    check_map<T>(images.alpha, pixels, 1, "normal loss: alpha map size");
    check_map<T>(images.normal, pixels, 3, "normal loss: normal map size");
    require(mask.empty() || mask.size() == pixels, "normal loss: mask size");

    std::vector<T> surf_depth(pixels), surf_normal(3 * pixels);
    expected_depth<T>(images.depth, images.alpha, surf_depth);
    depth_to_normal<T>(camera, surf_depth, surf_normal);

    const bool backward = grads != nullptr;
    std::vector<T> grad_surf_normal(backward ? 3 * pixels : 0);
    if (backward) ensure_size(grads->normal, 3 * pixels);
    const T scale = weight / T(pixels);  // mean over all pixels
    std::vector<T> row_sums(h, T(0));
    for_each_row(h, [&](int y) {
        T s = 0;
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y) * w + x;
            const T m = mask.empty() ? T(1) : mask[p];
            // (m N_rend) . (m N_d alpha), alpha detached: the normal-map factor is k = m^2 alpha.
            const T k = m * m * images.alpha[p];
            const Vec3<T> nr = load3<T>(images.normal, p), nd = load3<T>(surf_normal, p);
            s += T(1) - k * dot(nr, nd);
            if (!backward) continue;
            add3<T>(grads->normal, p, (-scale * k) * nd);
            const Vec3<T> gd = (-scale * k) * nr;
            grad_surf_normal[3 * p] = gd.x, grad_surf_normal[3 * p + 1] = gd.y,
                                 grad_surf_normal[3 * p + 2] = gd.z;
        }
        row_sums[y] = s;
    });
    const T loss = sum_in_order(row_sums) / T(pixels);
    if (!backward) return loss;

    std::vector<T> grad_surf_depth(pixels, T(0));
    depth_to_normal_backward<T>(camera, surf_depth, grad_surf_normal, grad_surf_depth);
    ensure_size(grads->depth, pixels);
    ensure_size(grads->alpha, pixels);
    expected_depth_backward<T>(images.depth, images.alpha, grad_surf_depth, grads->depth, grads->alpha);
    return loss;
}

template <typename T>
T distortion_loss(const RasterImages<T>& images, std::span<const T> mask, T weight,
                  RasterImageGrads<T>* grads) {
    const std::size_t pixels = std::size_t(images.width) * images.height;
    check_map<T>(images.distortion, pixels, 1, "distortion loss: distortion map size");
    require(mask.empty() || mask.size() == pixels, "distortion loss: mask size");
    if (grads) ensure_size(grads->distortion, pixels);
    T sum = 0;
    for (std::size_t p = 0; p < pixels; ++p) {
        const T m = mask.empty() ? T(1) : mask[p];
        sum += m * images.distortion[p];
        if (grads) grads->distortion[p] += weight * m / T(pixels);
    }
    return sum / T(pixels);
}

#define LG_INSTANTIATE(T)                                                                                \
    template void expected_depth<T>(std::span<const T>, std::span<const T>, std::span<T>);               \
    template void expected_depth_backward<T>(std::span<const T>, std::span<const T>, std::span<const T>, \
                                             std::span<T>, std::span<T>);                                \
    template void depth_to_normal<T>(const Camera&, std::span<const T>, std::span<T>);                   \
    template void depth_to_normal_backward<T>(const Camera&, std::span<const T>, std::span<const T>,     \
                                              std::span<T>);                                             \
    template T normal_consistency_loss<T>(const Camera&, const RasterImages<T>&, std::span<const T>, T,  \
                                          RasterImageGrads<T>*);                                         \
    template T distortion_loss<T>(const RasterImages<T>&, std::span<const T>, T, RasterImageGrads<T>*);
LG_INSTANTIATE(float)
LG_INSTANTIATE(double)
#undef LG_INSTANTIATE

}  // namespace lumigauss
