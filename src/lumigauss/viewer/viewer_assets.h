#pragma once
// The viewer's web page (web/viewer/: index.html, the scripts, the sorting worker), embedded into the binary
// at build time by cmake/EmbedWebAssets.cmake, so that `lumigauss view` needs no files beside itself.
#include <span>
#include <string>
#include <string_view>

namespace lumigauss::view {

struct EmbeddedAsset {
    std::string_view name;   // path relative to web/viewer/, e.g. "index.html"
    std::string_view bytes;  // the file's content, unchanged
};

// Every embedded file, sorted by name. Defined in the generated source.
std::span<const EmbeddedAsset> viewer_assets();

// The asset called exactly `name`, or nullptr.
const EmbeddedAsset* find_viewer_asset(std::string_view name);

// The Content-Type for a file name, by its extension (html, js, mjs, css, json, svg, png, txt, bin);
// "application/octet-stream" for anything else. Text types say charset=utf-8.
std::string content_type_for(std::string_view name);

}  // namespace lumigauss::view
