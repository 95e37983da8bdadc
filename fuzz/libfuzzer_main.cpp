// The libFuzzer entry points (clang -fsanitize=fuzzer; scripts/fuzz.sh). LUMIGAUSS_FUZZ_WRITE_SEEDS=DIR
// writes the target's seeds into DIR and exits: the script's starting corpus.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "fuzz_support.h"

namespace {

// The executable links exactly one file of targets/.
const lumigauss::fuzz::FuzzTarget& fuzz_target() {
    return lumigauss::fuzz::registered_targets().at(0);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    using namespace lumigauss::fuzz;
    if (const char* dir = std::getenv("LUMIGAUSS_FUZZ_WRITE_SEEDS")) {
        std::filesystem::create_directories(dir);
        const std::vector<std::string> seeds = fuzz_target().seeds();
        for (std::size_t i = 0; i < seeds.size(); ++i)
            write_file((std::filesystem::path(dir) / ("seed_" + std::to_string(i))).string(), seeds[i]);
        std::printf("%s: wrote %zu seeds to %s\n", fuzz_target().name, seeds.size(), dir);
        std::exit(0);
    }
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz_target().parse({data, size});
    return 0;
}
