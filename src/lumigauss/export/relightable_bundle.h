#pragma once
// `--format ply-relightable`: the full relightable model plus the lighting of every training photo, so that
// other tools can relight it without our MLP. Two files (docs/formats.md describes every field):
//   FILE.ply                  the official LumiGauss relightable PLY (model/relightable_ply.h), raw values
//   FILE.environments.json    sidecar (relightable_sidecar_path): the environment radiance SH of every
//                             training photo, as the lighting MLP gives it (lighting.env_sh(i)), world frame
// Sidecar layout:
//   {"format": "lumigauss-environments", "version": 1,
//    "model": "FILE.ply" (file name, same folder), "surfels": N,
//    "sh_degree": 2, "sh_basis": "real SH, order Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22 (sh.h)",
//    "quantity": "radiance", "up": "+z",
//    "environments": [{"name": PHOTO, "index": i, "sh": [[R, G, B] x 9]}, ...]}
#include <string>
#include <vector>

#include "lumigauss/math/vec.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/shading/sh.h"

namespace lumigauss {

struct NamedEnvironment {
    std::string name;
    int index = 0;
    ShCoeffs<double> sh;
};

struct EnvironmentSidecar {
    std::string model;  // the PLY's file name
    std::size_t surfels = 0;
    std::string up = "+z";
    std::vector<NamedEnvironment> environments;
};

// FILE minus a trailing ".ply" (any case), plus ".environments.json".
std::string relightable_sidecar_path(const std::string& ply_path);

// The learned environment of every training photo of the run, in embedding order.
std::vector<NamedEnvironment> learned_environments(const TrainedRun& run);

// Writes the PLY and its sidecar (both atomically); returns the sidecar path.
std::string write_relightable_bundle(const std::string& ply_path, const TrainedRun& run, Vec3d up);

// Reads a sidecar back. Throws Error naming the file on invalid JSON or a missing/malformed field.
EnvironmentSidecar read_environment_sidecar(const std::string& path);

}  // namespace lumigauss
