#pragma once
// Environment SH as text: 9 lines "R G B" of radiance coefficients L_lm in the basis order of sh.h
// (the format of data/*/env/*_sh.txt and of the official LumiGauss --envmaps files).
//
// A light fitted to a photo (`lumigauss fit-light`) may carry that photo's sky residual too: 25 more lines
// "#sky R G B", the degree-4 SH (sh_degree4.h) the run draws the photo's sky with beyond the light's own
// (model/sky_residual.h). They are comments to every reader of the 9 lines (numpy's loadtxt too), so such a
// file stays an ordinary SH file; read_sh_text_light returns them.
#include <optional>
#include <string>

#include "lumigauss/shading/sh.h"
#include "lumigauss/shading/sh_degree4.h"

namespace lumigauss {

// Reads 9 coefficient lines of three numbers each (separated by spaces, tabs or commas). Blank lines and
// '#' comments (to the end of a line) are skipped. Throws Error naming the file (and line) on a missing
// file, a non-numeric or non-finite value, a line without exactly three numbers, or a count other than 9.
ShCoeffs<double> read_sh_text(const std::string& path);

struct ShTextLight {
    ShCoeffs<double> sh;
    std::optional<Sh4Coeffs<float>> sky_residual;  // the "#sky" lines, when the file has them
};

// read_sh_text plus the "#sky" lines: none, or exactly 25 of three finite numbers each (an Error naming the
// file and line otherwise: a cut block would draw a wrong sky without a word).
ShTextLight read_sh_text_light(const std::string& path);

// Writes 9 lines "R G B" with %.9g (float-exact, double to ~1e-9 relative), then, when given, the 25 "#sky"
// lines of a sky residual, atomically (temp + rename). Throws Error naming the file on I/O failure.
void write_sh_text(const std::string& path, const ShCoeffs<double>& sh,
                   const Sh4Coeffs<float>* sky_residual = nullptr);

}  // namespace lumigauss
