// A COLMAP binary model (cameras.bin, images.bin, points3D.bin in one input; io/colmap.h).
#include "sample_files.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    return {colmap_seed(".bin")};
}

void parse(Bytes input) {
    parse_colmap_parts(input, ".bin");
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(colmap_binary, seeds, parse)

}  // namespace lumigauss::fuzz
