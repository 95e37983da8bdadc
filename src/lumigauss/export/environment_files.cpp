#include "lumigauss/export/environment_files.h"

#include <filesystem>
#include <map>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/image.h"
#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

std::string safe(std::string s, bool dots) {
    for (char& c : s)
        if (c == '/' || c == '\\' || (dots && c == '.')) c = '_';
    return s;
}

}  // namespace

std::vector<std::string> environment_stems(const std::vector<std::string>& names) {
    std::vector<std::string> stems;
    std::map<std::string, int> uses;
    for (const std::string& n : names) {
        std::filesystem::path p(n);
        p.replace_extension();
        stems.push_back(safe(p.string(), false));
        ++uses[stems.back()];
    }
    for (std::size_t i = 0; i < names.size(); ++i)
        if (uses[stems[i]] > 1) stems[i] = safe(names[i], true);
    return stems;
}

std::vector<std::string> write_environment_files(const std::string& dir,
                                                 const std::vector<NamedEnvironment>& envs, Vec3d up,
                                                 int preview_width) {
    if (envs.empty())
        throw Error("--format env: the model has no learned environments (a bare PLY has none)");
    if (preview_width < 2) throw Error("--preview-width must be at least 2");
    std::filesystem::create_directories(dir);
    std::vector<std::string> names;
    for (const auto& e : envs) names.push_back(e.name);
    const std::vector<std::string> stems = environment_stems(names);
    const Mat3d frame = panorama_frame_for_up(up);
    std::vector<std::string> written;
    for (std::size_t i = 0; i < envs.size(); ++i) {
        const std::string base = (std::filesystem::path(dir) / stems[i]).string();
        write_sh_text(base + "_sh.txt", envs[i].sh);
        write_exr(base + ".exr", render_sh_panorama(envs[i].sh, preview_width, preview_width / 2, frame));
        written.push_back(base + "_sh.txt");
        written.push_back(base + ".exr");
    }
    return written;
}

}  // namespace lumigauss
