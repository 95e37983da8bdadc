#pragma once
// Small string and path helpers shared by the readers and the tools.
#include <chrono>
#include <filesystem>
#include <string>
#include <string_view>

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

}  // namespace lumigauss
