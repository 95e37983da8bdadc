// A run's log.jsonl as --resume cuts it back to the checkpoint (train/training_run.h: truncate_log).
#include "fuzz_support.h"
#include "lumigauss/train/training_run.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    return {
        "{\"iteration\":10,\"total\":0.5,\"psnr\":20.1}\n{\"iteration\":20,\"total\":0.4}\n"
        "{\"iteration\":30,\"densified\":{\"cloned\":3}}\n"};
}

void parse(Bytes input) {
    const std::string path = scratch_path("log.jsonl");
    write_file(path, input);
    refuse_cleanly([&] { truncate_log(path, 20); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(training_log, seeds, parse)

}  // namespace lumigauss::fuzz
