// The relightable PLY of a run (model/relightable_ply.h: model.ply, bare-PLY render/export/view).
#include "lumigauss/model/relightable_ply.h"
#include "fuzz_support.h"
#include "sample_files.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    const std::string path = scratch_path("seed_relightable.ply");
    save_relightable_ply(path, sample_surfel_model());
    return {read_file(path)};
}

void parse(Bytes input) {
    const std::string path = scratch_path("input_relightable.ply");
    write_file(path, input);
    refuse_cleanly([&] { (void)load_relightable_ply(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(relightable_ply, seeds, parse)

}  // namespace lumigauss::fuzz
