// The generic PLY reader (io/ply.h): ASCII and both binary byte orders, other elements and list properties.
#include "fuzz_support.h"
#include "lumigauss/io/ply.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    PlyVertexTable table;
    table.count = 3;
    table.add("x", {0, 1, 2});
    table.add("y", {0.5f, -1, 3});
    table.add("opacity", {0.1f, 0.9f, -2});
    const std::string binary = scratch_path("seed.ply");
    write_ply_vertices(binary, table);
    const std::string ascii =
        "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 2\nproperty float x\nproperty uchar "
        "red\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0.5 255\n-1 3\n3 0 1 1\n";
    const std::string big_endian = std::string(
        "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty double x\nproperty short "
        "s\nend_header\n"
        "\x3f\xf0\0\0\0\0\0\0\x01\x02",
        86);
    return {read_file(binary), ascii, big_endian};
}

void parse(Bytes input) {
    const std::string path = scratch_path("input.ply");
    write_file(path, input);
    refuse_cleanly([&] { (void)read_ply_vertices(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(ply_vertices, seeds, parse)

}  // namespace lumigauss::fuzz
