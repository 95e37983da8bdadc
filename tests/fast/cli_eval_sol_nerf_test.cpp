// `lumigauss eval --protocol sol-nerf`: on the synthetic NeRF-OSR scene of support/sol_nerf_scene.h with the
// model as a bare relightable PLY, it writes metrics.json (the true angles found), report.md, the contact
// sheets and the per-image SH files, and prints the eval-summary line; a missing or malformed config, a
// missing environment map and a missing image fail with a message naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "lumigauss/io/image.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/shading/sh_text.h"
#include "support/run_cli.h"
#include "support/sol_nerf_scene.h"

namespace lumigauss {
namespace {

namespace fs = std::filesystem;
using testing::CommandResult;
using ::testing::HasSubstr;
using testing::run_lumigauss;
using testing::shell_quoted;
using testing::TempDir;

struct CliSolScene {
    TempDir dir{"cli_sol_nerf"};
    GaussianModel model = testing::street_model();
    testing::SolNerfTestScene scene = testing::write_sol_nerf_test_scene(dir.str(), model);
    std::string ply = dir / "model.ply";
    CliSolScene() { save_relightable_ply(ply, model); }

    std::string args(const std::string& config, const std::string& out) const {
        return "eval " + shell_quoted(ply) + " --scene " + shell_quoted(scene.scene) +
               " --protocol sol-nerf --sol-config " + shell_quoted(config) + " --mask-root " +
               shell_quoted(scene.mask_root) + " -o " + shell_quoted(out);
    }
};

const CliSolScene& cli_scene() {
    static CliSolScene s;
    return s;
}

std::string read_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

TEST(CliEvalSolNerf, WritesTheReportWithTheTrueAngles) {
    const CliSolScene& s = cli_scene();
    TempDir tmp("cli_sol_nerf_report");
    const std::string report = tmp / "report";
    const CommandResult r = run_lumigauss(s.args(s.scene.config, report), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("eval-summary: shadowed_psnr="));
    EXPECT_THAT(r.output, HasSubstr("shadowed_mae="));
    const nlohmann::json j = nlohmann::json::parse(read_file(report + "/metrics.json"));
    EXPECT_EQ(j["protocol"], "sol-nerf");
    EXPECT_EQ(j["angles"], 51);
    ASSERT_EQ(j["images"].size(), s.scene.images.size());
    for (std::size_t i = 0; i < s.scene.images.size(); ++i) {
        const nlohmann::json& im = j["images"][i];
        const testing::SolNerfTestImage& truth = s.scene.images[i];
        EXPECT_EQ(im["name"], truth.config_name);
        EXPECT_EQ(im["best_index"], truth.true_index);
        EXPECT_GT(im["shadowed"]["psnr"].get<double>(), 50.0);
        for (const char* key : {"psnr", "ssim", "mse", "mae"})
            EXPECT_TRUE(im["unshadowed"][key].is_number()) << key;
        // The contact sheet (two rows of six panels) and the SH it was scored under.
        const std::string sheet = report + "/sheets/" + truth.stem + ".png";
        ASSERT_TRUE(fs::exists(sheet)) << sheet;
        EXPECT_EQ(read_image_info(sheet).width, 6 * 64 + 10);
        const ShCoeffs<double> sh = read_sh_text(report + "/env/" + truth.stem + "_sh.txt");
        EXPECT_NEAR(sh.c[0].x, im["environment_sh"][0][0].get<double>(), 1e-6);
    }
    const std::string md = read_file(report + "/report.md");
    EXPECT_THAT(md, HasSubstr("sol-nerf"));
    EXPECT_THAT(md, HasSubstr("sheets/" + s.scene.images[0].stem + ".png"));
}

TEST(CliEvalSolNerf, BadInputsNameTheFile) {
    const CliSolScene& s = cli_scene();
    TempDir tmp("cli_sol_nerf_errors");
    // Missing config.
    CommandResult r = run_lumigauss(s.args(tmp / "none.json", tmp / "out"), tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr(tmp / "none.json"));
    // Malformed JSON.
    std::ofstream(tmp / "bad.json") << "{\"images\": [";
    r = run_lumigauss(s.args(tmp / "bad.json", tmp / "out"), tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr(tmp / "bad.json"));
    EXPECT_THAT(r.output, HasSubstr("JSON"));
    // A missing environment map.
    std::string text = read_file(s.scene.config);
    const std::string env = "ENV_MAP_CC/" + s.scene.images[0].session;
    text.replace(text.find(env), env.size(), "ENV_MAP_CC/gone");
    std::ofstream(tmp / "no_env.json") << text;
    r = run_lumigauss(s.args(tmp / "no_env.json", tmp / "out"), tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("ENV_MAP_CC/gone"));
    // An image the scene does not have.
    text = read_file(s.scene.config);
    const std::string name = s.scene.images[1].config_name;
    text.replace(text.find(name), name.size(), "nope.JPG");
    std::ofstream(tmp / "no_image.json") << text;
    r = run_lumigauss(s.args(tmp / "no_image.json", tmp / "out"), tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("nope.JPG"));
    EXPECT_THAT(r.output, HasSubstr(tmp / "no_image.json"));
    // No config and a scene path that names no shipped scene.
    r = run_lumigauss("eval " + shell_quoted(s.ply) + " --scene " + shell_quoted(s.scene.scene) +
                          " --protocol sol-nerf -o " + shell_quoted(tmp / "out"),
                      tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("--sol-config"));
}

}  // namespace
}  // namespace lumigauss
