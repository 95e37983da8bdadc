// The same seed gives byte-identical datasets, whatever the number of threads; another seed another one.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <filesystem>

#include "lumigauss/util/error.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
namespace fs = std::filesystem;

std::vector<std::string> relative_files(const std::string& root) {
    std::vector<std::string> files;
    for (const auto& e : fs::recursive_directory_iterator(root))
        if (e.is_regular_file()) files.push_back(fs::relative(e.path(), root).string());
    std::sort(files.begin(), files.end());
    return files;
}

TEST(SynthDeterminism, SameSeedGivesByteIdenticalFiles) {
    TempDir a("synth_det_a"), b("synth_det_b"), c("synth_det_c");
    synth::SynthOptions o = synth_test::tiny_options(a.str());
    o.width = 48, o.height = 36;  // keeps three generations well inside the time budget
    synth::generate_synthetic_scene(o);
    {
        // One thread instead of all: rows and points are computed in another order.
        tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
        o.output_dir = b.str();
        synth::generate_synthetic_scene(o);
    }
    const auto files = relative_files(a.str());
    ASSERT_EQ(files, relative_files(b.str()));
    ASSERT_GT(files.size(), 70u);
    for (const std::string& f : files)
        EXPECT_TRUE(synth_test::read_bytes(a.sub(f)) == synth_test::read_bytes(b.sub(f))) << f;

    o.output_dir = c.str();
    o.seed = 2;
    synth::generate_synthetic_scene(o);
    EXPECT_NE(synth_test::read_bytes(a.sub("images/train_0000.png")),
              synth_test::read_bytes(c.sub("images/train_0000.png")));
    EXPECT_NE(synth_test::read_bytes(a.sub("env/sky00_sh.txt")),
              synth_test::read_bytes(c.sub("env/sky00_sh.txt")));
}

TEST(SynthDeterminism, RefusesANonEmptyFolderUnlessForced) {
    TempDir a("synth_force");
    synth::SynthOptions o = synth_test::tiny_options(a.str());
    o.width = 16, o.height = 12, o.n_train = 2, o.n_test = 1, o.point_candidates = 50;
    synth::generate_synthetic_scene(o);
    EXPECT_THROW(synth::generate_synthetic_scene(o), Error);
    std::ofstream(a.sub("user_notes.txt")) << "keep me";
    o.overwrite = true;
    EXPECT_NO_THROW(synth::generate_synthetic_scene(o));
    EXPECT_TRUE(fs::exists(a.sub("user_notes.txt")));  // only the dataset's own files are replaced
}

TEST(SynthDeterminism, RejectsInvalidOptions) {
    TempDir a("synth_invalid");
    synth::SynthOptions o = synth_test::tiny_options(a.str());
    o.scene = "cathedral";
    EXPECT_THROW(synth::generate_synthetic_scene(o), Error);
    o = synth_test::tiny_options(a.str());
    o.n_train = 1;
    EXPECT_THROW(synth::generate_synthetic_scene(o), Error);
    EXPECT_THROW(synth::synth_preset("huge"), Error);
}

}  // namespace
}  // namespace lumigauss
