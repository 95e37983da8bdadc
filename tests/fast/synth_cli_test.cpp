// `lumigauss synth`: the built binary writes a loadable dataset and reports bad options as errors.
#include <gtest/gtest.h>

#include <cstdlib>

#include "lumigauss/io/dataset.h"
#include "support/run_cli.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::CommandResult;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

TEST(SynthCli, WritesTheTinyPresetWithOverrides) {
    TempDir tmp("synth_cli");
    const std::string out = tmp.sub("temple");
    const CommandResult r = run_lumigauss(
        "synth --preset tiny --landmark temple --train 4 --test 1 --width 40 --height 30 -o '" + out + "'",
        tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("landmark temple, 40x30, 4 train"), std::string::npos) << r.output;
    const Dataset d = load_dataset(out, DatasetOptions{});
    EXPECT_EQ(d.views.size(), 5u);
    EXPECT_EQ(d.views[0].camera.width, 40);
    EXPECT_EQ(synth_test::read_json(out + "/meta.json")["scene"], "temple");

    // The old name of --landmark still works.
    const CommandResult old_name =
        run_lumigauss("synth --preset tiny --scene temple --train 2 --test 0 --width 16 --height 12 -o '" +
                          tmp.sub("old") + "'",
                      tmp);
    ASSERT_EQ(old_name.exit_code, 0) << old_name.output;
    EXPECT_NE(old_name.output.find("landmark temple, 16x12"), std::string::npos) << old_name.output;

    const CommandResult again = run_lumigauss("synth --preset tiny -o '" + out + "'", tmp);
    EXPECT_EQ(again.exit_code, 1) << again.output;
    EXPECT_NE(again.output.find("--force"), std::string::npos) << again.output;

    // -q, as every command takes it: nothing printed, the dataset written; with -v it is an error.
    const CommandResult quiet = run_lumigauss(
        "synth --preset tiny --train 2 --test 0 --width 16 --height 12 -q -o '" + tmp.sub("quiet") + "'",
        tmp);
    ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
    EXPECT_EQ(quiet.output, "");
    EXPECT_EQ(load_dataset(tmp.sub("quiet"), DatasetOptions{}).views.size(), 2u);
    const CommandResult loud_and_quiet =
        run_lumigauss("synth --preset tiny -q -v -o '" + tmp.sub("both") + "'", tmp);
    EXPECT_NE(loud_and_quiet.exit_code, 0);
    EXPECT_NE(loud_and_quiet.output.find("excludes"), std::string::npos) << loud_and_quiet.output;

    const CommandResult bad =
        run_lumigauss("synth --preset tiny --transients 2 -o '" + tmp.sub("x") + "'", tmp);
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_FALSE(fs::exists(tmp.sub("x")));
}

}  // namespace
}  // namespace lumigauss
