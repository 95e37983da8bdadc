#pragma once
// Environment SH as text: 9 lines "R G B" of radiance coefficients L_lm in the basis order of sh.h
// (the format of data/*/env/*_sh.txt and of the official LumiGauss --envmaps files).
#include <string>

#include "lumigauss/shading/sh.h"

namespace lumigauss {

// Reads 9 coefficient lines of three numbers each (separated by spaces, tabs or commas). Blank lines and
// '#' comments (to the end of a line) are skipped. Throws Error naming the file (and line) on a missing
// file, a non-numeric or non-finite value, a line without exactly three numbers, or a count other than 9.
ShCoeffs<double> read_sh_text(const std::string& path);

// Writes 9 lines "R G B" with %.9g (float-exact, double to ~1e-9 relative), atomically (temp + rename).
// Throws Error naming the file on I/O failure.
void write_sh_text(const std::string& path, const ShCoeffs<double>& sh);

}  // namespace lumigauss
