// A training config (train/train_config.h: --config FILE and a run's config.json), then its validation.
#include "lumigauss/train/train_config.h"
#include "fuzz_support.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    return {train_config_to_json(train_preset("fast")), "{\"iterations\": 100, \"lambda_shadow\": 5}",
            "{\"preset\": \"paper\", \"sky_background\": true, \"mask_mode\": \"object\"}"};
}

void parse(Bytes input) {
    const std::string_view text(reinterpret_cast<const char*>(input.data()), input.size());
    refuse_cleanly([&] {
        TrainConfig config = train_preset("default");
        apply_train_config_json(config, text, "fuzz.json");
        validate_train_config(config);
    });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(train_config, seeds, parse)

}  // namespace lumigauss::fuzz
