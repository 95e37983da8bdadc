#include "lumigauss/export/ply_3dgs.h"

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
    std::vector<GaussianSplat> splats;
    try {
        splats = gaussian_splats(model, view_sh, sh_degree);
    } catch (const Error& e) {
        fail_in_file(path, std::string("internal: ") + e.what());
    }
    const std::size_t n = splats.size();
    PlyVertexTable t;
    const auto column = [&](auto&& f) {
        std::vector<float> v(n);
        for (std::size_t i = 0; i < n; ++i) v[i] = f(splats[i], i);
        return v;
    };
    const char* xyz_names[] = {"x", "y", "z"};
    const char* n_names[] = {"nx", "ny", "nz"};
    for (int k = 0; k < 3; ++k)
        t.add(xyz_names[k], column([&](const GaussianSplat& s, std::size_t) { return s.position[k]; }));
    for (int k = 0; k < 3; ++k)
        t.add(n_names[k], column([&](const GaussianSplat&, std::size_t i) { return model.normal(i)[k]; }));
    for (int c = 0; c < 3; ++c)
        t.add("f_dc_" + std::to_string(c),
              column([&](const GaussianSplat& s, std::size_t) { return s.dc[c]; }));
    const std::size_t rest = 3 * std::size_t(view_sh_coefficients(sh_degree) - 1);
    for (std::size_t j = 0; j < rest; ++j)
        t.add("f_rest_" + std::to_string(j),
              column([&](const GaussianSplat& s, std::size_t) { return s.rest[j]; }));
    t.add("opacity", column([&](const GaussianSplat& s, std::size_t) { return s.opacity; }));
    for (int k = 0; k < 3; ++k)
        t.add("scale_" + std::to_string(k),
              column([&](const GaussianSplat& s, std::size_t) { return s.log_scale[k]; }));
    for (int k = 0; k < 4; ++k)
        t.add("rot_" + std::to_string(k),
              column([&](const GaussianSplat& s, std::size_t) { return s.rotation[k]; }));
    write_ply_vertices(path, t);
}

}  // namespace lumigauss
