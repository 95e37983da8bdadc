// `lumigauss info`: the built binary run on the plaza scene and on broken scenes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>

#include "fast/io_test_util.h"

namespace lumigauss {
namespace {

using test::TempDir;

struct CommandResult {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
};

CommandResult run_lumigauss(const std::string& args, const TempDir& tmp) {
    const std::string out = tmp / "output.txt";
    const std::string command = std::string("'") + LUMIGAUSS_BINARY + "' " + args + " > '" + out + "' 2>&1";
    const int status = std::system(command.c_str());
    CommandResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.output = test::read_text(out);
    return r;
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

TEST(CliInfo, DescribesPlaza) {
    const std::string plaza = test::plaza_dir();
    if (plaza.empty()) GTEST_SKIP() << "shared data/plaza_mini not present";
    TempDir tmp;
    const CommandResult r = run_lumigauss("info '" + plaza + "'", tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "format:        colmap-text")) << r.output;
    EXPECT_TRUE(contains(r.output, "views:         28 (train 24, test 4, validation 0)")) << r.output;
    EXPECT_TRUE(contains(r.output, "resolutions:   128x96 (28)")) << r.output;
    EXPECT_TRUE(contains(r.output, "camera models: PINHOLE (28)")) << r.output;
    EXPECT_TRUE(contains(r.output, "masks:         28 of 28 views, taken as transient masks")) << r.output;
    EXPECT_TRUE(contains(r.output, "sky masks:     28 of 28 views (255 = sky")) << r.output;
    EXPECT_TRUE(contains(r.output, "points:        4658")) << r.output;
    const CommandResult object = run_lumigauss("info '" + plaza + "' --masks object", tmp);
    EXPECT_TRUE(contains(object.output, "taken as object masks (0 = empty space")) << object.output;
    EXPECT_TRUE(contains(r.output, "camera centre: mean (")) << r.output;
    EXPECT_TRUE(contains(r.output, "points bbox:   min (")) << r.output;

    const CommandResult half = run_lumigauss("info '" + plaza + "' -r 2", tmp);
    ASSERT_EQ(half.exit_code, 0) << half.output;
    EXPECT_TRUE(contains(half.output, "downscale:     2")) << half.output;
    EXPECT_TRUE(contains(half.output, "resolutions:   64x48 (28)")) << half.output;
}

TEST(CliInfo, SmallSceneExtent) {
    TempDir tmp;
    // Camera centres at x = 0, 1, 2 (z = -5): mean (1, 0, -5), max distance 1, extent 1.1.
    test::write_scene(tmp.path() / "scene", test::small_model(3, 8, 6));
    const CommandResult r = run_lumigauss("info '" + (tmp / "scene") + "'", tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "mean (1, 0, -5), extent 1.1 ")) << r.output;
    EXPECT_TRUE(contains(r.output, "sky masks:     0 of 3 views (the sky is then found")) << r.output;
    EXPECT_TRUE(contains(r.output, "min (-1, 0, 0), max (1, 2, 3)")) << r.output;
    // -r has one meaning and both long names on every command.
    const CommandResult half = run_lumigauss("info -r 2 '" + (tmp / "scene") + "'", tmp);
    ASSERT_EQ(half.exit_code, 0) << half.output;
    EXPECT_TRUE(contains(half.output, "resolutions:   4x3 (3)")) << half.output;
    for (const char* name : {"--resolution", "--downscale"})
        EXPECT_EQ(run_lumigauss(std::string("info ") + name + " 2 '" + (tmp / "scene") + "'", tmp).output,
                  half.output);
    const CommandResult quiet = run_lumigauss("info -q '" + (tmp / "scene") + "'", tmp);
    ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
    EXPECT_EQ(quiet.output,
              "info: " + (tmp / "scene") + ": colmap-text, 3 views (train 2, test 1), 3 SfM points\n");
}

TEST(CliInfo, BrokenSceneFailsNamingTheFile) {
    TempDir tmp;
    test::write_scene(tmp.path() / "scene", test::small_model(3, 8, 6));
    std::filesystem::remove(tmp.path() / "scene/images/img_2.png");
    const CommandResult r = run_lumigauss("info '" + (tmp / "scene") + "'", tmp);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_TRUE(contains(r.output, "error:")) << r.output;
    EXPECT_TRUE(contains(r.output, "img_2.png")) << r.output;

    const CommandResult bad_option = run_lumigauss("info '" + (tmp / "scene") + "' -r 3", tmp);
    EXPECT_NE(bad_option.exit_code, 0) << bad_option.output;
}

}  // namespace
}  // namespace lumigauss
