// A COLMAP text model (cameras.txt, images.txt, points3D.txt in one input; io/colmap.h).
#include "sample_files.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    return {colmap_seed(".txt")};
}

void parse(Bytes input) {
    parse_colmap_parts(input, ".txt");
}

}  // namespace

const FuzzTarget& fuzz_target() {
    static const FuzzTarget target{"colmap_text", seeds, parse};
    return target;
}

}  // namespace lumigauss::fuzz
