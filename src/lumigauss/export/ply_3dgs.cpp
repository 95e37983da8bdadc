#include "lumigauss/export/ply_3dgs.h"

#include "lumigauss/export/two_sided_sh.h"
#include "lumigauss/io/ply.h"
#include "lumigauss/model/view_sh.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

std::vector<std::string> ply_3dgs_property_names(int sh_degree) {
    std::vector<std::string> names = {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    const int rest = 3 * (view_sh_coefficients(sh_degree) - 1);
    for (int k = 0; k < rest; ++k) names.push_back("f_rest_" + std::to_string(k));
    for (const char* s : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
        names.push_back(s);
    return names;
}

void write_3dgs_ply(const std::string& path, const SurfelModel& model, const std::vector<float>& view_sh,
                    int sh_degree) {
    const std::size_t n = model.size();
    try {
        check_view_sh_size(view_sh.size(), n, sh_degree);
    } catch (const Error& e) {
        fail_in_file(path, std::string("internal: ") + e.what());
    }
    const std::size_t count = std::size_t(view_sh_coefficients(sh_degree));
    const auto& xyz = model.param(ModelParam::Xyz);
    const auto& op = model.param(ModelParam::Opacity);
    const auto& sc = model.param(ModelParam::Scaling);
    std::vector<Vec3f> normal(n);
    std::vector<Vec4f> quat(n);
    for (std::size_t i = 0; i < n; ++i) {
        normal[i] = model.normal(i);
        quat[i] = model.unit_quaternion(i);
    }
    PlyVertexTable t;
    const auto column = [&](auto&& f) {
        std::vector<float> v(n);
        for (std::size_t i = 0; i < n; ++i) v[i] = f(i);
        return v;
    };
    const auto coefficient = [&](std::size_t k, int c) {
        return column([&](std::size_t i) { return view_sh[(i * count + k) * 3 + std::size_t(c)]; });
    };
    const char* xyz_names[] = {"x", "y", "z"};
    const char* n_names[] = {"nx", "ny", "nz"};
    for (int k = 0; k < 3; ++k) t.add(xyz_names[k], column([&](std::size_t i) { return xyz[3 * i + k]; }));
    for (int k = 0; k < 3; ++k) t.add(n_names[k], column([&](std::size_t i) { return normal[i][k]; }));
    for (int c = 0; c < 3; ++c) t.add("f_dc_" + std::to_string(c), coefficient(0, c));
    for (int c = 0; c < 3; ++c)
        for (std::size_t k = 1; k < count; ++k)
            t.add("f_rest_" + std::to_string(std::size_t(c) * (count - 1) + k - 1), coefficient(k, c));
    t.add("opacity", column([&](std::size_t i) { return op[i]; }));
    for (int k = 0; k < 2; ++k)
        t.add("scale_" + std::to_string(k), column([&](std::size_t i) { return sc[2 * i + k]; }));
    t.add("scale_2", std::vector<float>(n, kThinLogScale));
    for (int k = 0; k < 4; ++k)
        t.add("rot_" + std::to_string(k), column([&](std::size_t i) { return quat[i][k]; }));
    write_ply_vertices(path, t);
}

}  // namespace lumigauss
