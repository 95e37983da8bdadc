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

LUMIGAUSS_FUZZ_TARGET(colmap_text, seeds, parse)

}  // namespace lumigauss::fuzz
