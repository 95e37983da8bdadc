// A COLMAP text model (cameras.txt, images.txt, points3D.txt in one input; io/colmap.h).
#include "fuzz_support.h"
#include "lumigauss/io/colmap.h"
#include "sample_files.h"

namespace lumigauss::fuzz {
namespace {

const char* const kFiles[] = {"cameras.txt", "images.txt", "points3D.txt"};

std::vector<std::string> seeds() {
    const std::string dir = scratch_path("seed_text");
    write_colmap_text(dir, sample_colmap_model());
    std::vector<std::string> parts;
    for (const char* f : kFiles) parts.push_back(read_file(dir + "/" + f));
    return {join_parts(parts)};
}

void parse(Bytes input) {
    const std::string dir = scratch_path("text");
    make_folder(dir);
    const std::vector<std::string> parts = split_parts(input, 3);
    for (int i = 0; i < 3; ++i) write_file(dir + "/" + kFiles[i], parts[std::size_t(i)]);
    refuse_cleanly([&] { (void)read_colmap_text(dir); });
}

}  // namespace

const FuzzTarget& fuzz_target() {
    static const FuzzTarget target{"colmap_text", seeds, parse};
    return target;
}

}  // namespace lumigauss::fuzz
