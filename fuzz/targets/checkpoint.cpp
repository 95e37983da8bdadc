// A training checkpoint (train/checkpoint.h: --resume).
#include "lumigauss/train/checkpoint.h"
#include "fuzz_support.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    TrainState state;
    state.config = train_preset("fast");
    state.iteration = 7;
    state.scene_extent = 3.5;
    state.image_names = {"a.png", "b.png"};
    state.model = GaussianModel::from_points({{0, 0, 0}, {1, 0, 0}, {0, 1, 1}},
                                             {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, state.scene_extent, 5);
    state.lighting = LightingMlp(2, 5);
    state.lighting_adam = lighting_optimizer(state.config, 2);
    const std::string path = scratch_path("seed.lgck");
    save_checkpoint(path, state);
    return {read_file(path)};
}

void parse(Bytes input) {
    const std::string path = scratch_path("input.lgck");
    write_file(path, input);
    refuse_cleanly([&] { (void)load_checkpoint(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(checkpoint, seeds, parse)

}  // namespace lumigauss::fuzz
