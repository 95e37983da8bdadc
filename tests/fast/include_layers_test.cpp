// The library's folders form layers, and a file includes only its own layer or lower ones (DESIGN.md):
// this test reads every #include "lumigauss/..." under src/lumigauss and fails on one that points up, on
// folders of one layer that include each other both ways, and on a folder the order below does not list.
// The layer order is written here and nowhere else.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Lowest first. A folder may include its own layer's folders and every lower layer's.
const std::vector<std::vector<std::string>> kLayers = {
    {"util", "math"},       // no project dependencies beyond each other
    {"io"},                 // files, images, datasets, image metrics
    {"shading", "render"},  // SH lighting; the rasterizer and its backends (render/cpu, cuda)
    {"model", "cameras"},   // the finished relightable model; camera paths and frames
    {"train", "synth"},     // optimisation; the synthetic scene generator
    {"eval", "relight", "export", "viewer"}  // what users run on a model
};

int layer_of(const std::string& folder) {
    for (std::size_t i = 0; i < kLayers.size(); ++i)
        for (const std::string& f : kLayers[i])
            if (f == folder) return int(i);
    return -1;
}

struct Include {
    std::string file, from, to;  // file, its top folder, the included file's top folder
};

std::vector<Include> project_includes() {
    const fs::path root = fs::path(LUMIGAUSS_SOURCE_DIR) / "src" / "lumigauss";
    const std::regex include_line(R"re(^\s*#\s*include\s*"lumigauss/([a-z_0-9]+)/)re");
    std::vector<Include> out;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        if (ext != ".h" && ext != ".cpp" && ext != ".cu" && ext != ".cuh") continue;
        const std::string folder = fs::relative(entry.path(), root).begin()->string();
        std::ifstream in(entry.path());
        std::string line;
        std::smatch m;
        while (std::getline(in, line))
            if (std::regex_search(line, m, include_line))
                out.push_back({fs::relative(entry.path(), root).string(), folder, m[1].str()});
    }
    return out;
}

TEST(IncludeLayers, TheSourceTreeIsFound) {
    EXPECT_GT(project_includes().size(), 300u) << "no includes read from " << LUMIGAUSS_SOURCE_DIR;
}

TEST(IncludeLayers, EveryFolderHasALayer) {
    const fs::path root = fs::path(LUMIGAUSS_SOURCE_DIR) / "src" / "lumigauss";
    for (const auto& entry : fs::directory_iterator(root)) {
        if (!entry.is_directory()) continue;
        EXPECT_GE(layer_of(entry.path().filename().string()), 0)
            << "src/lumigauss/" << entry.path().filename().string() << " is in no layer: add it to kLayers";
    }
}

TEST(IncludeLayers, NoIncludePointsUp) {
    for (const Include& inc : project_includes()) {
        const int from = layer_of(inc.from), to = layer_of(inc.to);
        EXPECT_LE(to, from) << inc.file << " (layer " << from << ") includes lumigauss/" << inc.to
                            << "/ (layer " << to << ")";
    }
}

TEST(IncludeLayers, FoldersOfOneLayerDoNotIncludeEachOtherBothWays) {
    std::map<std::string, std::set<std::string>> edges;
    std::map<std::pair<std::string, std::string>, std::string> example;
    for (const Include& inc : project_includes())
        if (inc.from != inc.to) {
            edges[inc.from].insert(inc.to);
            example.emplace(std::pair{inc.from, inc.to}, inc.file);
        }
    for (const auto& [from, tos] : edges)
        for (const std::string& to : tos)
            if (from < to && edges[to].count(from))
                ADD_FAILURE() << from << "/ and " << to << "/ include each other: " << example[{from, to}]
                              << " and " << example[{to, from}];
}

// A backend's own headers are render/'s business: nothing outside render/ includes render/cpu or
// render/cuda.
TEST(IncludeLayers, OnlyRenderNamesABackend) {
    const fs::path root = fs::path(LUMIGAUSS_SOURCE_DIR);
    const std::regex backend_include(R"re(^\s*#\s*include\s*"lumigauss/render/(cpu|cuda)/)re");
    for (const char* dir : {"src/lumigauss", "apps"}) {
        for (const auto& entry : fs::recursive_directory_iterator(root / dir)) {
            if (!entry.is_regular_file()) continue;
            const std::string rel = fs::relative(entry.path(), root).string();
            if (rel.rfind("src/lumigauss/render/", 0) == 0) continue;
            std::ifstream in(entry.path());
            std::string line;
            while (std::getline(in, line))
                EXPECT_FALSE(std::regex_search(line, backend_include)) << rel << ": " << line;
        }
    }
}

}  // namespace
