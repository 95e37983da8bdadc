// A COLMAP binary model (cameras.bin, images.bin, points3D.bin in one input; io/colmap.h).
#include "fuzz_support.h"
#include "lumigauss/io/colmap.h"
#include "sample_files.h"

namespace lumigauss::fuzz {
namespace {

const char* const kFiles[] = {"cameras.bin", "images.bin", "points3D.bin"};

std::vector<std::string> seeds() {
    const std::string dir = scratch_path("seed_binary");
    write_colmap_binary(dir, sample_colmap_model());
    std::vector<std::string> parts;
    for (const char* f : kFiles) parts.push_back(read_file(dir + "/" + f));
    return {join_parts(parts)};
}

void parse(Bytes input) {
    const std::string dir = scratch_path("binary");
    make_folder(dir);
    const std::vector<std::string> parts = split_parts(input, 3);
    for (int i = 0; i < 3; ++i) write_file(dir + "/" + kFiles[i], parts[std::size_t(i)]);
    refuse_cleanly([&] { (void)read_colmap_binary(dir); });
}

}  // namespace

const FuzzTarget& fuzz_target() {
    static const FuzzTarget target{"colmap_binary", seeds, parse};
    return target;
}

}  // namespace lumigauss::fuzz
