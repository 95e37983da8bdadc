// COLMAP binary models: little-endian, uint64 record counts, then fixed-layout records (see colmap.h).
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/colmap.h"
#include "lumigauss/io/colmap_detail.h"
#include "lumigauss/util/error.h"

namespace lumigauss {

// The files are little-endian and records are copied with memcpy.
static_assert(std::endian::native == std::endian::little, "COLMAP binary I/O assumes a little-endian host");

namespace {

using colmap_detail::join;

// A bounds-checked cursor over a whole file that knows which record it is in, for error messages.
class Reader {
  public:
    explicit Reader(std::string path)
        : path_(std::move(path)), data_(colmap_detail::read_whole_file(path_)) {}

    template <typename T>
    T get() {
        need(sizeof(T));
        T value;
        std::memcpy(&value, data_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return value;
    }

    // Passes over `bytes` that the caller does not need (checked like a read).
    void skip(std::uint64_t bytes) {
        need(bytes);
        pos_ += std::size_t(bytes);
    }

    std::string get_cstring() {
        const std::size_t end = data_.find('\0', pos_);
        if (end == std::string::npos) fail("truncated: the file ends inside the image name");
        std::string s = data_.substr(pos_, end - pos_);
        pos_ = end + 1;
        return s;
    }

    // A length inside a record, of elements of `element_bytes` each: one the rest of the file cannot hold is
    // caught before anything is allocated for it.
    std::uint64_t length(std::uint64_t element_bytes, const char* what) {
        const auto n = get<std::uint64_t>();
        if (n > remaining() / element_bytes)
            fail(std::string("truncated: the ") + what + " length " + std::to_string(n) +
                 " runs past the end of the file");
        return n;
    }

    // The record count at the start of the file. Each record takes at least `min_bytes`, so a count the file
    // cannot hold is caught before anything is allocated for it.
    std::uint64_t count(std::uint64_t min_bytes, const char* kind) {
        kind_ = kind;
        const auto n = get<std::uint64_t>();
        if (n > remaining() / min_bytes)
            fail("truncated: promises " + std::to_string(n) + " " + kind +
                 " records but the file can hold at most " + std::to_string(remaining() / min_bytes));
        count_ = n;
        return n;
    }

    void begin_record(std::uint64_t index) {
        in_header_ = false;
        record_ = index;
    }

    void expect_end() const {
        if (pos_ != data_.size())
            fail_in_file(path_,
                         std::to_string(data_.size() - pos_) + " unexpected bytes after the last record");
    }

    std::string where() const {
        if (in_header_) return "record count";
        return "record " + std::to_string(record_ + 1) + " of " + std::to_string(count_) + " (" + kind_ + ")";
    }

    [[noreturn]] void fail(const std::string& what) const { fail_in_file(path_, where() + ": " + what); }

  private:
    std::uint64_t remaining() const { return data_.size() - pos_; }
    void need(std::uint64_t bytes) const {
        if (remaining() < bytes) fail("truncated: the file ends inside this record");
    }

    std::string path_;
    std::string data_;
    std::size_t pos_ = 0;
    const char* kind_ = "";
    bool in_header_ = true;
    std::uint64_t count_ = 0, record_ = 0;
};

// A camera's width or height: a uint64 on disk. Cast to int unchecked, 2^32 + 640 would read as 640.
int image_side(Reader& in, const char* which) {
    const auto side = in.get<std::uint64_t>();
    constexpr std::uint64_t kMaxSide = 1 << 20;
    if (side == 0 || side > kMaxSide)
        in.fail("image " + std::string(which) + " " + std::to_string(side) + " is not between 1 and " +
                std::to_string(kMaxSide));
    return int(side);
}

std::map<int, ColmapCamera> read_cameras(const std::string& path) {
    Reader in(path);
    std::map<int, ColmapCamera> cameras;
    const std::uint64_t n = in.count(4 + 4 + 8 + 8, "camera");
    for (std::uint64_t i = 0; i < n; ++i) {
        in.begin_record(i);
        ColmapCamera cam;
        cam.id = in.get<std::int32_t>();
        const int model_id = in.get<std::int32_t>();
        cam.model = colmap_model_name(model_id);
        if (cam.model.empty()) in.fail("unknown camera model id " + std::to_string(model_id));
        cam.width = image_side(in, "width");
        cam.height = image_side(in, "height");
        cam.params.resize(std::size_t(colmap_model_num_params(cam.model)));
        for (double& p : cam.params) p = in.get<double>();
        colmap_detail::check_camera(cam, path, in.where());
        if (!cameras.emplace(cam.id, cam).second)
            in.fail("camera_id " + std::to_string(cam.id) + " repeated");
    }
    in.expect_end();
    return cameras;
}

std::vector<ColmapImage> read_images(const std::string& path, const std::map<int, ColmapCamera>& cameras,
                                     ColmapContent content) {
    Reader in(path);
    std::vector<ColmapImage> images;
    const std::uint64_t n = in.count(4 + 7 * 8 + 4 + 1 + 8, "image");
    for (std::uint64_t i = 0; i < n; ++i) {
        in.begin_record(i);
        ColmapImage im;
        im.id = int(in.get<std::uint32_t>());
        for (int k = 0; k < 4; ++k) im.qvec[k] = in.get<double>();
        for (int k = 0; k < 3; ++k) im.tvec[k] = in.get<double>();
        im.camera_id = int(in.get<std::uint32_t>());
        im.name = in.get_cstring();
        // Each observation is x, y (double) and point3D_id (int64, -1 for none); the ids become point indices
        // once points3D is read.
        const std::uint64_t observations = in.length(24, "POINTS2D");
        if (content == ColmapContent::PosesAndPoints)
            in.skip(24 * observations);
        else
            im.observations.resize(observations);
        for (ColmapObservation& o : im.observations) {
            o.xy.x = in.get<double>();
            o.xy.y = in.get<double>();
            o.point_index = in.get<std::int64_t>();
        }
        colmap_detail::check_image(im, cameras, path, in.where());
        images.push_back(std::move(im));
    }
    in.expect_end();
    return images;
}

// Appends the points to `model`; returns their POINT3D_IDs in file order.
std::vector<std::uint64_t> read_points(const std::string& path, ColmapModel& model, ColmapContent content) {
    Reader in(path);
    const std::uint64_t n = in.count(8 + 3 * 8 + 3 + 8 + 8, "point");
    const bool everything = content == ColmapContent::Everything;
    std::vector<std::uint64_t> ids;
    ids.reserve(n);
    model.point_xyz.reserve(n);
    model.point_rgb.reserve(n);
    if (everything) model.point_error.reserve(n), model.point_tracks.reserve(n);
    for (std::uint64_t i = 0; i < n; ++i) {
        in.begin_record(i);
        ids.push_back(in.get<std::uint64_t>());
        Vec3f xyz, rgb;
        for (int k = 0; k < 3; ++k) xyz[k] = float(in.get<double>());
        for (int k = 0; k < 3; ++k) rgb[k] = float(in.get<std::uint8_t>()) / 255.0f;
        const double error = in.get<double>();
        const std::uint64_t track_length = in.length(8, "TRACK");
        if (everything) {
            model.point_error.push_back(error);
            std::vector<ColmapTrackElement>& track = model.point_tracks.emplace_back(track_length);
            for (ColmapTrackElement& e : track) {  // (image_id, point2D_idx) as two uint32
                e.image_id = int(in.get<std::uint32_t>());
                e.observation = int(in.get<std::uint32_t>());
            }
        } else {
            in.skip(8 * track_length);
        }
        if (!std::isfinite(xyz.x) || !std::isfinite(xyz.y) || !std::isfinite(xyz.z))
            in.fail("point position has a NaN or Inf value");
        model.point_xyz.push_back(xyz);
        model.point_rgb.push_back(rgb);
    }
    in.expect_end();
    return ids;
}

template <typename T>
void put(std::string& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

}  // namespace

ColmapModel read_colmap_binary(const std::string& dir, ColmapContent content) {
    ColmapModel model;
    model.cameras = read_cameras(join(dir, "cameras.bin"));
    model.images = read_images(join(dir, "images.bin"), model.cameras, content);
    colmap_detail::index_observed_points(model, read_points(join(dir, "points3D.bin"), model, content));
    return model;
}

void write_colmap_binary(const std::string& dir, const ColmapModel& model) {
    colmap_detail::check_optional_arrays(model, dir);
    std::filesystem::create_directories(dir);
    std::string cams, ims, pts;
    put<std::uint64_t>(cams, model.cameras.size());
    for (const auto& [id, c] : model.cameras) {
        const int model_id = colmap_model_id(c.model);
        if (model_id < 0) fail_in_file(join(dir, "cameras.bin"), "unknown camera model '" + c.model + "'");
        put<std::int32_t>(cams, id);
        put<std::int32_t>(cams, model_id);
        put<std::uint64_t>(cams, std::uint64_t(c.width));
        put<std::uint64_t>(cams, std::uint64_t(c.height));
        for (double p : c.params) put<double>(cams, p);
    }
    put<std::uint64_t>(ims, model.images.size());
    for (const ColmapImage& im : model.images) {
        put<std::uint32_t>(ims, std::uint32_t(im.id));
        for (int k = 0; k < 4; ++k) put<double>(ims, im.qvec[k]);
        for (int k = 0; k < 3; ++k) put<double>(ims, im.tvec[k]);
        put<std::uint32_t>(ims, std::uint32_t(im.camera_id));
        ims.append(im.name.c_str(), im.name.size() + 1);
        put<std::uint64_t>(ims, im.observations.size());
        for (const ColmapObservation& o : im.observations) {
            put<double>(ims, o.xy.x);
            put<double>(ims, o.xy.y);
            put<std::int64_t>(ims, o.point_index < 0 ? -1 : o.point_index + 1);
        }
    }
    put<std::uint64_t>(pts, model.point_xyz.size());
    for (std::size_t i = 0; i < model.point_xyz.size(); ++i) {
        put<std::uint64_t>(pts, i + 1);
        for (int k = 0; k < 3; ++k) put<double>(pts, model.point_xyz[i][k]);
        const Vec3f rgb = i < model.point_rgb.size() ? model.point_rgb[i] : Vec3f{};
        for (int k = 0; k < 3; ++k) put<std::uint8_t>(pts, colmap_detail::colour_byte(rgb[k]));
        put<double>(pts, colmap_detail::point_error(model, i));
        const std::vector<ColmapTrackElement>& track = colmap_detail::point_track(model, i);
        put<std::uint64_t>(pts, track.size());
        for (const ColmapTrackElement& e : track) {
            put<std::uint32_t>(pts, std::uint32_t(e.image_id));
            put<std::uint32_t>(pts, std::uint32_t(e.observation));
        }
    }
    write_file_atomically(join(dir, "cameras.bin"), cams);
    write_file_atomically(join(dir, "images.bin"), ims);
    write_file_atomically(join(dir, "points3D.bin"), pts);
}

}  // namespace lumigauss
