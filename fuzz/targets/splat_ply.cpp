// A 2DGS surfel PLY (model/splat_ply.h: `render --ply`).
#include "lumigauss/model/splat_ply.h"
#include "fuzz_support.h"
#include "lumigauss/io/ply.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    PlyVertexTable table;
    table.count = 2;
    for (const char* name : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                             "rot_0", "rot_1", "rot_2", "rot_3"})
        table.add(name, {0.25f, -0.5f});
    table.add("f_rest_0", {0.1f, 0.2f});  // a partial higher degree: the reader must decide what it means
    const std::string path = scratch_path("seed_2dgs.ply");
    write_ply_vertices(path, table);
    return {read_file(path)};
}

void parse(Bytes input) {
    const std::string path = scratch_path("input_2dgs.ply");
    write_file(path, input);
    refuse_cleanly([&] { (void)load_2dgs_ply(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(splat_ply, seeds, parse)

}  // namespace lumigauss::fuzz
