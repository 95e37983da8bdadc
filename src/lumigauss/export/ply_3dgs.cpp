#include "lumigauss/export/ply_3dgs.h"

#include "lumigauss/export/baked_colours.h"
#include "lumigauss/io/ply.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

std::vector<std::string> ply_3dgs_property_names() {
    std::vector<std::string> names = {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
    for (int k = 0; k < kPly3dgsRestCount; ++k) names.push_back("f_rest_" + std::to_string(k));
    for (const char* s : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
        names.push_back(s);
    return names;
}

void write_3dgs_ply(const std::string& path, const SurfelModel& model, const std::vector<float>& colours) {
    const std::size_t n = model.size();
    if (colours.size() != 3 * n)
        fail_in_file(path, "internal: " + std::to_string(colours.size()) + " colour values for " +
                               std::to_string(n) + " surfels");
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
    const char* xyz_names[] = {"x", "y", "z"};
    const char* n_names[] = {"nx", "ny", "nz"};
    for (int k = 0; k < 3; ++k) t.add(xyz_names[k], column([&](std::size_t i) { return xyz[3 * i + k]; }));
    for (int k = 0; k < 3; ++k) t.add(n_names[k], column([&](std::size_t i) { return normal[i][k]; }));
    const float y00 = float(sh_const::kY00);
    for (int c = 0; c < 3; ++c)
        t.add("f_dc_" + std::to_string(c),
              column([&](std::size_t i) { return (colours[3 * i + std::size_t(c)] - 0.5f) / y00; }));
    for (int k = 0; k < kPly3dgsRestCount; ++k)
        t.add("f_rest_" + std::to_string(k), std::vector<float>(n, 0.0f));
    t.add("opacity", column([&](std::size_t i) { return op[i]; }));
    for (int k = 0; k < 2; ++k)
        t.add("scale_" + std::to_string(k), column([&](std::size_t i) { return sc[2 * i + k]; }));
    t.add("scale_2", std::vector<float>(n, kThinLogScale));
    for (int k = 0; k < 4; ++k)
        t.add("rot_" + std::to_string(k), column([&](std::size_t i) { return quat[i][k]; }));
    write_ply_vertices(path, t);
}

}  // namespace lumigauss
