// A split file: "filename;split" lines (io/split_file.h: split.csv of a scene).
#include "lumigauss/io/split_file.h"
#include "fuzz_support.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    return {"filename;split\na.png;train\nb.png;test\nc.jpg;validation\n", "x.png;train\r\ny.png;test"};
}

void parse(Bytes input) {
    const std::string path = scratch_path("split.csv");
    write_file(path, input);
    refuse_cleanly([&] { (void)read_split_file(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(split_file, seeds, parse)

}  // namespace lumigauss::fuzz
