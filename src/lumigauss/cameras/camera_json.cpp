#include "lumigauss/cameras/camera_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/text_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

using Json = nlohmann::json;

double number_field(const Json& e, const char* key, const std::string& path, const std::string& where) {
    if (!e.contains(key) || !e[key].is_number())
        fail_in_file(path, where + ": needs a number \"" + key + "\"");
    const double v = e[key].get<double>();
    if (!std::isfinite(v)) fail_in_file(path, where + ": \"" + key + "\" is not finite");
    return v;
}

int size_field(const Json& e, const char* key, const std::string& path, const std::string& where) {
    if (!e.contains(key) || !e[key].is_number_integer() || e[key].get<long long>() <= 0 ||
        e[key].get<long long>() > 1000000)
        fail_in_file(path, where + ": needs a positive integer \"" + key + "\"");
    return int(e[key].get<long long>());
}

std::vector<double> numbers(const Json& j) {
    std::vector<double> out;
    for (const Json& v : j) {
        if (!v.is_number()) return {};
        out.push_back(v.get<double>());
    }
    return out;
}

Mat3d rotation_field(const Json& e, const std::string& path, const std::string& where) {
    const std::string bad = where + ": \"R\" must be a 3x3 rotation (3 rows of 3 numbers, or 9 numbers)";
    if (!e.contains("R") || !e["R"].is_array()) fail_in_file(path, bad);
    std::vector<double> v;
    const Json& r = e["R"];
    if (r.size() == 3) {
        for (const Json& row : r) {
            if (!row.is_array() || row.size() != 3) fail_in_file(path, bad);
            for (double x : numbers(row)) v.push_back(x);
        }
    } else {
        v = numbers(r);
    }
    if (v.size() != 9) fail_in_file(path, bad);
    Mat3d m;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(v[std::size_t(3 * i + k)])) fail_in_file(path, bad);
            m(i, k) = v[std::size_t(3 * i + k)];
        }
    const Mat3d should_be_identity = m * transpose(m);
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            if (std::abs(should_be_identity(i, k) - (i == k ? 1.0 : 0.0)) > 1e-3)
                fail_in_file(path, where + ": \"R\" is not orthonormal (R R^T != I)");
    if (dot(cross(m.row(0), m.row(1)), m.row(2)) < 0)
        fail_in_file(path, where + ": \"R\" is a reflection (determinant -1), not a rotation");
    return m;
}

bool safe_name(const std::string& name) {
    if (name.empty() || name[0] == '/' || name.back() == '/') return false;
    std::size_t start = 0;
    while (start <= name.size()) {
        const std::size_t end = std::min(name.find('/', start), name.size());
        const std::string part = name.substr(start, end - start);
        if (part.empty() || part == "." || part == "..") return false;
        start = end + 1;
    }
    return name.find('\\') == std::string::npos && name.find('\0') == std::string::npos;
}

}  // namespace

std::vector<NamedCamera> read_camera_json(const std::string& path) {
    const Json doc = Json::parse(read_text_file(path), nullptr, false);
    if (doc.is_discarded()) fail_in_file(path, "not valid JSON");
    const Json* list = &doc;
    if (doc.is_object() && doc.contains("cameras")) list = &doc["cameras"];
    if (!list->is_array())
        fail_in_file(path, "expected a JSON list of cameras (or an object with a \"cameras\" list)");
    if (list->empty()) fail_in_file(path, "the camera list is empty");
    std::vector<NamedCamera> cameras;
    std::set<std::string> names;
    for (std::size_t i = 0; i < list->size(); ++i) {
        const Json& e = (*list)[i];
        const std::string where = "cameras[" + std::to_string(i) + "]";
        if (!e.is_object()) fail_in_file(path, where + ": expected an object");
        NamedCamera nc;
        if (e.contains("name")) {
            if (!e["name"].is_string()) fail_in_file(path, where + ": \"name\" must be a string");
            nc.name = e["name"].get<std::string>();
        } else {
            char buf[32];
            std::snprintf(buf, sizeof buf, "cam_%03zu", i);
            nc.name = buf;
        }
        if (!safe_name(nc.name))
            fail_in_file(path, where + ": name '" + nc.name +
                                   "' must be a relative path without '.', '..' or empty parts");
        if (!names.insert(nc.name).second)
            fail_in_file(path, where + ": name '" + nc.name + "' is used twice");
        Camera& c = nc.camera;
        c.width = size_field(e, "width", path, where);
        c.height = size_field(e, "height", path, where);
        // Every render allocates its frame buffers for this size: 10^6 x 10^6 was accepted.
        if (static_cast<long long>(c.width) * c.height > kMaxImagePixels)
            fail_in_file(path, where + ": " + std::to_string(c.width) + " x " + std::to_string(c.height) +
                                   " pixels is over the limit of " + std::to_string(kMaxImagePixels) +
                                   " (16384 x 8192)");
        c.fx = number_field(e, "fx", path, where);
        c.fy = number_field(e, "fy", path, where);
        c.cx = number_field(e, "cx", path, where);
        c.cy = number_field(e, "cy", path, where);
        if (!(c.fx > 0) || !(c.fy > 0)) fail_in_file(path, where + ": fx and fy must be positive");
        c.rotation = rotation_field(e, path, where);
        if (!e.contains("t") || !e["t"].is_array() || e["t"].size() != 3 || numbers(e["t"]).size() != 3)
            fail_in_file(path, where + ": needs \"t\", a list of 3 numbers");
        const std::vector<double> t = numbers(e["t"]);
        for (double v : t)
            if (!std::isfinite(v)) fail_in_file(path, where + ": \"t\" is not finite");
        c.translation = {t[0], t[1], t[2]};
        cameras.push_back(std::move(nc));
    }
    return cameras;
}

void write_camera_json(const std::string& path, const std::vector<NamedCamera>& cameras) {
    Json list = Json::array();
    for (const NamedCamera& nc : cameras) {
        const Camera& c = nc.camera;
        Json r = Json::array();
        for (int i = 0; i < 3; ++i) r.push_back({c.rotation(i, 0), c.rotation(i, 1), c.rotation(i, 2)});
        list.push_back({{"name", nc.name},
                        {"width", c.width},
                        {"height", c.height},
                        {"fx", c.fx},
                        {"fy", c.fy},
                        {"cx", c.cx},
                        {"cy", c.cy},
                        {"R", r},
                        {"t", {c.translation.x, c.translation.y, c.translation.z}}});
    }
    write_file_atomically(path, list.dump(2) + "\n");
}

}  // namespace lumigauss
