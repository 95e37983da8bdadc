#include "lumigauss/export/relightable_bundle.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

std::string relightable_sidecar_path(const std::string& ply_path) {
    std::string base = ply_path;
    if (base.size() >= 4) {
        std::string tail = base.substr(base.size() - 4);
        std::transform(tail.begin(), tail.end(), tail.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        if (tail == ".ply") base.resize(base.size() - 4);
    }
    return base + ".environments.json";
}

std::vector<NamedEnvironment> learned_environments(const TrainedRun& run) {
    std::vector<NamedEnvironment> out;
    for (int i = 0; i < int(run.image_names.size()); ++i)
        out.push_back({run.image_names[std::size_t(i)], i, run.learned_sh(i)});
    return out;
}

std::string write_relightable_bundle(const std::string& ply_path, const TrainedRun& run, Vec3d up) {
    save_relightable_ply(ply_path, run.model);
    nlohmann::json envs = nlohmann::json::array();
    for (const NamedEnvironment& e : learned_environments(run)) {
        nlohmann::json sh = nlohmann::json::array();
        for (int k = 0; k < kShCount; ++k) sh.push_back({e.sh.c[k].x, e.sh.c[k].y, e.sh.c[k].z});
        envs.push_back({{"name", e.name}, {"index", e.index}, {"sh", sh}});
    }
    nlohmann::json j;
    j["format"] = "lumigauss-environments";
    j["version"] = 1;
    j["model"] = std::filesystem::path(ply_path).filename().string();
    j["surfels"] = run.model.size();
    j["sh_degree"] = 2;
    j["sh_basis"] = "real SH, order Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22 (sh.h)";
    j["quantity"] = "radiance";
    j["up"] = up_axis_name(up);
    j["environments"] = envs;
    const std::string sidecar = relightable_sidecar_path(ply_path);
    write_file_atomically(sidecar, j.dump(2) + "\n");
    return sidecar;
}

EnvironmentSidecar read_environment_sidecar(const std::string& path) {
    const nlohmann::json j = nlohmann::json::parse(read_text_file(path), nullptr, false);
    if (j.is_discarded() || !j.is_object()) fail_in_file(path, "not a JSON object");
    if (j.value("format", std::string()) != "lumigauss-environments")
        fail_in_file(path, "\"format\" is not \"lumigauss-environments\"");
    EnvironmentSidecar s;
    try {
        s.model = j.at("model").get<std::string>();
        s.surfels = j.at("surfels").get<std::size_t>();
        s.up = j.value("up", std::string("+z"));
        const auto& envs = j.at("environments");
        for (std::size_t e = 0; e < envs.size(); ++e) {
            NamedEnvironment env;
            env.name = envs[e].at("name").get<std::string>();
            env.index = envs[e].at("index").get<int>();
            const auto& sh = envs[e].at("sh");
            if (!sh.is_array() || sh.size() != std::size_t(kShCount))
                fail_in_file(path, "environments[" + std::to_string(e) + "].sh: expected 9 rows");
            for (int k = 0; k < kShCount; ++k) {
                const auto& row = sh[std::size_t(k)];
                if (!row.is_array() || row.size() != 3)
                    fail_in_file(path, "environments[" + std::to_string(e) + "].sh: expected [R, G, B] rows");
                for (int c = 0; c < 3; ++c) env.sh.c[k][c] = row[std::size_t(c)].get<double>();
            }
            s.environments.push_back(std::move(env));
        }
    } catch (const nlohmann::json::exception& ex) {
        fail_in_file(path, std::string("malformed: ") + ex.what());
    }
    return s;
}

}  // namespace lumigauss
