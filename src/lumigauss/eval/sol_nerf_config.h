#pragma once
// The per-scene constants of the SOL-NeRF protocol (eval/sol_nerf.h), read from a JSON file. The three
// NeRF-OSR scenes of the paper ship as configs/sol_nerf/{lk2,st,lwp}.json (configs/sol_nerf/README.md).
//
//   {
//     "scene": "lk2",                       (informative)
//     "angles": 51,                         (y-angles searched per image; optional, default 51)
//     "defaults": {                         (optional; any per-image key below except name)
//       "rotation_deg": {"x": -90, "y": 0, "z": 0},
//       "hdr_threshold": 0.999, "hdr_scale": 10
//     },
//     "images": [
//       {"name": "01-08_07_30_IMG_6710.JPG",           the test photo (its name or stem in the scene)
//        "env_map": "ENV_MAP_CC/01-08_07_30/20210801_082411.jpg",
//        "mask": "01-08_07_30_IMG_6710.png",           evaluation mask; optional (absent: the scene's mask)
//        "y_range_pi": [-0.1, 0.4]}                    search range, in units of pi radians
//     ]
//   }
// Required per image (directly or through "defaults"): name, env_map, y_range_pi, hdr_threshold, hdr_scale.
// rotation_deg defaults to 0 on each axis. Keys starting with "_" are comments; any other unknown key is an
// error (a typo must not silently fall back to a default).
//
// Relative paths: env_map against the environment root, mask against the mask root (SolNerfRoots); when a
// root is not given, against the scene folder, then its final/ subfolder (NeRF-OSR keeps ENV_MAP_CC there).
// Absolute paths are used as they are.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace lumigauss {

inline constexpr int kSolNerfDefaultAngles = 51;

struct SolNerfImageConfig {
    std::string name;
    std::string env_map;
    std::string mask;                    // empty: the scene's own mask
    double rotation_deg[3] = {0, 0, 0};  // x0, y0, z0 of the fixed alignment
    double hdr_threshold = 0, hdr_scale = 1;
    double y_min = 0, y_max = 0;  // radians (y_range_pi times pi)
};

struct SolNerfConfig {
    std::string path;  // the file it came from (for messages and the report)
    std::string scene;
    int angles = kSolNerfDefaultAngles;
    std::vector<SolNerfImageConfig> images;
};

// Throws Error naming `path` (and the image entry) when the file is missing, not JSON, or breaks the rules
// above.
SolNerfConfig load_sol_nerf_config(const std::string& path);
SolNerfConfig parse_sol_nerf_config(const nlohmann::json& json, const std::string& path);

struct SolNerfRoots {
    std::string scene;      // the scene folder
    std::string env_root;   // empty: the scene folder (then scene/final)
    std::string mask_root;  // empty: the scene folder (then scene/final)
};

// The file a configured relative or absolute path names: the first candidate that exists, or nullopt.
// `tried` receives every candidate, for the error message.
std::optional<std::string> resolve_sol_nerf_path(const std::string& configured, const std::string& root,
                                                 const std::string& scene, std::vector<std::string>& tried);

// The shipped config of a NeRF-OSR scene ("lk2", "st", "lwp"): the first existing <dir>/<name>.json.
std::optional<std::string> find_shipped_sol_nerf_config(const std::string& name,
                                                        const std::vector<std::string>& dirs);
// The shipped scene a scene path names: a path component equal to lk2, st or lwp or starting with it and
// '_' (Zenodo's lk2_colmap/undistorted). Empty when none does.
std::string guess_sol_nerf_scene(const std::string& scene_path);

}  // namespace lumigauss
