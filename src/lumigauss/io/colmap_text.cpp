// COLMAP text models: cameras.txt, images.txt (two lines per image), points3D.txt; '#' starts a comment line.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/colmap.h"
#include "lumigauss/io/colmap_detail.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

namespace {

using colmap_detail::join;

// Walks a file's lines, counting them (1-based) for error messages.
class Lines {
  public:
    explicit Lines(std::string path) : path_(std::move(path)), text_(colmap_detail::read_whole_file(path_)) {}

    // The next line (without '\n' or '\r'), or false at the end of the file.
    bool next(std::string_view& line) {
        if (pos_ >= text_.size()) return false;
        std::size_t end = text_.find('\n', pos_);
        if (end == std::string::npos) end = text_.size();
        line = std::string_view(text_).substr(pos_, end - pos_);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos_ = end + 1;
        ++number_;
        return true;
    }

    // The next line that is neither empty nor a comment. Notes the count of a "# Number of ...: N" comment,
    // which COLMAP writes at the top of each file.
    bool next_record(std::string_view& line) {
        while (next(line)) {
            const std::size_t first = line.find_first_not_of(" \t");
            if (first != std::string_view::npos && line[first] != '#') return true;
            note_declared_count(line);
        }
        return false;
    }

    // A file cut short (a copy interrupted, a disk full) still parses, one record short of what COLMAP wrote.
    void check_declared_count(std::size_t records, const char* what) const {
        if (declared_ && *declared_ != records)
            fail_in_file(path_, "holds " + std::to_string(records) + " " + what +
                                    " but its header declares " + std::to_string(*declared_) +
                                    " (cut short, or edited without the header)");
    }

    [[noreturn]] void fail(const std::string& what) const {
        fail_in_file(path_, "line " + std::to_string(number_) + ": " + what);
    }

    std::string where() const { return "line " + std::to_string(number_); }

  private:
    void note_declared_count(std::string_view line) {
        constexpr std::string_view kPrefix = "# Number of ";
        if (declared_ || !line.starts_with(kPrefix)) return;
        const std::size_t colon = line.find(':');
        if (colon == std::string_view::npos) return;
        const std::size_t start = line.find_first_not_of(' ', colon + 1);
        if (start == std::string_view::npos) return;
        std::size_t n = 0;
        const auto [end, ec] = std::from_chars(line.data() + start, line.data() + line.size(), n);
        if (ec == std::errc()) declared_ = n;
    }

    std::string path_;
    std::string text_;
    std::size_t pos_ = 0;
    int number_ = 0;
    std::optional<std::size_t> declared_;
};

bool is_blank(char c) {
    return c == ' ' || c == '\t';
}

// The blank-separated tokens of a line. A plain loop: string_view::find_first_of with a set of two took
// about 70 instructions per byte, half of reading a 7 MB images.txt.
// At most `limit` of them when given (the rest of the line is not looked at).
std::vector<std::string_view> split(std::string_view line, std::size_t limit = std::size_t(-1)) {
    std::vector<std::string_view> tokens;
    const char* p = line.data();
    const char* const end = p + line.size();
    while (tokens.size() < limit) {
        while (p != end && is_blank(*p)) ++p;
        if (p == end) break;
        const char* const start = p;
        while (p != end && !is_blank(*p)) ++p;
        tokens.emplace_back(start, std::size_t(p - start));
    }
    return tokens;
}

template <typename T>
T parse(std::string_view token, const Lines& lines, const char* what) {
    T value{};
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size())
        lines.fail(std::string("expected ") + what + ", found '" + std::string(token) + "'");
    return value;
}

std::map<int, ColmapCamera> read_cameras(const std::string& path) {
    Lines lines(path);
    std::map<int, ColmapCamera> cameras;
    std::string_view line;
    while (lines.next_record(line)) {
        const auto t = split(line);
        if (t.size() < 4) lines.fail("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
        ColmapCamera cam;
        cam.id = parse<int>(t[0], lines, "an integer CAMERA_ID");
        cam.model = std::string(t[1]);
        cam.width = parse<int>(t[2], lines, "an integer WIDTH");
        cam.height = parse<int>(t[3], lines, "an integer HEIGHT");
        for (std::size_t i = 4; i < t.size(); ++i)
            cam.params.push_back(parse<double>(t[i], lines, "a number"));
        colmap_detail::check_camera(cam, path, lines.where());
        if (!cameras.emplace(cam.id, cam).second)
            lines.fail("camera_id " + std::to_string(cam.id) + " repeated");
    }
    lines.check_declared_count(cameras.size(), "cameras");
    return cameras;
}

ColmapImage parse_image_line(std::string_view line, const Lines& lines) {
    const auto t = split(line);
    if (t.size() < 10) lines.fail("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    ColmapImage im;
    im.id = parse<int>(t[0], lines, "an integer IMAGE_ID");
    for (int k = 0; k < 4; ++k) im.qvec[k] = parse<double>(t[1 + k], lines, "a number");
    for (int k = 0; k < 3; ++k) im.tvec[k] = parse<double>(t[5 + k], lines, "a number");
    im.camera_id = parse<int>(t[8], lines, "an integer CAMERA_ID");
    // The name is the rest of the line, so that names with spaces survive.
    std::string_view name = line.substr(std::size_t(t[9].data() - line.data()));
    name = name.substr(0, name.find_last_not_of(" \t") + 1);
    im.name = std::string(name);
    return im;
}

// The observations line: triples X Y POINT3D_ID (-1 for a keypoint without a point). The ids are turned into
// point indices once points3D is read.
std::vector<ColmapObservation> parse_observations_line(std::string_view line, const Lines& lines) {
    const auto t = split(line);
    if (t.size() % 3 != 0) lines.fail("POINTS2D must be triples X Y POINT3D_ID");
    std::vector<ColmapObservation> observations(t.size() / 3);
    for (std::size_t i = 0; i < observations.size(); ++i) {
        ColmapObservation& o = observations[i];
        o.xy.x = parse<double>(t[3 * i], lines, "a number X");
        o.xy.y = parse<double>(t[3 * i + 1], lines, "a number Y");
        o.point_index = parse<std::int64_t>(t[3 * i + 2], lines, "an integer POINT3D_ID");
    }
    return observations;
}

std::vector<ColmapImage> read_images(const std::string& path, const std::map<int, ColmapCamera>& cameras,
                                     ColmapContent content) {
    Lines lines(path);
    std::vector<ColmapImage> images;
    std::string_view line;
    while (lines.next_record(line)) {
        images.push_back(parse_image_line(line, lines));
        colmap_detail::check_image(images.back(), cameras, path, lines.where());
        // The observations line always follows (empty when the image has none); at the end it may be absent.
        if (lines.next(line) && content == ColmapContent::Everything)
            images.back().observations = parse_observations_line(line, lines);
    }
    lines.check_declared_count(images.size(), "images");
    return images;
}

// Appends the points to `model`; returns their POINT3D_IDs in file order.
std::vector<std::uint64_t> read_points(const std::string& path, ColmapModel& model, ColmapContent content) {
    Lines lines(path);
    const bool everything = content == ColmapContent::Everything;
    std::vector<std::uint64_t> ids;
    std::string_view line;
    while (lines.next_record(line)) {
        const auto t = everything ? split(line) : split(line, 8);
        if (t.size() < 8 || (everything && (t.size() - 8) % 2 != 0))
            lines.fail("expected POINT3D_ID X Y Z R G B ERROR TRACK[] (pairs IMAGE_ID POINT2D_IDX)");
        ids.push_back(parse<std::uint64_t>(t[0], lines, "an integer POINT3D_ID"));
        Vec3f xyz, rgb;
        for (int k = 0; k < 3; ++k) xyz[k] = float(parse<double>(t[1 + k], lines, "a number"));
        for (int k = 0; k < 3; ++k) {
            const int c = parse<int>(t[4 + k], lines, "an integer colour 0..255");
            if (c < 0 || c > 255) lines.fail("colour " + std::to_string(c) + " is outside 0..255");
            rgb[k] = float(c) / 255.0f;
        }
        if (!std::isfinite(xyz.x) || !std::isfinite(xyz.y) || !std::isfinite(xyz.z))
            lines.fail("point position has a NaN or Inf value");
        model.point_xyz.push_back(xyz);
        model.point_rgb.push_back(rgb);
        if (!everything) continue;
        model.point_error.push_back(parse<double>(t[7], lines, "a number ERROR"));
        std::vector<ColmapTrackElement>& track = model.point_tracks.emplace_back((t.size() - 8) / 2);
        for (std::size_t k = 0; k < track.size(); ++k) {
            track[k].image_id = parse<int>(t[8 + 2 * k], lines, "an integer IMAGE_ID");
            track[k].observation = parse<int>(t[9 + 2 * k], lines, "an integer POINT2D_IDX");
        }
    }
    lines.check_declared_count(model.point_xyz.size(), "points");
    return ids;
}

// Text output: strings as they are, numbers in the shortest form that reads back to the same value.
void put(std::string& out, std::string_view text) {
    out.append(text);
}

template <typename T>
requires std::is_arithmetic_v<T>
void put(std::string& out, T value) {
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, value);
    out.append(buf, res.ptr);
}

template <typename... Parts>
void append(std::string& out, const Parts&... parts) {
    (put(out, parts), ...);
}

std::string cameras_text(const ColmapModel& model) {
    std::string out =
        "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
    append(out, "# Number of cameras: ", model.cameras.size(), "\n");
    for (const auto& [id, c] : model.cameras) {
        append(out, id, " ", c.model, " ", c.width, " ", c.height);
        for (double p : c.params) append(out, " ", p);
        put(out, "\n");
    }
    return out;
}

// Two lines per image: the pose, then the 2D observations (empty when the model has none).
std::string images_text(const ColmapModel& model) {
    std::string out =
        "# Image list with two lines of data per image:\n"
        "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n#   POINTS2D[] as (X, Y, POINT3D_ID)\n";
    append(out, "# Number of images: ", model.images.size(), "\n");
    for (const ColmapImage& im : model.images) {
        put(out, im.id);
        for (int k = 0; k < 4; ++k) append(out, " ", im.qvec[k]);
        for (int k = 0; k < 3; ++k) append(out, " ", im.tvec[k]);
        append(out, " ", im.camera_id, " ", im.name, "\n");
        for (std::size_t i = 0; i < im.observations.size(); ++i) {
            const ColmapObservation& o = im.observations[i];
            if (i > 0) put(out, " ");
            append(out, o.xy.x, " ", o.xy.y, " ", o.point_index < 0 ? std::int64_t(-1) : o.point_index + 1);
        }
        put(out, "\n");
    }
    return out;
}

// Points numbered from 1, with their reprojection errors and tracks (0 and empty when the model has none).
std::string points_text(const ColmapModel& model) {
    std::string out =
        "# 3D point list with one line of data per point:\n"
        "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
    append(out, "# Number of points: ", model.point_xyz.size(), "\n");
    for (std::size_t i = 0; i < model.point_xyz.size(); ++i) {
        put(out, i + 1);
        for (int k = 0; k < 3; ++k) append(out, " ", model.point_xyz[i][k]);
        const Vec3f rgb = i < model.point_rgb.size() ? model.point_rgb[i] : Vec3f{};
        for (int k = 0; k < 3; ++k) append(out, " ", int(colmap_detail::colour_byte(rgb[k])));
        append(out, " ", colmap_detail::point_error(model, i));
        for (const ColmapTrackElement& e : colmap_detail::point_track(model, i))
            append(out, " ", e.image_id, " ", e.observation);
        put(out, "\n");
    }
    return out;
}

}  // namespace

ColmapModel read_colmap_text(const std::string& dir, ColmapContent content) {
    ColmapModel model;
    model.cameras = read_cameras(join(dir, "cameras.txt"));
    model.images = read_images(join(dir, "images.txt"), model.cameras, content);
    colmap_detail::index_observed_points(model, read_points(join(dir, "points3D.txt"), model, content));
    return model;
}

void write_colmap_text(const std::string& dir, const ColmapModel& model) {
    colmap_detail::check_optional_arrays(model, dir);
    std::filesystem::create_directories(dir);
    write_file_atomically(join(dir, "cameras.txt"), cameras_text(model));
    write_file_atomically(join(dir, "images.txt"), images_text(model));
    write_file_atomically(join(dir, "points3D.txt"), points_text(model));
}

}  // namespace lumigauss
