// A camera list (cameras/camera_json.h: render --cameras FILE, the viewer's saved views).
#include "lumigauss/cameras/camera_json.h"
#include "fuzz_support.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    Camera c;
    c.width = 64, c.height = 48, c.fx = 50, c.fy = 51, c.cx = 32, c.cy = 24;
    c.translation = {0.5, -1, 4};
    const std::string path = scratch_path("seed_cameras.json");
    write_camera_json(path, {{"front", c}, {"side", c.resized(32, 24)}});
    return {read_file(path)};
}

void parse(Bytes input) {
    const std::string path = scratch_path("input_cameras.json");
    write_file(path, input);
    refuse_cleanly([&] { (void)read_camera_json(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(camera_json, seeds, parse)

}  // namespace lumigauss::fuzz
