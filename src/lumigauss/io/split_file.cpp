#include "lumigauss/io/split_file.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <optional>

#include "lumigauss/util/error.h"
#include "lumigauss/util/text.h"

namespace lumigauss {

namespace {

std::optional<Split> parse_split(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (s == "train") return Split::Train;
    if (s == "test") return Split::Test;
    if (s == "val" || s == "validation") return Split::Validation;
    return std::nullopt;
}

char separator_of(const std::string& line) {
    if (line.find(';') != std::string::npos) return ';';
    if (line.find('\t') != std::string::npos) return '\t';
    return ',';
}

}  // namespace

std::map<std::string, Split> read_split_file(const std::string& path) {
    std::ifstream in(path);
    if (!in) fail_in_file(path, "cannot open the split file");
    std::map<std::string, Split> splits;
    std::string line;
    bool first_record = true;
    for (int number = 1; std::getline(in, line); ++number) {
        if (trim_whitespace(line).empty()) continue;
        const std::string where = "line " + std::to_string(number) + ": ";
        const auto sep = line.find(separator_of(line));
        if (sep == std::string::npos) fail_in_file(path, where + "expected `filename;split`");
        const std::string name(trim_whitespace(line.substr(0, sep))),
            value(trim_whitespace(line.substr(sep + 1)));
        const auto split = parse_split(value);
        const bool header = first_record && !split;
        first_record = false;
        if (header) continue;
        if (!split)
            fail_in_file(path, where + "unknown split '" + value + "' (use train, test, val or validation)");
        if (name.empty()) fail_in_file(path, where + "empty file name");
        if (!splits.emplace(name, *split).second) fail_in_file(path, where + name + " is listed twice");
    }
    return splits;
}

}  // namespace lumigauss
