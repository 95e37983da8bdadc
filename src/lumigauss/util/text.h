#pragma once
// Small string and path helpers shared by the readers and the tools.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lumigauss {

// `s` without leading and trailing spaces, tabs, carriage returns and newlines.
inline std::string_view trim_whitespace(std::string_view s) {
    constexpr std::string_view kSpace = " \t\r\n";
    const std::size_t first = s.find_first_not_of(kSpace);
    if (first == std::string_view::npos) return {};
    return s.substr(first, s.find_last_not_of(kSpace) - first + 1);
}

// A file name or path without its extension, folders kept ("a/b.png" -> "a/b").
inline std::string without_extension(const std::string& path) {
    return std::filesystem::path(path).replace_extension().generic_string();
}

// Wall time since `t0`, in seconds.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Exactly `count` finite numbers separated by commas ("1,2.5, -3"; spaces around each allowed), or nothing.
inline std::optional<std::vector<double>> parse_number_list(const std::string& text, std::size_t count) {
    std::vector<double> values;
    std::size_t at = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t end = i + 1 < count ? text.find(',', at) : text.size();
        if (end == std::string::npos) return std::nullopt;
        const std::string part(trim_whitespace(std::string_view(text).substr(at, end - at)));
        char* stop = nullptr;
        const double v = std::strtod(part.c_str(), &stop);
        if (part.empty() || stop != part.c_str() + part.size() || !std::isfinite(v)) return std::nullopt;
        values.push_back(v);
        at = end + 1;
    }
    return values;
}

}  // namespace lumigauss
