#pragma once
// Shared helpers of the Synth* tests: the tiny preset generated into a unique temporary folder (removed
// afterwards), and small readers for what the project's loaders do not keep (COLMAP tracks, meta.json).

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "lumigauss/synth/synth.h"
#include "support/temp_dir.h"

namespace lumigauss::synth_test {

namespace fs = std::filesystem;

using lumigauss::testing::TempDir;

inline synth::SynthOptions tiny_options(const std::string& output_dir) {
    synth::SynthOptions o = synth::synth_preset("tiny");
    o.output_dir = output_dir;
    return o;
}

inline nlohmann::json read_json(const std::string& path) {
    std::ifstream f(path);
    return nlohmann::json::parse(f);
}

inline std::string read_bytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

// A COLMAP text model with tracks read independently of io/colmap.h, to check what its writer wrote.
struct TrackPoint {
    int id = 0;
    double x = 0, y = 0, z = 0, error = 0;
    int r = 0, g = 0, b = 0;
    std::vector<std::pair<int, int>> track;  // (image id, point2D index)
};
struct Point2D {
    double x = 0, y = 0;
    int point_id = -1;
};
struct TrackModel {
    std::map<int, std::string> image_names;
    std::map<int, std::vector<Point2D>> observations;  // per image id
    std::vector<TrackPoint> points;
};

inline TrackModel read_tracks(const std::string& sparse_dir) {
    TrackModel m;
    std::ifstream images(sparse_dir + "/images.txt");
    std::string line;
    bool header_line = true;
    int current = 0;
    while (std::getline(images, line)) {
        if (!line.empty() && line[0] == '#') continue;
        std::istringstream s(line);
        if (header_line) {
            double q[7];
            int cam = 0;
            std::string name;
            s >> current;
            for (double& v : q) s >> v;
            s >> cam >> name;
            m.image_names[current] = name;
            m.observations[current];
        } else {
            Point2D p;
            while (s >> p.x >> p.y >> p.point_id) m.observations[current].push_back(p);
        }
        header_line = !header_line;
    }
    std::ifstream points(sparse_dir + "/points3D.txt");
    while (std::getline(points, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream s(line);
        TrackPoint p;
        s >> p.id >> p.x >> p.y >> p.z >> p.r >> p.g >> p.b >> p.error;
        int image = 0, idx = 0;
        while (s >> image >> idx) p.track.emplace_back(image, idx);
        m.points.push_back(p);
    }
    return m;
}

}  // namespace lumigauss::synth_test
