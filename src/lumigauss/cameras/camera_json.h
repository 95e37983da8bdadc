#pragma once
// Camera paths as JSON: a list of pinhole cameras in the conventions of io/camera.h,
//   [{"name": "frame_000", "width": 640, "height": 480, "fx": 500, "fy": 500, "cx": 320, "cy": 240,
//     "R": [[r00, r01, r02], [r10, r11, r12], [r20, r21, r22]],   world-to-camera rotation, row-major
//     "t": [tx, ty, tz]},                                             X_cam = R X_world + t
//    ...]
// or {"cameras": [...]} with the same list. "R" may also be a flat list of 9 numbers (row-major); "name" is
// optional (default "cam_NNN" by position) and must be unique, and may hold '/' for sub-folders of the
// output (no "..", not absolute).
#include <string>
#include <vector>

#include "lumigauss/io/camera.h"

namespace lumigauss {

struct NamedCamera {
    std::string name;  // output file stem
    Camera camera;
};

// Throws Error naming the file and the entry ("cameras[3]: ...") on a missing file, invalid JSON, a missing
// or non-numeric field, a non-positive size or focal length, an R that is not a rotation (orthonormal to
// 1e-3, determinant +1), a repeated or unsafe name, or an empty list.
std::vector<NamedCamera> read_camera_json(const std::string& path);

// Writes the list in the layout above (full double precision, so reading it back gives the same numbers),
// atomically. Throws Error naming the file on I/O failure.
void write_camera_json(const std::string& path, const std::vector<NamedCamera>& cameras);

}  // namespace lumigauss
