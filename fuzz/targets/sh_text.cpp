// An SH lighting file: 9 lines "R G B", with a fitted photo's 25 "#sky" rows or without (shading/sh_text.h:
// render --light, eval's true lights).
#include "lumigauss/shading/sh_text.h"
#include "fuzz_support.h"

namespace lumigauss::fuzz {
namespace {

std::vector<std::string> seeds() {
    ShCoeffs<double> sh;
    for (int j = 0; j < kShCount; ++j) sh.c[j] = {0.1 * j, -0.2 * j, 1.5};
    const std::string path = scratch_path("seed_sh.txt");
    write_sh_text(path, sh);
    const std::string light = read_file(path);
    Sh4Coeffs<float> sky{};
    for (int k = 0; k < kSh4Count; ++k) sky.c[k] = {0.01f * float(k), -0.5f, 2.0f};
    write_sh_text(path, sh, &sky);
    return {light, read_file(path),
            "# comment\n1 1 1\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n"};
}

void parse(Bytes input) {
    const std::string path = scratch_path("input_sh.txt");
    write_file(path, input);
    refuse_cleanly([&] { (void)read_sh_text_light(path); });
}

}  // namespace

LUMIGAUSS_FUZZ_TARGET(sh_text, seeds, parse)

}  // namespace lumigauss::fuzz
