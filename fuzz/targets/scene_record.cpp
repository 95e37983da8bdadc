// A run's scene.json (model/scene_record.h): the scene path and camera poses that render, eval and view read.
#include "lumigauss/model/scene_record.h"
#include "fuzz_support.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    SceneRecord r;
    r.scene = "/data/plaza";
    r.format = "colmap-text";
    for (int i = 0; i < 2; ++i) {
        RecordedPhoto p;
        p.name = "train_000" + std::to_string(i) + ".png";
        p.split = i == 0 ? "train" : "test";
        p.rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        p.translation = {0.5 * i, -1, 2};
        r.photos.push_back(p);
    }
    const std::string path = scratch_path("seed_scene.json");
    save_scene_record(path, r);
    return {read_file(path), R"({"scene": "s", "photos": []})"};
}

void parse(Bytes input) {
    const std::string path = scratch_path("scene.json");
    write_file(path, input);
    refuse_cleanly([&] { (void)load_scene_record(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(scene_record, seeds, parse)

}  // namespace lumigauss::fuzz
