// Damaged checkpoints (train/checkpoint.h): a flipped byte, an impossible length or an out-of-range header
// field is refused with a message naming the file, before training could run on it or memory is spent on it.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "fast/io_test_util.h"
#include "lumigauss/train/checkpoint.h"
#include "lumigauss/train/trainer.h"

namespace lumigauss {
namespace {

using test::expect_error;
using test::TempDir;

TrainState small_state() {
    TrainState s;
    s.config = train_preset("fast");
    s.iteration = 7;
    s.scene_extent = 3.5;
    s.image_names = {"a.png", "b.png"};
    s.model = GaussianModel::from_points({{0, 0, 0}, {1, 0, 0}, {0, 1, 1}}, {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                         s.scene_extent, 5);
    s.lighting = LightingMlp(2, 5);
    s.lighting_adam = lighting_optimizer(s.config, 2);
    return s;
}

std::string saved_bytes(const TempDir& tmp, const TrainState& s) {
    save_checkpoint(tmp / "good.lgck", s);
    return test::read_text(tmp / "good.lgck");
}

TEST(Checkpoint, RoundTripKeepsTheState) {
    TempDir tmp;
    const TrainState s = small_state();
    save_checkpoint(tmp / "a.lgck", s);
    const TrainState back = load_checkpoint(tmp / "a.lgck");
    EXPECT_EQ(back.iteration, 7);
    EXPECT_EQ(back.image_names, s.image_names);
    for (const ModelParam p : kAllModelParams) EXPECT_EQ(back.model.param(p), s.model.param(p));
}

// 8 of 8 single-byte flips in the payload were trained on with exit 0 before the checksum.
TEST(Checkpoint, AnyFlippedByteIsRefused) {
    TempDir tmp;
    const std::string bytes = saved_bytes(tmp, small_state());
    for (std::size_t at = 8; at < bytes.size(); at += bytes.size() / 97) {
        std::string damaged = bytes;
        damaged[at] = char(damaged[at] ^ 0x10);
        test::write_text(tmp / "damaged.lgck", damaged);
        EXPECT_THROW((void)load_checkpoint(tmp / "damaged.lgck"), Error) << "byte " << at;
    }
    std::string last = bytes;
    last[bytes.size() / 2] = char(last[bytes.size() / 2] ^ 1);
    test::write_text(tmp / "damaged.lgck", last);
    expect_error([&] { (void)load_checkpoint(tmp / "damaged.lgck"); },
                 {"damaged.lgck", "corrupt checkpoint"});
}

// A length field of 2^36 floats passed the old sanity bound and allocated 256 GB (std::bad_alloc).
TEST(Checkpoint, ALengthLargerThanTheFileIsRefusedBeforeAllocating) {
    TempDir tmp;
    const std::string bytes = saved_bytes(tmp, small_state());
    const std::uint64_t config_length = [&] {
        std::uint64_t n;
        std::memcpy(&n, bytes.data() + 8, 8);
        return n;
    }();
    std::string damaged = bytes;
    const std::uint64_t huge = std::uint64_t(1) << 36;
    std::memcpy(damaged.data() + 8, &huge, 8);
    test::write_text(tmp / "long.lgck", damaged);
    expect_error([&] { (void)load_checkpoint(tmp / "long.lgck"); }, {"long.lgck", "bytes left in the file"});
    EXPECT_LT(config_length, bytes.size());
}

// A negative iteration ran on until "lighting MLP: image index 48 out of range", naming neither file nor
// field; 1e6 in a 200-iteration run and a NaN scene extent trained silently.
TEST(Checkpoint, OutOfRangeHeaderFieldsAreNamed) {
    TempDir tmp;
    for (const std::int64_t iteration : {std::int64_t(-3), std::int64_t(1000000)}) {
        TrainState s = small_state();
        s.iteration = iteration;
        save_checkpoint(tmp / "it.lgck", s);
        expect_error([&] { (void)load_checkpoint(tmp / "it.lgck"); }, {"it.lgck", "iteration"});
    }
    for (const double extent : {-1.0, std::nan("")}) {
        TrainState s = small_state();
        s.scene_extent = extent;
        save_checkpoint(tmp / "extent.lgck", s);
        expect_error([&] { (void)load_checkpoint(tmp / "extent.lgck"); }, {"extent.lgck", "scene extent"});
    }
    TrainState s = small_state();
    s.model.param(ModelParam::Xyz)[0] = std::numeric_limits<float>::infinity();
    save_checkpoint(tmp / "inf.lgck", s);
    expect_error([&] { (void)load_checkpoint(tmp / "inf.lgck"); }, {"inf.lgck", "non-finite"});
}

}  // namespace
}  // namespace lumigauss
