#include "lumigauss/viewer/viewer_assets.h"

#include <utility>

namespace lumigauss::view {

const EmbeddedAsset* find_viewer_asset(std::string_view name) {
    for (const EmbeddedAsset& a : viewer_assets())
        if (a.name == name) return &a;
    return nullptr;
}

std::string content_type_for(std::string_view name) {
    static const std::pair<std::string_view, std::string_view> kTypes[] = {
        {".html", "text/html; charset=utf-8"},
        {".js", "text/javascript; charset=utf-8"},  // module scripts and workers need a JavaScript type
        {".mjs", "text/javascript; charset=utf-8"},
        {".css", "text/css; charset=utf-8"},
        {".json", "application/json"},
        {".svg", "image/svg+xml"},
        {".png", "image/png"},
        {".txt", "text/plain; charset=utf-8"},
        {".bin", "application/octet-stream"},
    };
    for (const auto& [ext, type] : kTypes)
        if (name.size() > ext.size() && name.ends_with(ext)) return std::string(type);
    return "application/octet-stream";
}

}  // namespace lumigauss::view
