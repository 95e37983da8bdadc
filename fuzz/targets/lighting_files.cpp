// A run's lighting files: the MLP (lighting.lgmlp), the sky residuals (sky.lgsky) and appearance.json
// (model/lighting_mlp.h, model/sky_residual.h, model/run_files.h), each from its own part of the input.
#include "fuzz_support.h"
#include "lumigauss/model/lighting_mlp.h"
#include "lumigauss/model/run_files.h"
#include "lumigauss/model/sky_residual.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    const std::string mlp = scratch_path("seed.lgmlp"), sky = scratch_path("seed.lgsky"),
                      appearance = scratch_path("seed_appearance.json");
    save_lighting_mlp(mlp, LightingMlp(3, 9));
    save_sky_residuals(sky, SkyResiduals(3));
    save_appearance(appearance, {"a.png", "b.png", "c.png"});
    return {join_parts({read_file(mlp), read_file(sky), read_file(appearance)})};
}

void parse(Bytes input) {
    const std::vector<std::string> parts = split_parts(input, 3);
    const std::string mlp = scratch_path("input.lgmlp"), sky = scratch_path("input.lgsky"),
                      appearance = scratch_path("appearance.json");
    write_file(mlp, parts[0]);
    write_file(sky, parts[1]);
    write_file(appearance, parts[2]);
    refuse_cleanly([&] { (void)load_lighting_mlp(mlp); });
    refuse_cleanly([&] { (void)load_sky_residuals(sky); });
    refuse_cleanly([&] { (void)load_appearance(appearance); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(lighting_files, seeds, parse)

}  // namespace lumigauss::fuzz
