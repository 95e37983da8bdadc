#include "lumigauss/shading/sh_text.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// Larger coefficients are refused: 1e308 is finite, but the radiance summed from it is not (an all-Inf
// preview EXR that the tool then refused to read), and squares of anything past ~1e19 overflow the single
// precision of panoramas and renders. No light is within many orders of magnitude of this.
constexpr double kMaxShCoefficient = 1e15;

// One token as a finite double within +-kMaxShCoefficient, or an Error naming file and line.
double parse_number(const std::string& token, const std::string& path, int line_no) {
    // from_chars rejects a leading '+', which other writers may emit.
    const char* first = token.data() + (token.front() == '+' ? 1 : 0);
    const char* last = token.data() + token.size();
    double value = 0;
    const auto [end, ec] = std::from_chars(first, last, value);
    const std::string where = "line " + std::to_string(line_no) + ": ";
    if (ec != std::errc{} || end != last) fail_in_file(path, where + "'" + token + "' is not a number");
    if (!std::isfinite(value)) fail_in_file(path, where + "'" + token + "' is not a finite number");
    if (std::abs(value) > kMaxShCoefficient)
        fail_in_file(path, where + "'" + token + "' is out of range (|value| <= 1e15)");
    return value;
}

constexpr const char* kSkyPrefix = "#sky";

// A line of the sky residual block: the word "#sky" first (after blanks); "#sky01 ..." is a comment.
bool is_sky_line(const std::string& line) {
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line.compare(first, 4, kSkyPrefix) != 0) return false;
    return first + 4 == line.size() || line[first + 4] == ' ' || line[first + 4] == '\t';
}

// The whitespace/comma separated tokens of a line, comments removed.
std::vector<std::string> tokens_of(std::string line) {
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    for (char& ch : line)
        if (ch == ',') ch = ' ';
    std::istringstream in(line);
    std::vector<std::string> tokens;
    for (std::string t; in >> t;) tokens.push_back(t);
    return tokens;
}

}  // namespace

ShTextLight read_sh_text_light(const std::string& path) {
    std::ifstream in(path);
    if (!in) fail_in_file(path, "cannot open the SH file (expected 9 lines 'R G B')");
    ShTextLight light;
    Sh4Coeffs<float> sky{};
    int rows = 0, sky_rows = 0, line_no = 0;
    for (std::string line; std::getline(in, line);) {
        ++line_no;
        const std::string where = "line " + std::to_string(line_no) + ": ";
        if (is_sky_line(line)) {
            const std::vector<std::string> tokens = tokens_of(line.substr(line.find(kSkyPrefix) + 4));
            if (sky_rows == kSh4Count)
                fail_in_file(path, where + "more than 25 '#sky' lines (the sky residual is a degree-4 SH)");
            if (tokens.size() != 3)
                fail_in_file(path, where + "expected '#sky R G B', found " + std::to_string(tokens.size()) +
                                       " numbers");
            for (int c = 0; c < 3; ++c) sky.c[sky_rows][c] = float(parse_number(tokens[c], path, line_no));
            ++sky_rows;
            continue;
        }
        const std::vector<std::string> tokens = tokens_of(line);
        if (tokens.empty()) continue;
        if (rows == kShCount) fail_in_file(path, where + "more than 9 coefficient lines (degree-2 SH has 9)");
        if (tokens.size() != 3)
            fail_in_file(path, where + "expected 3 numbers 'R G B', found " + std::to_string(tokens.size()));
        for (int c = 0; c < 3; ++c) light.sh.c[rows][c] = parse_number(tokens[c], path, line_no);
        ++rows;
    }
    if (in.bad()) fail_in_file(path, "read error");
    if (rows != kShCount)
        fail_in_file(path, "expected 9 coefficient lines 'R G B', found " + std::to_string(rows));
    if (sky_rows != 0 && sky_rows != kSh4Count)
        fail_in_file(path, "expected 25 '#sky' lines of the sky residual, found " + std::to_string(sky_rows));
    if (sky_rows == kSh4Count) light.sky_residual = sky;
    return light;
}

ShCoeffs<double> read_sh_text(const std::string& path) {
    return read_sh_text_light(path).sh;
}

void write_sh_text(const std::string& path, const ShCoeffs<double>& sh,
                   const Sh4Coeffs<float>* sky_residual) {
    std::string text;
    char buf[128];
    for (const Vec3d& v : sh.c) {
        std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", v.x, v.y, v.z);
        text += buf;
    }
    if (sky_residual != nullptr) {
        text += "# the photo's sky residual: degree-4 SH, 25 rows R G B (drawn by lumigauss render)\n";
        for (const Vec3f& v : sky_residual->c) {
            std::snprintf(buf, sizeof buf, "%s %.9g %.9g %.9g\n", kSkyPrefix, double(v.x), double(v.y),
                          double(v.z));
            text += buf;
        }
    }
    write_file_atomically(path, text);
}

}  // namespace lumigauss
