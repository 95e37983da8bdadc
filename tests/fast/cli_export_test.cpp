// `lumigauss export` end to end on a tiny trained run: every format writes what docs/formats.md says, the
// official-layout model.ply with an SH text file bakes exactly as the run with that photo's learned light
// (import), and bad input fails naming the format or the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>

#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/export/export_region.h"
#include "lumigauss/export/relightable_bundle.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/model/splat_ply.h"
#include "lumigauss/train/run_folder.h"
#include "support/run_cli.h"
#include "support/shared_tiny_run.h"
#include "synth_test_util.h"

namespace lumigauss {
namespace {

using synth_test::TempDir;
using testing::CommandResult;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::run_lumigauss;
using testing::shell_quoted;
namespace fs = std::filesystem;

// The tiny scene and a short run on it, shared with the other CLI tests (support/shared_tiny_run.h).
const testing::SharedTinyRun& tiny_run() {
    return testing::shared_tiny_run();
}

// `lumigauss export ARGS` run in `tmp` fails and says `message`.
void expect_refused(const std::string& args, const std::string& message, const TempDir& tmp) {
    const CommandResult r = run_lumigauss("export " + args, tmp);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_THAT(r.output, HasSubstr(message)) << args;
}

TEST(CliExport, EveryFormatAndImportFromBarePly) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_export_formats");
    const std::vector<std::string> photos = load_appearance(run_paths(t.run).appearance);
    ASSERT_FALSE(photos.empty());
    const std::size_t surfels = load_relightable_ply(run_paths(t.run).model).size();

    // env: one SH file and one EXR per photo.
    CommandResult r = run_lumigauss(
        "export " + shell_quoted(t.run) + " --format env --width 64 -o " + shell_quoted(tmp / "env"), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::size_t txt = 0, exr = 0;
    for (const auto& e : fs::directory_iterator(tmp / "env")) {
        txt += e.path().extension() == ".txt";
        exr += e.path().extension() == ".exr";
    }
    EXPECT_EQ(txt, photos.size());
    EXPECT_EQ(exr, photos.size());

    // ply-3dgs under the first photo's learned light; readable by the 2DGS reader.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format ply-3dgs --light " +
                          shell_quoted(photos[0]) + " -o " + shell_quoted(tmp / "baked/photo.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("both sides, SH degree 3"));
    EXPECT_EQ(load_2dgs_ply(tmp / "baked/photo.ply").size(), surfels);
    EXPECT_EQ(load_2dgs_ply(tmp / "baked/photo.ply").sh_degree, 3);
    // --sh-degree 0: one colour, the side the run's recorded training photos see.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format ply-3dgs --sh-degree 0 --light " +
                          shell_quoted(photos[0]) + " -o " + shell_quoted(tmp / "baked/one.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("the side the training photos see"));
    EXPECT_EQ(load_2dgs_ply(tmp / "baked/one.ply").sh_degree, 0);
    // 17 floats per surfel instead of 62.
    EXPECT_LT(3 * fs::file_size(tmp / "baked/one.ply"), fs::file_size(tmp / "baked/photo.ply"));

    // Import: the bare model.ply (official layout) with that photo's SH text file bakes the same bytes.
    fs::path stem = fs::path(photos[0]).replace_extension();
    std::string sh_name = stem.string();
    for (char& c : sh_name)
        if (c == '/' || c == '\\') c = '_';
    const std::string sh = tmp / ("env/" + sh_name + "_sh.txt");
    ASSERT_TRUE(fs::exists(sh)) << sh;
    r = run_lumigauss("export --ply " + shell_quoted(run_paths(t.run).model) + " --format ply-3dgs --light " +
                          shell_quoted(sh) + " -o " + shell_quoted(tmp / "baked/imported.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(synth_test::read_bytes(tmp / "baked/photo.ply"),
              synth_test::read_bytes(tmp / "baked/imported.ply"));

    // splat: 32 bytes per surfel.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format splat --light " + shell_quoted(sh) +
                          " -o " + shell_quoted(tmp / "m.splat"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(fs::file_size(tmp / "m.splat"), 32 * surfels);

    // --orient y-down: the same surfels, the world turned for y-down viewers.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format ply-3dgs --orient y-down --light " +
                          shell_quoted(photos[0]) + " -o " + shell_quoted(tmp / "baked/turned.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("is -y"));
    EXPECT_EQ(load_2dgs_ply(tmp / "baked/turned.ply").size(), surfels);

    // --crop-radius and --recentre: the surfels near the median centre, moved so that it is the origin; the
    // colours are those of the same crop left in place (the cameras move with the surfels).
    // The radius: the median distance of the surfels from their median centre, so that about half stay.
    const SurfelModel model = load_relightable_ply(run_paths(t.run).model);
    ExportRegion region;
    region.recentre = true;
    const Vec3d centre = apply_export_region(model, {}, region).centre;
    std::vector<double> distances;
    for (std::size_t i = 0; i < model.size(); ++i) {
        const std::vector<float>& xyz = model.param(ModelParam::Xyz);
        distances.push_back(length(Vec3d{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]} - centre));
    }
    std::nth_element(distances.begin(), distances.begin() + std::ptrdiff_t(distances.size() / 2),
                     distances.end());
    region = ExportRegion{};
    region.radius = distances[distances.size() / 2];
    char radius[32];
    std::snprintf(radius, sizeof radius, "%.17g", *region.radius);
    const std::string crop =
        " --format ply-3dgs --crop-radius " + std::string(radius) + " --light " + shell_quoted(photos[0]);
    r = run_lumigauss("export " + shell_quoted(t.run) + crop + " -o " + shell_quoted(tmp / "baked/crop.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("the crop keeps"));
    r = run_lumigauss(
        "export " + shell_quoted(t.run) + crop + " --recentre -o " + shell_quoted(tmp / "baked/centred.ply"),
        tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("origin moved to"));
    const ViewDependentSurfels in_place = load_2dgs_ply(tmp / "baked/crop.ply");
    const ViewDependentSurfels centred = load_2dgs_ply(tmp / "baked/centred.ply");
    ASSERT_EQ(in_place.size(), centred.size());
    EXPECT_GT(in_place.size(), 0u);
    EXPECT_LT(in_place.size(), surfels);
    const RegionedModel expected = apply_export_region(model, {}, region);
    EXPECT_EQ(in_place.size(), expected.model.size());
    for (std::size_t i = 0; i < centred.size(); ++i)
        for (int a = 0; a < 3; ++a)
            ASSERT_NEAR(centred.surfels.means[3 * i + a],
                        in_place.surfels.means[3 * i + a] - expected.centre[a], 1e-4);
    for (std::size_t k = 0; k < centred.sh.size(); ++k) ASSERT_NEAR(centred.sh[k], in_place.sh[k], 1e-4);
    expect_refused(shell_quoted(t.run) + " --format html --recentre -o " + shell_quoted(tmp / "page.html"),
                   "not html", tmp);

    // spz: gzip; the run's photos' up (the synthetic scene's +z) turned to +y.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format spz --light " + shell_quoted(photos[0]) +
                          " -o " + shell_quoted(tmp / "m.spz"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("is +y"));
    const std::string spz = synth_test::read_bytes(tmp / "m.spz");
    ASSERT_GT(spz.size(), 2u);
    EXPECT_EQ(std::uint8_t(spz[0]), 0x1f);
    EXPECT_EQ(std::uint8_t(spz[1]), 0x8b);

    // compressed-ply (export_compressed_ply_test.cpp reads it): degree 1, y-down by default (SuperSplat turns
    // a PLY by 180 degrees about z), 16 + 9 bytes per surfel; --orient none keeps the world.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format compressed-ply --sh-degree 1 --light " +
                          shell_quoted(photos[0]) + " -o " + shell_quoted(tmp / "m.compressed.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("is -y"));
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format compressed-ply --orient none --light " +
                          shell_quoted(photos[0]) + " -o " + shell_quoted(tmp / "world.compressed.ply"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, Not(HasSubstr("turned")));
    const std::string compressed = synth_test::read_bytes(tmp / "m.compressed.ply");
    const std::size_t body = compressed.size() - (compressed.find("end_header\n") + 11);
    EXPECT_EQ(body, 72 * ((surfels + 255) / 256) + (16 + 9) * surfels);

    // glb (export_gltf_test.cpp reads it): binary glTF, y-up; --orient is refused.
    r = run_lumigauss("export " + shell_quoted(t.run) + " --format glb --sh-degree 2 --light " +
                          shell_quoted(photos[0]) + " -o " + shell_quoted(tmp / "m.glb"),
                      tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, HasSubstr("is +y"));
    const std::string glb = synth_test::read_bytes(tmp / "m.glb");
    ASSERT_GT(glb.size(), 28u);
    EXPECT_EQ(glb.substr(0, 4), "glTF");
    EXPECT_NE(glb.find("KHR_gaussian_splatting:SH_DEGREE_2_COEF_4"), std::string::npos);
    expect_refused(shell_quoted(t.run) + " --format glb --orient y-down --light " + shell_quoted(photos[0]) +
                       " -o " + shell_quoted(tmp / "m2.glb"),
                   "glb is always y-up", tmp);

    // html: one page holding the viewer, the model (base64) and the run's lights (the browser test opens
    // one).
    r = run_lumigauss(
        "export " + shell_quoted(t.run) + " --format html -o " + shell_quoted(tmp / "page.html"), tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string page = synth_test::read_bytes(tmp / "page.html");
    EXPECT_NE(page.find("window.__lgEmbedded"), std::string::npos);
    EXPECT_NE(page.find(photos[0]), std::string::npos) << "the learned lights are offered by photo name";
    EXPECT_GT(page.size(), 124 * surfels * 4 / 3) << "the model payload is missing";

    // ply-relightable + sidecar; -q prints nothing. The sidecar's up is the training photos' (the synthetic
    // scene is z-up), not the +z default a bare PLY gets.
    r = run_lumigauss(
        "export -q " + shell_quoted(t.run) + " --format ply-relightable -o " + shell_quoted(tmp / "rel.ply"),
        tmp);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output, "");
    EXPECT_EQ(load_relightable_ply(tmp / "rel.ply").size(), surfels);
    const EnvironmentSidecar sidecar = read_environment_sidecar(tmp / "rel.environments.json");
    EXPECT_EQ(sidecar.environments.size(), photos.size());
    EXPECT_GT(parse_up_axis(sidecar.up).z, std::cos(2 * std::numbers::pi / 180)) << sidecar.up;
}

TEST(CliExport, BadInputNamesTheProblem) {
    const testing::SharedTinyRun& t = tiny_run();
    ASSERT_EQ(t.exit_code, 0) << t.output;
    TempDir tmp("cli_export_bad");
    CommandResult r =
        run_lumigauss("export " + shell_quoted(t.run) + " --format obj -o " + shell_quoted(tmp / "x"), tmp);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.output, HasSubstr("--format 'obj'"));

    const std::string missing = tmp / "no_such_run";
    expect_refused(shell_quoted(missing) + " --format env -o " + shell_quoted(tmp / "e"), missing, tmp);

    expect_refused(shell_quoted(t.run) + " --format splat -o " + shell_quoted(tmp / "m.splat"), "--light",
                   tmp);

    expect_refused(shell_quoted(t.run) + " --format ply-3dgs --light " + shell_quoted(tmp / "nope.txt") +
                       " -o " + shell_quoted(tmp / "m.ply"),
                   "nope.txt", tmp);
    EXPECT_FALSE(fs::exists(tmp / "m.ply"));

    // A baked light's options on a format that bakes none are refused, not ignored.
    expect_refused(shell_quoted(t.run) + " --format html --rotate 30 -o " + shell_quoted(tmp / "page.html"),
                   "--rotate shapes a baked light", tmp);
    EXPECT_FALSE(fs::exists(tmp / "page.html"));

    const std::string light = shell_quoted(load_appearance(run_paths(t.run).appearance).at(0));
    // --orient: none, y-up or y-down, for ply-3dgs, compressed-ply and splat (SPZ and glTF are y-up).
    expect_refused(shell_quoted(t.run) + " --format ply-3dgs --orient z-up --light " + light + " -o " +
                       shell_quoted(tmp / "m.ply"),
                   "--orient 'z-up'", tmp);
    expect_refused(shell_quoted(t.run) + " --format spz --orient y-down --light " + light + " -o " +
                       shell_quoted(tmp / "m.spz"),
                   "spz is always y-up", tmp);

    // --sh-degree: 0..3, and only for the formats with view-dependent colour.
    expect_refused(shell_quoted(t.run) + " --format ply-3dgs --sh-degree 4 --light " + light + " -o " +
                       shell_quoted(tmp / "m.ply"),
                   "--sh-degree 4", tmp);
    expect_refused(shell_quoted(t.run) + " --format splat --sh-degree 1 --light " + light + " -o " +
                       shell_quoted(tmp / "m.splat"),
                   "--sh-degree is for --format ply-3dgs", tmp);
    EXPECT_FALSE(fs::exists(tmp / "m.ply"));
    EXPECT_FALSE(fs::exists(tmp / "m.splat"));

    // A bare PLY has no photos to export.
    expect_refused(shell_quoted(run_paths(t.run).model) + " --format env -o " + shell_quoted(tmp / "e2"),
                   "no learned environments", tmp);
}

}  // namespace
}  // namespace lumigauss
