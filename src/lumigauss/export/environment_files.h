#pragma once
// `--format env`: the per-photo environments of a run as files, into a folder:
//   STEM_sh.txt    9 rows "R G B" of radiance SH, world frame (shading/sh_text.h; what `render --light` and
//                  the official --envmaps read)
//   STEM.exr       an equirectangular preview of that radiance (render_sh_panorama), width x width/2, top
//                  row along the up axis (shading/envmap.h, up_axis.h), linear float RGB
// STEM is the photo name without its extension, with '/' and '\' replaced by '_'; when two photos would get
// the same STEM, the full name is used (with '.' also replaced by '_').
#include <string>
#include <vector>

#include "lumigauss/export/relightable_bundle.h"
#include "lumigauss/math/vec.h"

namespace lumigauss {

// The file stems of the photos (rule above), one per name, all distinct.
std::vector<std::string> environment_stems(const std::vector<std::string>& names);

// Writes both files per environment into `dir` (created). Returns the paths written. Throws Error when
// there is no environment (a bare PLY) or on I/O failure.
std::vector<std::string> write_environment_files(const std::string& dir,
                                                 const std::vector<NamedEnvironment>& envs, Vec3d up,
                                                 int preview_width);

}  // namespace lumigauss
