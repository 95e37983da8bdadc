#include "lumigauss/relight/video.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace lumigauss {

std::string find_on_path(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path || name.empty()) return "";
    const std::string dirs = path;
    std::size_t start = 0;
    while (start <= dirs.size()) {
        const std::size_t end = std::min(dirs.find(':', start), dirs.size());
        const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
        const std::filesystem::path candidate = std::filesystem::path(dir) / name;
        std::error_code ec;
        if (std::filesystem::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0)
            return candidate.string();
        start = end + 1;
    }
    return "";
}

std::string shell_quote(const std::string& s) {
    std::string out = "'";
    for (char c : s) {
        if (c == '\'')
            out += "'\\''";
        else
            out += c;
    }
    return out + "'";
}

std::string escape_percent(const std::string& s) {
    std::string out;
    for (char c : s) {
        out += c;
        if (c == '%') out += '%';
    }
    return out;
}

std::string ffmpeg_command(const std::string& ffmpeg, const std::string& pattern, const std::string& output,
                           int fps) {
    return shell_quote(ffmpeg) + " -nostdin -y -loglevel error -framerate " + std::to_string(fps) + " -i " +
           shell_quote(pattern) + " -vf " + shell_quote("pad=ceil(iw/2)*2:ceil(ih/2)*2") +
           " -pix_fmt yuv420p -f mp4 " + shell_quote(output);
}

bool encode_video(const std::string& ffmpeg, const std::string& pattern, const std::string& output, int fps) {
    const std::string tmp = output + ".tmp.mp4";
    const std::string command = ffmpeg_command(ffmpeg, pattern, tmp, fps) + " < /dev/null";
    const int status = std::system(command.c_str());
    std::error_code ec;
    if (status != 0) {
        std::filesystem::remove(tmp, ec);
        return false;
    }
    std::filesystem::rename(tmp, output, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        return false;
    }
    return true;
}

}  // namespace lumigauss
