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

const FuzzTarget& fuzz_target() {
    static const FuzzTarget target{"colmap_binary", seeds, parse};
    return target;
}

}  // namespace lumigauss::fuzz
