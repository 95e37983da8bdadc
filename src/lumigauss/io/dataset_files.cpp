// File lookups shared by the layout readers: which files are images, and images indexed by stem.
#include <algorithm>
#include <cctype>
#include <filesystem>

#include "lumigauss/io/dataset_detail.h"

namespace lumigauss::dataset_detail {

namespace fs = std::filesystem;

bool has_image_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* e : {".png", ".jpg", ".jpeg", ".exr", ".hdr", ".bmp", ".tga"})
        if (ext == e) return true;
    return false;
}

std::map<std::string, std::string> index_images_by_stem(const std::string& dir) {
    std::map<std::string, std::string> index;
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return index;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (!entry.is_regular_file() || !has_image_extension(entry.path().string())) continue;
        const fs::path rel = entry.path().lexically_relative(dir);
        const std::string key = (rel.parent_path() / rel.stem()).generic_string();
        // Several files with one stem (b.png, b.jpg): keep the first by name, whatever the listing order.
        const auto [it, inserted] = index.emplace(key, entry.path().string());
        if (!inserted && entry.path().string() < it->second) it->second = entry.path().string();
    }
    return index;
}

}  // namespace lumigauss::dataset_detail
