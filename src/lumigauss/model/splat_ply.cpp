#include "lumigauss/model/splat_ply.h"

#include <tbb/parallel_for.h>

#include <cmath>

#include "lumigauss/io/ply.h"
#include "lumigauss/model/view_sh.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

float sigmoid(float x) {
    return 1.0f / (1.0f + std::exp(-x));
}
float logit(float p) {
    return std::log(p / (1.0f - p));
}

int degree_from_rest_count(int rest, const std::string& path) {
    for (int d = 0; d <= 3; ++d)
        if (rest == 3 * (view_sh_coefficients(d) - 1)) return d;
    fail_in_file(
        path, std::to_string(rest) + " f_rest_* properties do not match any SH degree 0..3 (0, 9, 24, 45)");
}

}  // namespace

ViewDependentSurfels load_2dgs_ply(const std::string& path) {
    const PlyVertexTable t = read_ply_vertices(path);
    if (t.count == 0) fail_in_file(path, "the model has no surfels (0 vertices)");
    int rest = 0;
    while (t.has("f_rest_" + std::to_string(rest))) ++rest;
    ViewDependentSurfels m;
    m.sh_degree = degree_from_rest_count(rest, path);
    // Every column first: a file with a few of them must not make us allocate the whole model.
    for (const char* name : {"x", "y", "z", "rot_0", "rot_1", "rot_2", "rot_3", "scale_0", "scale_1",
                             "opacity", "f_dc_0", "f_dc_1", "f_dc_2"})
        (void)t.column(name, path);
    const std::size_t n = t.count;
    const int nk = view_sh_coefficients(m.sh_degree);
    m.surfels.channels = 3;
    m.surfels.resize(n);
    m.sh.resize(n * std::size_t(nk) * 3);
    const char* xyz[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
        const auto& col = t.column(xyz[k], path);
        for (std::size_t i = 0; i < n; ++i) m.surfels.means[3 * i + k] = col[i];
    }
    for (int k = 0; k < 4; ++k) {
        const auto& col = t.column("rot_" + std::to_string(k), path);
        for (std::size_t i = 0; i < n; ++i) m.surfels.quats[4 * i + k] = col[i];
    }
    for (int k = 0; k < 2; ++k) {
        const auto& col = t.column("scale_" + std::to_string(k), path);
        for (std::size_t i = 0; i < n; ++i) m.surfels.scales[2 * i + k] = std::exp(col[i]);
    }
    const auto& op = t.column("opacity", path);
    for (std::size_t i = 0; i < n; ++i) m.surfels.opacities[i] = sigmoid(op[i]);
    for (int c = 0; c < 3; ++c) {
        const auto& dc = t.column("f_dc_" + std::to_string(c), path);
        for (std::size_t i = 0; i < n; ++i) m.sh[i * nk * 3 + c] = dc[i];
        for (int k = 1; k < nk; ++k) {
            const auto& col = t.column("f_rest_" + std::to_string(c * (nk - 1) + (k - 1)), path);
            for (std::size_t i = 0; i < n; ++i) m.sh[(i * nk + k) * 3 + c] = col[i];
        }
    }
    for (std::size_t i = 0; i < n; ++i) {
        const float* q = &m.surfels.quats[4 * i];
        if (q[0] == 0 && q[1] == 0 && q[2] == 0 && q[3] == 0)
            fail_in_file(path, "vertex " + std::to_string(i) + " has a zero quaternion");
    }
    return m;
}

void save_2dgs_ply(const std::string& path, const ViewDependentSurfels& m) {
    const std::size_t n = m.size();
    const int nk = view_sh_coefficients(m.sh_degree);
    PlyVertexTable t;
    const auto column = [&](auto&& f) {
        std::vector<float> v(n);
        for (std::size_t i = 0; i < n; ++i) v[i] = f(i);
        return v;
    };
    const char* xyz[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k)
        t.add(xyz[k], column([&](std::size_t i) { return m.surfels.means[3 * i + k]; }));
    for (int c = 0; c < 3; ++c)
        t.add("f_dc_" + std::to_string(c), column([&](std::size_t i) { return m.sh[i * nk * 3 + c]; }));
    for (int c = 0; c < 3; ++c)
        for (int k = 1; k < nk; ++k)
            t.add("f_rest_" + std::to_string(c * (nk - 1) + (k - 1)),
                  column([&](std::size_t i) { return m.sh[(i * nk + k) * 3 + c]; }));
    t.add("opacity", column([&](std::size_t i) { return logit(m.surfels.opacities[i]); }));
    for (int k = 0; k < 2; ++k)
        t.add("scale_" + std::to_string(k),
              column([&](std::size_t i) { return std::log(m.surfels.scales[2 * i + k]); }));
    for (int k = 0; k < 4; ++k)
        t.add("rot_" + std::to_string(k), column([&](std::size_t i) { return m.surfels.quats[4 * i + k]; }));
    write_ply_vertices(path, t);
}

void colors_for_view(ViewDependentSurfels& m, const Vec3d& camera_center) {
    const int nk = view_sh_coefficients(m.sh_degree);
    m.surfels.channels = 3;
    m.surfels.colors.resize(m.size() * 3);
    const Vec3f cam = camera_center.cast<float>();
    tbb::parallel_for(std::size_t(0), m.size(), [&](std::size_t i) {
        const Vec3f mean{m.surfels.means[3 * i], m.surfels.means[3 * i + 1], m.surfels.means[3 * i + 2]};
        const Vec3f d = mean - cam;
        const float len = length(d);
        const Vec3f dir = len > 0 ? d / len : Vec3f{0, 0, 1};
        const Vec3f rgb = eval_view_sh(m.sh_degree, &m.sh[i * nk * 3], dir);
        for (int c = 0; c < 3; ++c) m.surfels.colors[3 * i + c] = std::max(0.0f, 0.5f + rgb[c]);
    });
}

}  // namespace lumigauss
