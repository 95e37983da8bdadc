// RUN/progress.html and RUN/progress/: the charts read log.jsonl (damaged lines and null PSNRs skipped), the
// progress images are listed newest first, and a training run writes both with every checkpoint.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "lumigauss/io/image.h"
#include "lumigauss/synth/synth.h"
#include "lumigauss/train/progress_report.h"
#include "lumigauss/train/train_config.h"
#include "lumigauss/train/training_run.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using synth_test::TempDir;

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// The points of the chart of `key`.
std::string chart_points(const std::string& html, const std::string& key) {
    const std::size_t chart = html.find("data-key=\"" + key + "\"");
    if (chart == std::string::npos) return {};
    const std::size_t from = html.find("points=\"", chart) + 8;
    return html.substr(from, html.find('"', from) - from);
}

TEST(ProgressReport, ChartsFromTheLogAndImagesNewestFirst) {
    const std::string log =
        R"({"iteration": 10, "psnr": 12.5, "total": 0.5, "surfels": 100, "elapsed_s": 30})"
        "\n"
        R"({"iteration": 20, "psnr": null, "total": 0.4, "surfels": 120, "elapsed_s": 60})"
        "\n"
        "not json at all\n"
        R"({"iteration": 30, "psnr": 14.0, "total": 0.3, "surfels": 150, "elapsed_s": 120,)"
        R"( "held_out_psnr": 12.5})"
        "\n";
    const std::string html =
        progress_report_html("run <1>", log, {"progress/0000010.png", "progress/0000030.png"});
    EXPECT_EQ(count(html, "<svg"), 4u);
    EXPECT_EQ(count(chart_points(html, "psnr"), ","), 2u) << "the null PSNR is a gap, not a zero";
    EXPECT_EQ(count(chart_points(html, "total"), ","), 3u);
    EXPECT_EQ(count(chart_points(html, "surfels"), ","), 3u);
    EXPECT_EQ(count(chart_points(html, "held_out_psnr"), ","), 1u) << "scored at one snapshot";
    EXPECT_NE(html.find("run &lt;1&gt;"), std::string::npos);
    EXPECT_NE(html.find("iteration 30, 2.0 min"), std::string::npos);
    EXPECT_LT(html.find("0000030.png"), html.find("0000010.png")) << "newest first";

    const std::string empty = progress_report_html("r", "", {});
    EXPECT_EQ(count(empty, "no values yet"), 4u);
    EXPECT_NE(empty.find("none yet"), std::string::npos);
}

TEST(ProgressReport, TrainingWritesItWithEveryCheckpoint) {
    TempDir dir("progress_report_run");
    synth::generate_synthetic_scene(synth_test::tiny_options(dir / "scene"));
    TrainingRunRequest r;
    r.scene = dir / "scene";
    r.out = dir / "run";
    r.config = train_preset("fast");
    r.config.iterations = 30;
    r.config.checkpoint_interval = 10;
    TrainingRun run(r);
    ASSERT_EQ(run.run(
                  0, [] { return false; }, [](const StepReport&) {}),
              TrainingOutcome::Finished);
    for (const char* name : {"0000010.png", "0000020.png", "0000030.png"})
        EXPECT_TRUE(fs::exists(fs::path(r.out) / "progress" / name)) << name;
    const Image sheet = read_image((fs::path(r.out) / "progress/0000030.png").string());
    const TrainView& first = run.trainer().views().front();
    EXPECT_EQ(sheet.width, 3 * first.rgb.width);
    EXPECT_EQ(sheet.height, 4 * first.rgb.height) << "four training views stacked";
    std::ifstream in(fs::path(r.out) / "progress.html");
    std::stringstream html;
    html << in.rdbuf();
    EXPECT_EQ(count(html.str(), "<img src=\"progress/"), 3u);
    EXPECT_NE(html.str().find("iteration 30"), std::string::npos);
}

}  // namespace
}  // namespace lumigauss
