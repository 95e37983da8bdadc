// `export --format ply-relightable` and `--format env` (export/relightable_bundle.h,
// export/environment_files.h): the relightable PLY reads back to the same raw parameters, the sidecar to
// the learned environment of every photo; the env folder holds one SH text file per photo that reads back
// equal to lighting.env_sh(i), plus an EXR preview; a bare PLY loads as a run without photos.
#include <gtest/gtest.h>

#include <filesystem>

#include "lumigauss/export/environment_files.h"
#include "lumigauss/export/relightable_bundle.h"
#include "lumigauss/io/image.h"
#include "lumigauss/io/ply.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/util/error.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
namespace fs = std::filesystem;

TrainedRun small_run() {
    const Camera cam = lumigauss::testing::test_camera();
    return relight_test::in_memory_run(relight_test::random_model(cam, 21, 15),
                                       {"a.jpg", "sub/b.png", "c.jpg", "c.png"});
}

void expect_sh_equal(const ShCoeffs<double>& a, const ShCoeffs<double>& b, double tol) {
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(a.c[k][c], b.c[k][c], tol) << "coefficient " << k << " channel " << c;
}

TEST(ExportBundle, RelightablePlyAndSidecarRoundTrip) {
    TempDir tmp("export_bundle");
    const TrainedRun run = small_run();
    const std::string ply = tmp / "out/model_relightable.ply";
    fs::create_directories(tmp / "out");
    const std::string sidecar = write_relightable_bundle(ply, run, Vec3d{0, -1, 0});
    EXPECT_EQ(sidecar, tmp / "out/model_relightable.environments.json");
    EXPECT_EQ(relightable_sidecar_path("x/y.PLY"), "x/y.environments.json");

    const SurfelModel back = load_relightable_ply(ply);
    ASSERT_EQ(back.size(), run.model.size());
    for (int p = 0; p < kModelParamCount; ++p)
        EXPECT_EQ(back.param(ModelParam(p)), run.model.param(ModelParam(p)))
            << GaussianModel::name(ModelParam(p));

    const EnvironmentSidecar s = read_environment_sidecar(sidecar);
    EXPECT_EQ(s.model, "model_relightable.ply");
    EXPECT_EQ(s.surfels, run.model.size());
    EXPECT_EQ(s.up, "-y");
    ASSERT_EQ(s.environments.size(), run.image_names.size());
    for (std::size_t i = 0; i < s.environments.size(); ++i) {
        EXPECT_EQ(s.environments[i].name, run.image_names[i]);
        EXPECT_EQ(s.environments[i].index, int(i));
        expect_sh_equal(s.environments[i].sh, run.learned_sh(int(i)), 0.0);  // JSON keeps doubles exactly
    }

    // Every property, no surfel: refused, naming the file (it used to load as an empty model).
    PlyVertexTable table = read_ply_vertices(ply), empty;
    for (const std::string& name : table.names) empty.add(name, {});
    write_ply_vertices(tmp / "out/empty.ply", empty);
    try {
        (void)load_relightable_ply(tmp / "out/empty.ply");
        ADD_FAILURE() << "an empty model was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("empty.ply: the model has no surfels"), std::string::npos)
            << e.what();
    }
}

TEST(ExportBundle, EnvironmentFilesReadBackEqual) {
    TempDir tmp("export_env");
    const TrainedRun run = small_run();
    const std::vector<std::string> stems = environment_stems(run.image_names);
    EXPECT_EQ(stems, (std::vector<std::string>{"a", "sub_b", "c_jpg", "c_png"}));
    const std::string dir = tmp / "env";
    const auto files = write_environment_files(dir, learned_environments(run), Vec3d{0, 0, 1}, 32);
    EXPECT_EQ(files.size(), 2 * run.image_names.size());
    for (std::size_t i = 0; i < stems.size(); ++i) {
        const ShCoeffs<double> sh = read_sh_text(dir + "/" + stems[i] + "_sh.txt");
        const ShCoeffs<double> want = run.lighting.env_sh(int(i)).cast<double>();
        expect_sh_equal(sh, want, 1e-6);
        // %.9g keeps a float exactly
        for (int k = 0; k < kShCount; ++k)
            for (int c = 0; c < 3; ++c) EXPECT_EQ(float(sh.c[k][c]), float(want.c[k][c]));
        const Image pano = read_image(dir + "/" + stems[i] + ".exr");
        EXPECT_EQ(pano.width, 32);
        EXPECT_EQ(pano.height, 16);
    }
    EXPECT_THROW(write_environment_files(tmp / "none", {}, Vec3d{0, 0, 1}, 32), Error);
}

TEST(ExportBundle, BarePlyLoadsAsRunWithoutPhotos) {
    TempDir tmp("export_bare");
    const TrainedRun run = small_run();
    const std::string ply = tmp / "official.ply";
    save_relightable_ply(ply, run.model);
    const TrainedRun bare = load_run_or_ply(ply);
    EXPECT_TRUE(bare.image_names.empty());
    EXPECT_EQ(bare.model.param(ModelParam::Albedo), run.model.param(ModelParam::Albedo));
    try {
        load_run_or_ply(tmp / "missing_run");
        ADD_FAILURE() << "no throw";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("missing_run"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace lumigauss
