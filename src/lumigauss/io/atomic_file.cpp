#include "lumigauss/io/atomic_file.h"

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "lumigauss/util/error.h"

namespace lumigauss {

std::string temp_path_for(const std::string& path) {
    return path + ".tmp";
}

void write_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write) {
    const std::string tmp = temp_path_for(path);
    std::error_code ignored;
    try {
        write(tmp);
    } catch (...) {
        std::filesystem::remove(tmp, ignored);
        throw;
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ignored);
        fail_in_file(path, "cannot replace the file with its temporary copy " + tmp + ": " + ec.message());
    }
}

void write_file_atomically(const std::string& path, const std::string& content) {
    write_atomically(path, [&](const std::string& tmp) {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f) fail_in_file(path, "cannot open " + tmp + " for writing (does the folder exist?)");
        const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size();
        if (std::fclose(f) != 0 || !ok) fail_in_file(path, "write failed (disk full?)");
    });
}

}  // namespace lumigauss
