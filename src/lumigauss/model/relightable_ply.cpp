#include "lumigauss/model/relightable_ply.h"

#include <utility>
#include <vector>

#include "lumigauss/io/ply.h"

namespace lumigauss {

namespace {

// Column name and the float offset inside a surfel's row of `param` for every official field, in file order.
struct Field {
    std::string name;
    ModelParam param;
    int offset;
};

void transfer_fields(std::vector<Field>& f, const std::string& side, ModelParam p) {
    for (int c = 0; c < 3; ++c) f.push_back({"f_dc_" + side + "_" + std::to_string(c), p, c});
    for (int c = 0; c < 3; ++c)
        for (int k = 1; k < kTransferCoeffs; ++k)
            f.push_back({"f_rest_" + side + "_" + std::to_string(c * 8 + k - 1), p, k * 3 + c});
}

const std::vector<Field>& fields() {
    static const std::vector<Field> f = [] {
        std::vector<Field> v;
        for (int a = 0; a < 3; ++a) v.push_back({std::string(1, "xyz"[a]), ModelParam::Xyz, a});
        transfer_fields(v, "positive", ModelParam::TransferPositive);
        transfer_fields(v, "negative", ModelParam::TransferNegative);
        for (int a = 0; a < 3; ++a) v.push_back({"albedo_" + std::to_string(a), ModelParam::Albedo, a});
        v.push_back({"opacity", ModelParam::Opacity, 0});
        for (int a = 0; a < 2; ++a) v.push_back({"scale_" + std::to_string(a), ModelParam::Scaling, a});
        for (int a = 0; a < 4; ++a) v.push_back({"rot_" + std::to_string(a), ModelParam::Rotation, a});
        return v;
    }();
    return f;
}

std::vector<float> column_of(const SurfelModel& m, const Field& f) {
    const auto& v = m.param(f.param);
    const auto w = std::size_t(SurfelModel::width(f.param));
    std::vector<float> col(m.size());
    for (std::size_t i = 0; i < col.size(); ++i) col[i] = v[i * w + std::size_t(f.offset)];
    return col;
}

}  // namespace

void save_relightable_ply(const std::string& path, const SurfelModel& model) {
    PlyVertexTable table;
    table.count = model.size();
    const auto& f = fields();
    // x y z, then the (always zero) normals, then everything else in the official order.
    for (std::size_t i = 0; i < 3; ++i) table.add(f[i].name, column_of(model, f[i]));
    for (const char* n : {"nx", "ny", "nz"}) table.add(n, std::vector<float>(model.size(), 0.0f));
    for (std::size_t i = 3; i < f.size(); ++i) table.add(f[i].name, column_of(model, f[i]));
    write_ply_vertices(path, table);
}

SurfelModel load_relightable_ply(const std::string& path) {
    const PlyVertexTable table = read_ply_vertices(path);
    if (table.count == 0) fail_in_file(path, "the model has no surfels (0 vertices)");
    // Every column first: a file with a few of them must not make us allocate the whole model.
    for (const Field& f : fields()) (void)table.column(f.name, path);
    const std::size_t n = table.count;
    std::vector<std::vector<float>> raw(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p)
        raw[std::size_t(p)].resize(n * std::size_t(SurfelModel::width(ModelParam(p))));
    for (const Field& f : fields()) {
        const std::vector<float>& col = table.column(f.name, path);
        const auto w = std::size_t(SurfelModel::width(f.param));
        auto& dst = raw[std::size_t(f.param)];
        for (std::size_t i = 0; i < n; ++i) dst[i * w + std::size_t(f.offset)] = col[i];
    }
    return SurfelModel::from_raw(std::move(raw));
}

}  // namespace lumigauss
