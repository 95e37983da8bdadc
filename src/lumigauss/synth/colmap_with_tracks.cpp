#include "lumigauss/synth/colmap_with_tracks.h"

#include <cstdio>
#include <string>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/math/quaternion.h"

namespace lumigauss::synth {

namespace {

template <typename... Args>
void appendf(std::string& out, const char* fmt, Args... args) {
    char buf[256];
    const int n = std::snprintf(buf, sizeof buf, fmt, args...);
    out.append(buf, std::size_t(n));
}

std::string cameras_txt(const std::vector<ColmapView>& views) {
    std::string s =
        "# Camera list with one line of data per camera:\n"
        "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
    appendf(s, "# Number of cameras: %d\n", int(views.size()));
    for (const ColmapView& v : views) {
        const Camera& c = v.camera;
        appendf(s, "%d PINHOLE %d %d %.9f %.9f %.9f %.9f\n", v.image_id, c.width, c.height, c.fx, c.fy, c.cx,
                c.cy);
    }
    return s;
}

// Per training view, its observations in point order: (x, y, point id). The index in this list is the
// POINT2D_IDX that the points' tracks refer to.
struct Point2D {
    double x, y;
    int point_id;
};

std::vector<std::vector<Point2D>> observations_per_view(const std::vector<SfmPoint>& points, int n_training,
                                                        std::vector<std::vector<int>>& track_indices) {
    std::vector<std::vector<Point2D>> per_view(static_cast<std::size_t>(n_training));
    track_indices.assign(points.size(), {});
    for (std::size_t p = 0; p < points.size(); ++p)
        for (const Observation& o : points[p].track) {
            auto& list = per_view[std::size_t(o.view)];
            track_indices[p].push_back(int(list.size()));
            list.push_back({o.x, o.y, int(p) + 1});
        }
    return per_view;
}

std::string images_txt(const std::vector<ColmapView>& views,
                       const std::vector<std::vector<Point2D>>& per_view) {
    std::size_t total = 0;
    for (const auto& l : per_view) total += l.size();
    std::string s =
        "# Image list with two lines of data per image:\n"
        "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
        "#   POINTS2D[] as (X, Y, POINT3D_ID)\n";
    appendf(s, "# Number of images: %d, mean observations per image: %.1f\n", int(views.size()),
            views.empty() ? 0.0 : double(total) / double(views.size()));
    for (const ColmapView& v : views) {
        const Vec4<double> q = quaternion_from_rotation(v.camera.rotation);
        const Vec3d t = v.camera.translation;
        appendf(s, "%d %.12f %.12f %.12f %.12f %.9f %.9f %.9f %d %s\n", v.image_id, q.x, q.y, q.z, q.w, t.x,
                t.y, t.z, v.image_id, v.name.c_str());
        if (v.training_index >= 0)
            for (const Point2D& o : per_view[std::size_t(v.training_index)]) {
                if (&o != per_view[std::size_t(v.training_index)].data()) s += ' ';
                appendf(s, "%.4f %.4f %d", o.x, o.y, o.point_id);
            }
        s += '\n';
    }
    return s;
}

std::string points3d_txt(const std::vector<ColmapView>& views, const std::vector<SfmPoint>& points,
                         const std::vector<std::vector<int>>& track_indices) {
    // Training index -> image id.
    std::vector<int> image_of(views.size(), 0);
    for (const ColmapView& v : views)
        if (v.training_index >= 0) image_of[std::size_t(v.training_index)] = v.image_id;
    std::string s =
        "# 3D point list with one line of data per point:\n"
        "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
    appendf(s, "# Number of points: %d\n", int(points.size()));
    for (std::size_t p = 0; p < points.size(); ++p) {
        const SfmPoint& pt = points[p];
        appendf(s, "%d %.6f %.6f %.6f %d %d %d %.4f", int(p) + 1, pt.position.x, pt.position.y, pt.position.z,
                int(pt.rgb[0]), int(pt.rgb[1]), int(pt.rgb[2]), pt.error);
        for (std::size_t k = 0; k < pt.track.size(); ++k)
            appendf(s, " %d %d", image_of[std::size_t(pt.track[k].view)], track_indices[p][k]);
        s += '\n';
    }
    return s;
}

}  // namespace

void write_colmap_with_tracks(const std::string& dir, const std::vector<ColmapView>& views,
                              const std::vector<SfmPoint>& points) {
    int n_training = 0;
    for (const ColmapView& v : views) n_training += v.training_index >= 0;
    std::vector<std::vector<int>> track_indices;
    const auto per_view = observations_per_view(points, n_training, track_indices);
    write_file_atomically(dir + "/cameras.txt", cameras_txt(views));
    write_file_atomically(dir + "/images.txt", images_txt(views, per_view));
    write_file_atomically(dir + "/points3D.txt", points3d_txt(views, points, track_indices));
}

}  // namespace lumigauss::synth
