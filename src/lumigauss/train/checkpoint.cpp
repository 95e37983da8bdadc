#include "lumigauss/train/checkpoint.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <span>

#include "lumigauss/io/atomic_file.h"
#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// Version 3 ends with a checksum of everything before it; version 2 added the sky residuals after the
// lighting model. Versions 1 and 2 (no checksum) still load.
constexpr char kMagic[9] = "LGCKPT03";
constexpr char kMagicV2[9] = "LGCKPT02";
constexpr char kMagicV1[9] = "LGCKPT01";
constexpr char kEndMarker[9] = "LGCKEND1";

// FNV-1a, 64 bit: catches a flipped byte or an edited value anywhere in the file (it is not a defence against
// someone forging a checkpoint, which would have to be run to matter).
struct Checksum {
    std::uint64_t state = 0xcbf29ce484222325ULL;
    void add(const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < bytes; ++i) state = (state ^ p[i]) * 0x100000001b3ULL;
    }
};

class Writer {
  public:
    explicit Writer(std::ofstream& out) : out_(out) {}
    void raw(const void* data, std::size_t bytes) {
        checksum_.add(data, bytes);
        out_.write(static_cast<const char*>(data), std::streamsize(bytes));
    }
    std::uint64_t checksum() const { return checksum_.state; }
    template <typename T>
    void value(T v) {
        raw(&v, sizeof(T));
    }
    void string(const std::string& s) {
        value<std::uint64_t>(s.size());
        raw(s.data(), s.size());
    }
    void floats(std::span<const float> v) {
        value<std::uint64_t>(v.size());
        raw(v.data(), v.size() * sizeof(float));
    }
    void adam(const AdamGroup& g) {
        value<std::int64_t>(g.step_count());
        floats(g.exp_avg());
        floats(g.exp_avg_sq());
    }

  private:
    std::ofstream& out_;
    Checksum checksum_;
};

struct SavedAdam {
    std::int64_t step = 0;
    std::vector<float> m, v;
};

void restore_adam(AdamGroup& g, SavedAdam a, const std::string& path, const std::string& what) {
    if (a.m.size() != g.size() || a.v.size() != g.size())
        fail_in_file(path, "corrupt checkpoint (optimizer state of " + what + " has the wrong size)");
    g.restore(a.step, std::move(a.m), std::move(a.v));
}

class Reader {
  public:
    Reader(std::ifstream& in, const std::string& path) : in_(in), path_(path) {
        in_.seekg(0, std::ios::end);
        remaining_ = std::uint64_t(std::max<std::streamoff>(in_.tellg(), 0));
        in_.seekg(0, std::ios::beg);
    }
    void raw(void* data, std::size_t bytes, const char* what) {
        in_.read(static_cast<char*>(data), std::streamsize(bytes));
        if (!in_) fail_in_file(path_, std::string("truncated checkpoint (while reading ") + what + ")");
        checksum_.add(data, bytes);
        remaining_ -= bytes;
    }
    template <typename T>
    T value(const char* what) {
        T v;
        raw(&v, sizeof(T), what);
        return v;
    }
    // A count of elements of `element_bytes` each, checked against the bytes left in the file before anything
    // is allocated for it.
    std::uint64_t length(const char* what, std::uint64_t element_bytes = 1) {
        const auto n = value<std::uint64_t>(what);
        if (n > remaining_ / std::max<std::uint64_t>(element_bytes, 1))
            fail_in_file(path_, std::string("corrupt checkpoint (") + what + " declares " +
                                    std::to_string(n) + " elements, more than the " +
                                    std::to_string(remaining_) + " bytes left in the file)");
        return n;
    }
    std::string string(const char* what) {
        std::string s(length(what), '\0');
        raw(s.data(), s.size(), what);
        return s;
    }
    std::vector<float> floats(const char* what) {
        std::vector<float> v(length(what, sizeof(float)));
        raw(v.data(), v.size() * sizeof(float), what);
        return v;
    }
    // An optimizer state as Writer::adam wrote it; put back with restore_adam once its group exists.
    SavedAdam adam(const char* what) {
        SavedAdam a;
        a.step = value<std::int64_t>(what);
        a.m = floats(what);
        a.v = floats(what);
        return a;
    }
    std::uint64_t checksum() const { return checksum_.state; }

  private:
    std::ifstream& in_;
    const std::string& path_;
    std::uint64_t remaining_ = 0;
    Checksum checksum_;
};

// Header fields a damaged or edited file could hold and training would otherwise run on.
void check_header(const TrainState& s, const std::string& path) {
    try {
        validate_train_config(s.config);
    } catch (const Error& e) {
        fail_in_file(path, std::string("corrupt checkpoint (embedded config: ") + e.what() + ")");
    }
    if (s.iteration < 0 || s.iteration > s.config.iterations)
        fail_in_file(path, "corrupt checkpoint (iteration " + std::to_string(s.iteration) + " outside 0.." +
                               std::to_string(s.config.iterations) + ")");
    if (!std::isfinite(s.scene_extent) || s.scene_extent <= 0)
        fail_in_file(path, "corrupt checkpoint (scene extent " + std::to_string(s.scene_extent) + ")");
}

}  // namespace

void save_checkpoint(const std::string& path, const TrainState& s) {
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) fail_in_file(tmp, "cannot open for writing");
        Writer w(out);
        w.raw(kMagic, 8);
        w.string(train_config_to_json(s.config));
        w.value<std::int64_t>(s.iteration);
        w.value<double>(s.scene_extent);
        w.value<std::uint64_t>(s.image_names.size());
        for (const auto& name : s.image_names) w.string(name);

        w.value<std::uint64_t>(s.model.size());
        for (int p = 0; p < kModelParamCount; ++p) {
            w.floats(s.model.param(ModelParam(p)));
            w.adam(s.model.adam(ModelParam(p)));
        }
        w.floats(s.model.grad_accum());
        w.floats(s.model.grad_count());
        w.floats(s.model.max_radii());

        w.value<std::int32_t>(s.lighting.num_images());
        for (int g = 0; g < kMlpGroupCount; ++g) {
            w.floats(s.lighting.param(MlpGroup(g)));
            w.adam(s.lighting_adam[std::size_t(g)]);
        }
        w.floats(s.sky_residuals.params());
        w.value<std::uint64_t>(s.sky_residual_adam.size());
        for (const AdamGroup& g : s.sky_residual_adam) w.adam(g);
        w.raw(kEndMarker, 8);
        const std::uint64_t checksum = w.checksum();
        out.write(reinterpret_cast<const char*>(&checksum), sizeof checksum);
        out.flush();
        if (!out) fail_in_file(tmp, "write failed (disk full?)");
    });
}

TrainState load_checkpoint(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail_in_file(path, "cannot open the checkpoint");
    Reader r(in, path);
    char magic[8];
    r.raw(magic, 8, "magic");
    const bool version1 = std::memcmp(magic, kMagicV1, 8) == 0;
    const bool version2 = std::memcmp(magic, kMagicV2, 8) == 0;
    if (!version1 && !version2 && std::memcmp(magic, kMagic, 8) != 0)
        fail_in_file(path, "not a LumiGauss checkpoint (wrong magic)");

    TrainState s;
    s.config = TrainConfig{};
    apply_train_config_json(s.config, r.string("config"), path + " (embedded config)");
    s.iteration = r.value<std::int64_t>("iteration");
    s.scene_extent = r.value<double>("scene extent");
    check_header(s, path);
    const auto names = r.length("photo count", sizeof(std::uint64_t));
    for (std::uint64_t i = 0; i < names; ++i) s.image_names.push_back(r.string("photo name"));

    const auto surfels = r.length("surfel count", sizeof(float));
    std::vector<std::vector<float>> raw(kModelParamCount);
    std::vector<SavedAdam> adam(kModelParamCount);
    for (int p = 0; p < kModelParamCount; ++p) {
        raw[std::size_t(p)] = r.floats("surfel parameters");
        if (raw[std::size_t(p)].size() != surfels * std::size_t(GaussianModel::width(ModelParam(p))))
            fail_in_file(path, std::string("corrupt checkpoint (") + GaussianModel::name(ModelParam(p)) +
                                   " has the wrong size)");
        adam[std::size_t(p)] = r.adam("surfel optimizer");
    }
    s.model = GaussianModel::from_raw(std::move(raw), s.scene_extent, model_learning_rates(s.config));
    for (int p = 0; p < kModelParamCount; ++p)
        restore_adam(s.model.adam(ModelParam(p)), std::move(adam[std::size_t(p)]), path,
                     GaussianModel::name(ModelParam(p)));
    auto accum = r.floats("densification statistics");
    auto count = r.floats("densification statistics");
    auto radii = r.floats("densification statistics");
    if (accum.size() != surfels || count.size() != surfels || radii.size() != surfels)
        fail_in_file(path, "corrupt checkpoint (densification statistics have the wrong size)");
    s.model.restore_densification_stats(std::move(accum), std::move(count), std::move(radii));

    const auto images = r.value<std::int32_t>("lighting model");
    if (images <= 0 || std::uint64_t(images) != names)
        fail_in_file(path, "corrupt checkpoint (lighting model and photo list disagree)");
    s.lighting = LightingMlp::zeros(images);
    s.lighting_adam = lighting_optimizer(s.config, images);
    for (int g = 0; g < kMlpGroupCount; ++g) {
        auto values = r.floats("lighting model");
        if (values.size() != s.lighting.param(MlpGroup(g)).size())
            fail_in_file(path, std::string("corrupt checkpoint (lighting ") + mlp_group_name(MlpGroup(g)) +
                                   " has the wrong size)");
        s.lighting.param(MlpGroup(g)) = std::move(values);
        restore_adam(s.lighting_adam[std::size_t(g)], r.adam(mlp_group_name(MlpGroup(g))), path,
                     mlp_group_name(MlpGroup(g)));
    }
    if (!version1) {
        std::vector<float> residuals = r.floats("sky residuals");
        const auto groups = r.length("sky residual optimizers", sizeof(std::int64_t));
        if (!residuals.empty() || groups != 0) {
            if (residuals.size() != std::size_t(images) * SkyResiduals::kRowWidth ||
                groups != std::uint64_t(images))
                fail_in_file(path, "corrupt checkpoint (sky residuals do not match the photo count)");
            s.sky_residuals = SkyResiduals(images);
            s.sky_residuals.params() = std::move(residuals);
            s.sky_residual_adam = sky_residual_optimizer(s.config, images);
            for (AdamGroup& g : s.sky_residual_adam)
                restore_adam(g, r.adam("sky residual optimizer"), path, "sky residuals");
        }
    }
    char end[8];
    r.raw(end, 8, "end marker");
    if (std::memcmp(end, kEndMarker, 8) != 0) fail_in_file(path, "corrupt checkpoint (no end marker)");
    if (!version1 && !version2) {
        const std::uint64_t computed = r.checksum();
        if (r.value<std::uint64_t>("checksum") != computed)
            fail_in_file(path, "corrupt checkpoint (checksum mismatch: the file was damaged or edited)");
    }
    for (const ModelParam p : kAllModelParams)
        for (const float v : s.model.param(p))
            if (!std::isfinite(v))
                fail_in_file(path,
                             std::string("corrupt checkpoint (a non-finite ") + GaussianModel::name(p) + ")");
    return s;
}

}  // namespace lumigauss
