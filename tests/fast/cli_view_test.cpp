// `lumigauss view`: the command serves the viewer on 127.0.0.1 (the URL it prints works, Ctrl-C stops it,
// a taken port is a clear error), and the page really renders: headless Chromium (software WebGL through
// SwiftShader) opens it in bench mode, and the test checks that no JS error happened, every control works,
// the canvas is not blank, the JS environment rotation equals the C++ one, and the page's image of every view
// for a fixed camera matches the C++ renderer's (RelitRenderer, relit_outputs.h conventions).
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "lumigauss/cameras/camera_json.h"
#include "lumigauss/cameras/up_axis.h"
#include "lumigauss/io/image.h"
#include "lumigauss/model/relightable_ply.h"
#include "lumigauss/model/trained_run.h"
#include "lumigauss/relight/light_source.h"
#include "lumigauss/relight/relit_render.h"
#include "lumigauss/render/raster_maps.h"
#include "lumigauss/shading/envmap.h"
#include "lumigauss/shading/sh4_rotation.h"
#include "lumigauss/shading/sh_rotation.h"
#include "lumigauss/shading/sh_text.h"
#include "lumigauss/shading/sky_image.h"
#include "lumigauss/viewer/http_server.h"
#include "lumigauss/viewer/model_payload.h"
#include "lumigauss/viewer/scene_info.h"
#include "lumigauss/viewer/url_path.h"
#include "lumigauss/viewer/viewer_site.h"
#include "relight_test_util.h"
#include "support/random_surfels.h"
#include "support/run_cli.h"
#include "support/temp_dir.h"

extern char** environ;

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using Clock = std::chrono::steady_clock;

std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// A child process with stdout and stderr in `log`, optionally leading its own process group (so that a
// browser and every helper process it starts can be ended together).
pid_t spawn(const std::vector<std::string>& args, const std::string& log, bool own_group) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    if (own_group) {
        posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
        posix_spawnattr_setpgroup(&attr, 0);
    }
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = -1;
    if (posix_spawnp(&pid, argv[0], &actions, &attr, argv.data(), environ) != 0) pid = -1;
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    return pid;
}

// The exit status once `pid` has exited, or nothing after `seconds`.
std::optional<int> wait_for_exit(pid_t pid, double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        if (Clock::now() > end) return std::nullopt;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
}

// Ends a child we started (and, for a group leader, its group): SIGTERM, then SIGKILL.
void end_child(pid_t pid, bool group) {
    ::kill(group ? -pid : pid, SIGTERM);
    if (!wait_for_exit(pid, 5)) {
        ::kill(group ? -pid : pid, SIGKILL);
        ::waitpid(pid, nullptr, 0);
    }
    if (group) ::kill(-pid, SIGKILL);  // helpers that outlived the leader
}

// The port of the URL `view` prints, once it has printed it.
std::optional<int> wait_for_port(const std::string& log, double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) {
        const std::string text = read_text(log);
        const std::size_t at = text.find("http://127.0.0.1:");
        if (at != std::string::npos && text.find('/', at + 17) != std::string::npos)
            return std::atoi(text.c_str() + at + 17);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return std::nullopt;
}

// GET over a plain socket: the status code and the body.
std::pair<int, std::string> http_get(int port, const std::string& target) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(std::uint16_t(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        return {0, ""};
    }
    const std::string req =
        "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n\r\n";
    ::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
    std::string data;
    char buf[65536];
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) data.append(buf, std::size_t(n));
    ::close(fd);
    const std::size_t end = data.find("\r\n\r\n");
    if (data.size() < 12 || end == std::string::npos) return {0, ""};
    return {std::atoi(data.c_str() + 9), data.substr(end + 4)};
}

// A bare relightable PLY of `count` surfels in front of `cam`, and an SH file, in `tmp`.
void write_model_and_light(const TempDir& tmp, const Camera& cam, std::size_t count) {
    save_relightable_ply(tmp / "model.ply", relight_test::random_model(cam, 21, count));
    write_sh_text(tmp / "env.txt", relight_test::bright_sh(8));
}

TEST(CliView, PrintsItsUrlServesThePageAndStopsOnCtrlC) {
    TempDir tmp("cli_view");
    write_model_and_light(tmp, testing::test_camera(), 40);
    const pid_t pid =
        spawn({LUMIGAUSS_BINARY, "view", tmp / "model.ply", "--port", "0", "--light", tmp / "env.txt"},
              tmp / "log.txt", false);
    ASSERT_GT(pid, 0);
    const std::optional<int> port = wait_for_port(tmp / "log.txt", 20);
    if (!port) end_child(pid, false);
    ASSERT_TRUE(port) << read_text(tmp / "log.txt");
    const auto [status, body] = http_get(*port, "/");
    EXPECT_EQ(status, 200);
    EXPECT_NE(body.find("<canvas"), std::string::npos);
    const auto scene = http_get(*port, "/scene.json");
    EXPECT_NE(scene.second.find("\"env.txt\""), std::string::npos) << scene.second;
    EXPECT_EQ(http_get(*port, "/bench-report?data=%7B%7D").first, 404) << "no report route without the flag";
    ::kill(pid, SIGINT);
    const std::optional<int> code = wait_for_exit(pid, 10);
    if (!code) end_child(pid, false);
    ASSERT_TRUE(code) << "Ctrl-C did not stop the server";
    EXPECT_EQ(*code, 0);
    EXPECT_NE(read_text(tmp / "log.txt").find("view: stopped"), std::string::npos);
}

// A running training writes a newer snapshot with every checkpoint: `view` serves it (GET /version grows,
// model.bin is the new model) and keeps the current one when a snapshot cannot be loaded.
TEST(CliView, FollowsANewerSnapshotOfTheModel) {
    TempDir tmp("cli_view_reload");
    write_model_and_light(tmp, testing::test_camera(), 40);
    const pid_t pid =
        spawn({LUMIGAUSS_BINARY, "view", tmp / "model.ply", "--port", "0"}, tmp / "log.txt", false);
    ASSERT_GT(pid, 0);
    const std::optional<int> port = wait_for_port(tmp / "log.txt", 20);
    if (!port) end_child(pid, false);
    ASSERT_TRUE(port) << read_text(tmp / "log.txt");
    const auto version = [&] { return nlohmann::json::parse(http_get(*port, "/version").second)["version"]; };
    const auto wait_for_version = [&](int want) {
        const auto end = Clock::now() + std::chrono::seconds(15);
        while (version() != want && Clock::now() < end)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        return version() == want;
    };
    EXPECT_EQ(version(), 1);
    EXPECT_EQ(http_get(*port, "/model.bin").second.size(), 32u + 124u * 40u);

    // A newer snapshot, written as training writes it (to a temporary name, then renamed).
    save_relightable_ply(tmp / "newer.ply", relight_test::random_model(testing::test_camera(), 5, 25));
    std::filesystem::rename(tmp / "newer.ply", tmp / "model.ply");
    EXPECT_TRUE(wait_for_version(2)) << read_text(tmp / "log.txt");
    EXPECT_EQ(http_get(*port, "/model.bin").second.size(), 32u + 124u * 25u);

    // A damaged one: reported, the current model stays.
    {
        std::ofstream bad(tmp / "model.ply", std::ios::trunc);
        bad << "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n";
    }
    const auto end = Clock::now() + std::chrono::seconds(15);
    while (read_text(tmp / "log.txt").find("could not reload") == std::string::npos && Clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_NE(read_text(tmp / "log.txt").find("could not reload"), std::string::npos)
        << read_text(tmp / "log.txt");
    EXPECT_EQ(version(), 2);
    EXPECT_EQ(http_get(*port, "/model.bin").second.size(), 32u + 124u * 25u);
    ::kill(pid, SIGINT);
    const std::optional<int> code = wait_for_exit(pid, 10);
    if (!code) end_child(pid, false);
    ASSERT_TRUE(code) << "Ctrl-C did not stop the server";
    EXPECT_EQ(*code, 0);
}

TEST(CliView, InitialCameraAndUpAxisFromACameraJson) {
    TempDir tmp("cli_view_camera");
    const Camera cam = testing::test_camera();  // camera y down along about -y of the world
    write_model_and_light(tmp, cam, 20);
    write_camera_json(tmp / "cams.json", {{"first", cam}});
    const pid_t pid = spawn({LUMIGAUSS_BINARY, "view", tmp / "model.ply", "--port", "0", "--camera",
                             tmp / "cams.json", "--up", "auto", "-q"},
                            tmp / "log.txt", false);
    ASSERT_GT(pid, 0);
    const std::optional<int> port = wait_for_port(tmp / "log.txt", 20);
    const auto scene = port ? http_get(*port, "/scene.json") : std::pair<int, std::string>{};
    end_child(pid, false);
    ASSERT_TRUE(port) << read_text(tmp / "log.txt");
    EXPECT_EQ(read_text(tmp / "log.txt").find("surfels"), std::string::npos) << "-q prints only the address";
    const nlohmann::json j = nlohmann::json::parse(scene.second);
    // The camera's own up (its -y), not the axis nearest to it (-y).
    const Vec3d camera_up = -1.0 * cam.rotation.row(1);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(j["up"][i].get<double>(), camera_up[i], 1e-9) << i;
    EXPECT_EQ(j["up_name"], up_axis_name(camera_up));
    EXPECT_EQ(j["camera"]["fx"].get<double>(), cam.fx);
    EXPECT_EQ(j["camera"]["t"][1].get<double>(), cam.translation.y);
}

TEST(CliView, ATakenPortIsAClearError) {
    TempDir tmp("cli_view_port");
    write_model_and_light(tmp, testing::test_camera(), 10);
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    ASSERT_EQ(::listen(fd, 1), 0);
    socklen_t len = sizeof addr;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    const int port = ntohs(addr.sin_port);
    const auto r = testing::run_lumigauss(
        "view " + testing::shell_quoted(tmp / "model.ply") + " --port " + std::to_string(port), tmp);
    ::close(fd);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("port " + std::to_string(port)), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("already in use"), std::string::npos) << r.output;
}

TEST(CliView, BadSourceOrUpAxisIsAnErrorNamingIt) {
    TempDir tmp("cli_view_bad");
    const auto missing =
        testing::run_lumigauss("view " + testing::shell_quoted(tmp / "nope") + " --port 0", tmp);
    EXPECT_NE(missing.exit_code, 0);
    EXPECT_NE(missing.output.find("nope"), std::string::npos) << missing.output;
    write_model_and_light(tmp, testing::test_camera(), 10);
    const auto up =
        testing::run_lumigauss("view " + testing::shell_quoted(tmp / "model.ply") + " --up sideways", tmp);
    EXPECT_NE(up.exit_code, 0);
    EXPECT_NE(up.output.find("up axis 'sideways'"), std::string::npos) << up.output;
}

// ---------------------------------------------------------------------------------------------------------
// Headless Chromium

std::optional<std::string> find_chromium() {
    if (const char* env = std::getenv("LUMIGAUSS_CHROMIUM")) return std::string(env);
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "");
    for (std::string dir; std::getline(dirs, dir, ':');)
        for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
            const std::filesystem::path p = std::filesystem::path(dir) / name;
            if (::access(p.c_str(), X_OK) == 0) return p.string();
        }
    return std::nullopt;
}

std::vector<unsigned char> base64_decode(const std::string& text) {
    std::vector<unsigned char> out;
    int bits = 0;
    unsigned value = 0;
    for (char ch : text) {
        const std::string_view alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        const std::size_t v = alphabet.find(ch);
        if (v == std::string_view::npos) continue;  // '=' padding
        value = (value << 6) | unsigned(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out.push_back(static_cast<unsigned char>((value >> bits) & 0xffu));
        }
    }
    return out;
}

// The C++ image of each view, as relit_outputs.h writes it (3 channels, clamped to [0, 1]).
std::map<std::string, Image> cpu_views(const SurfelModel& model, const Camera& cam,
                                       const ShCoeffs<float>& env) {
    RelitRenderer renderer(model);
    const RasterImages<float>& raster = renderer.render(cam, env);
    std::map<std::string, Image> views;
    views["shadowed"] = raster_channels(raster, kRelitShadowed, 3);
    views["unshadowed"] = raster_channels(raster, kRelitUnshadowed, 3);
    views["albedo"] = raster_channels(raster, kRelitAlbedo, 3);
    views["normals"] = encode_normals(raster);
    const Image shadow = shadow_image(raster_channels(raster, kRelitIntensityUnshadowed, 3),
                                      raster_channels(raster, kRelitIntensityShadowed, 3));
    Image grey(shadow.width, shadow.height, 3);
    for (std::size_t p = 0; p < shadow.pixels.size(); ++p)
        for (int c = 0; c < 3; ++c) grey.pixels[3 * p + std::size_t(c)] = shadow.pixels[p];
    views["shadow"] = grey;
    for (auto& [name, im] : views)
        for (float& v : im.pixels) v = std::clamp(v, 0.0f, 1.0f);
    return views;
}

double psnr(const std::vector<unsigned char>& page, const Image& cpu) {
    double se = 0;
    for (std::size_t i = 0; i < cpu.pixels.size(); ++i) {
        const double d = double(page[i]) / 255.0 - double(cpu.pixels[i]);
        se += d * d;
    }
    const double mse = se / double(cpu.pixels.size());
    return mse > 0 ? 10 * std::log10(1.0 / mse) : 99.0;
}

// Headless Chromium on `url` (software WebGL, a fresh profile in `tmp`, output in tmp/browser.txt), leading
// its own process group.
pid_t spawn_browser(const TempDir& tmp, const std::string& chromium, const std::string& url) {
    return spawn(
        {chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
         "--user-data-dir=" + tmp / "profile", "--window-size=640,480", "--force-device-scale-factor=1",
         "--no-first-run", "--no-default-browser-check", "--disable-extensions",
         "--disable-background-networking", "--disable-dev-shm-usage", "--mute-audio", url},
        tmp / "browser.txt", true);
}

struct BrowserRun {
    nlohmann::json report;
    std::string server_log, browser_log;
};

// Serves `model.ply` with the bench report enabled, opens `query` in headless Chromium and waits for the
// report (the server exits once it has it).
std::optional<BrowserRun> run_in_browser(const TempDir& tmp, const std::string& chromium,
                                         const std::string& query) {
    const pid_t server = spawn({LUMIGAUSS_BINARY, "view", tmp / "model.ply", "--port", "0", "--light",
                                tmp / "env.txt", "--bench-report", tmp / "report.json"},
                               tmp / "server.txt", false);
    if (server <= 0) return std::nullopt;
    const std::optional<int> port = wait_for_port(tmp / "server.txt", 20);
    BrowserRun run;
    pid_t browser = -1;
    if (port) {
        browser = spawn_browser(tmp, chromium, "http://127.0.0.1:" + std::to_string(*port) + "/?" + query);
    }
    const std::optional<int> code = browser > 0 ? wait_for_exit(server, 45) : std::nullopt;
    if (!code) end_child(server, false);
    if (browser > 0) end_child(browser, true);
    run.server_log = read_text(tmp / "server.txt");
    run.browser_log = read_text(tmp / "browser.txt");
    if (!code || !std::filesystem::exists(tmp / "report.json")) {
        ADD_FAILURE() << "no report from the page\nserver:\n"
                      << run.server_log << "\nbrowser:\n"
                      << run.browser_log;
        return std::nullopt;
    }
    run.report = nlohmann::json::parse(read_text(tmp / "report.json"));
    return run;
}

std::string camera_param(const Camera& c) {
    std::ostringstream s;
    s.precision(17);
    s << c.width << ',' << c.height << ',' << c.fx << ',' << c.fy << ',' << c.cx << ',' << c.cy;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s << ',' << c.rotation(i, j);
    for (int k = 0; k < 3; ++k) s << ',' << c.translation[k];
    return s.str();
}

// Compares the page's shots of the named views with the C++ images, each at least `min_psnr` dB.
void expect_shots_match(const TempDir& tmp, const Camera& cam, double rotate, const nlohmann::json& r,
                        const std::map<std::string, double>& min_psnr) {
    const ShCoeffs<double> env = rotate_about_up(read_sh_text(tmp / "env.txt"), {0, 0, 1}, rotate);
    const auto cpu = cpu_views(load_relightable_ply(tmp / "model.ply"), cam, env.cast<float>());
    for (const auto& [name, bound] : min_psnr) {
        const Image& image = cpu.at(name);
        const nlohmann::json& shot = r["shots"][name];
        ASSERT_EQ(shot["width"], cam.width) << name;
        ASSERT_EQ(shot["height"], cam.height) << name;
        const std::vector<unsigned char> rgb = base64_decode(shot["rgb"]);
        ASSERT_EQ(rgb.size(), image.pixels.size()) << name;
        const double p = psnr(rgb, image);
        std::printf("  %-10s PSNR %.1f dB (%s target)\n", name.c_str(), p,
                    r["float_target"].get<bool>() ? "float" : "8-bit");
        EXPECT_GE(p, bound) << name;
    }
}

TEST(CliViewBrowser, RendersWithoutErrorsAndMatchesTheCppRenderer) {
    const std::optional<std::string> chromium = find_chromium();
    if (!chromium)
        GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/setup.sh does)";
    TempDir tmp("cli_view_browser");
    const Camera cam = testing::test_camera(96, 72);
    write_model_and_light(tmp, cam, 400);
    const double rotate = 30;
    const auto run = run_in_browser(tmp, *chromium, "bench=6&controls&rot=30&cam=" + camera_param(cam));
    ASSERT_TRUE(run);
    const nlohmann::json& r = run->report;
    ASSERT_TRUE(r.contains("errors")) << r.dump(2);
    EXPECT_TRUE(r["errors"].empty()) << r["errors"].dump(2);
    ASSERT_FALSE(r.value("failed", false)) << r.dump(2);
    EXPECT_EQ(r["splats"], 400);
    EXPECT_EQ(r["frame_ms"]["count"], 6);
    EXPECT_GT(r["frame_ms"]["median"].get<double>(), 0.0);
    EXPECT_GT(r["sort_ms"]["count"].get<int>(), 0) << "the worker sorted nothing";
    EXPECT_GT(r["nonblank_fraction"].get<double>(), 0.01) << "the orbit frames are blank";
    for (const auto& [name, ok] : r["controls"].items()) EXPECT_TRUE(ok.get<bool>()) << "control " << name;
    EXPECT_GE(r["controls"].size(), 12u);
    for (const char* control : {"drop_sh_file", "drop_panorama", "hdr_flat_equals_rle", "panel_toggle",
                                "loading_hidden", "sh_file_sky_rows", "sh_file_bad_sky_row"})
        EXPECT_TRUE(r["controls"].contains(control)) << control;
    std::printf("  %s, %s target: frame median %.1f ms\n", r["renderer"].get<std::string>().c_str(),
                r["float_target"].get<bool>() ? "float" : "8-bit", r["frame_ms"]["median"].get<double>());

    // The page's SH rotation is the C++ one.
    const nlohmann::json& rc = r["rotation_check"];
    ShCoeffs<double> sh;
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) sh.c[k][c] = rc["sh"][k][c];
    const ShCoeffs<double> want = rotate_about_up(sh, {0, 0, 1}, rc["degrees"].get<double>());
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(rc["rotated"][k][c].get<double>(), want.c[k][c], 1e-12) << k;

    // The dropped panorama lights the page with the SH the C++ projects from the same file about the same up
    // (the page decoded the .hdr itself), and the page's panorama frames are the C++ ones.
    const nlohmann::json& pc = r["panorama_check"];
    ASSERT_TRUE(pc.is_object()) << r.dump(2);
    const std::vector<unsigned char> hdr = base64_decode(pc["hdr_base64"]);
    std::ofstream(tmp / "dropped.hdr", std::ios::binary)
        .write(reinterpret_cast<const char*>(hdr.data()), std::streamsize(hdr.size()));
    const Vec3d page_up{pc["up"][0], pc["up"][1], pc["up"][2]};
    const ShCoeffs<double> projected =
        project_panorama_to_sh(read_image(tmp / "dropped.hdr"), panorama_frame_for_up(page_up));
    for (int k = 0; k < kShCount; ++k)
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(pc["sh"][k][c].get<double>(), projected.c[k][c], 1e-9) << k;
    for (const nlohmann::json& f : pc["frames"]) {
        const Mat3d frame = panorama_frame_for_up({f["up"][0], f["up"][1], f["up"][2]});
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                EXPECT_NEAR(f["frame"][i][j].get<double>(), frame(i, j), 1e-12) << f.dump();
    }

    // Every view from the fixed camera. The page computes in float like the C++ (same formulas); what differs
    // is rounding (GPU exp/pow, half-float blending, 8-bit read-back), so colours agree to about 1/255:
    // 40 dB leaves a margin over the ~60 dB measured. Normals are normalised per pixel, so a pixel at the
    // edge of a splat's 1/255 alpha cut-off flips between black and a full normal: 30 dB allows a few such
    // pixels.
    expect_shots_match(
        tmp, cam, rotate, r,
        {{"shadowed", 40}, {"unshadowed", 40}, {"albedo", 40}, {"normals", 30}, {"shadow", 40}});
}

// Serves the page's requests in this process with `route` (and /bench-report itself), opens `target` (path
// and query) in headless Chromium and returns the page's bench report, or nothing after 60 s. `waiting` runs
// on this thread every 20 ms until the report arrives (the reload test hands the site a newer model there).
std::optional<nlohmann::json> report_from_page(
    const TempDir& tmp, const std::string& chromium, const std::string& target,
    const std::function<view::HttpResponse(const view::HttpRequest&)>& route,
    const std::function<void()>& waiting = {}) {
    std::optional<std::string> report;
    std::mutex mutex;
    view::HttpServer* server_ptr = nullptr;
    view::HttpServerOptions options;
    options.max_request_bytes = 8u << 20;  // the report rides in the query string
    view::HttpServer server(options, [&](const view::HttpRequest& request) {
        const auto parsed = view::parse_request_target(request.target);
        if (parsed && parsed->path == "bench-report") {
            const auto query = view::parse_query(parsed->query);
            const std::lock_guard lock(mutex);
            if (query && query->count("data") && !report) report = query->at("data");
            server_ptr->stop();
            return view::HttpResponse::text(200, "ok");
        }
        return route(request);
    });
    server_ptr = &server;
    std::thread serving([&server] { server.run(); });
    const pid_t browser =
        spawn_browser(tmp, chromium, "http://127.0.0.1:" + std::to_string(server.port()) + target);
    const auto arrived = [&] {
        const std::lock_guard lock(mutex);
        return report.has_value();
    };
    const auto end = Clock::now() + std::chrono::seconds(60);
    while (browser > 0 && !arrived() && Clock::now() < end) {
        if (waiting) waiting();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    server.stop();
    serving.join();
    if (browser > 0) end_child(browser, true);
    if (!report) {
        ADD_FAILURE() << "no report from the page\n" << read_text(tmp / "browser.txt");
        return std::nullopt;
    }
    return nlohmann::json::parse(*report);
}

// `export --format html`: the page with the model inside, in headless Chromium with nothing else: served
// here as a single file by a bare server that knows no viewer routes (only the page and the bench report),
// so the scene, the model, the modules and the sorting worker can only come from the page itself. No
// errors, the worker (started from a blob) sorted, and the views from a fixed camera are the C++ renderer's.
// (Opened from disk the page works the same; headless Chromium's --dump-dom cannot be made to wait for a
// report reliably, so the test serves it. The page puts its report into #lg-report when opened from disk.)
TEST(CliViewBrowser, ExportedPageWorksAlone) {
    const std::optional<std::string> chromium = find_chromium();
    if (!chromium)
        GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/setup.sh does)";
    TempDir tmp("cli_view_page");
    const Camera cam = testing::test_camera(96, 72);
    write_model_and_light(tmp, cam, 400);
    const auto exported = testing::run_lumigauss(
        "export --ply " + testing::shell_quoted(tmp / "model.ply") + " --format html --light " +
            testing::shell_quoted(tmp / "env.txt") + " -o " + testing::shell_quoted(tmp / "page.html"),
        tmp);
    ASSERT_EQ(exported.exit_code, 0) << exported.output;
    EXPECT_NE(exported.output.find("400 surfels and 2 lights in one page"), std::string::npos)
        << exported.output;

    const auto page = std::make_shared<const std::string>(read_text(tmp / "page.html"));
    std::vector<std::string> other_requests;
    std::mutex other_mutex;  // the server answers each connection on its own thread
    const auto route = [&](const view::HttpRequest& request) {
        const auto target = view::parse_request_target(request.target);
        if (target && target->path == "page.html") {
            view::HttpResponse r;
            r.content_type = "text/html; charset=utf-8";
            r.body = *page;
            r.owner = page;
            return r;
        }
        const std::lock_guard lock(other_mutex);
        other_requests.push_back(request.target);
        return view::HttpResponse::text(404, "not here");
    };
    const auto report =
        report_from_page(tmp, *chromium, "/page.html?bench=2&cam=" + camera_param(cam), route);
    ASSERT_TRUE(report);
    for (const std::string& t : other_requests)
        EXPECT_TRUE(t.rfind("/favicon.ico", 0) == 0) << "the page asked the server for " << t;
    const nlohmann::json& r = *report;
    EXPECT_TRUE(r["errors"].empty()) << r["errors"].dump(2);
    ASSERT_FALSE(r.value("failed", false)) << r.dump(2);
    EXPECT_EQ(r["splats"], 400);
    EXPECT_GT(r["sort_ms"]["count"].get<int>(), 0) << "the worker sorted nothing";
    expect_shots_match(tmp, cam, 0, r, {{"shadowed", 40}, {"unshadowed", 40}, {"albedo", 40}});
}

// The page follows a newer model: served by the viewer's own site in this process, which is handed a
// second model once the page has fetched the first; the page (bench mode, &reload=300) polls /version,
// reloads, and renders the new model like the C++ renderer.
TEST(CliViewBrowser, PageReloadsANewerModel) {
    const std::optional<std::string> chromium = find_chromium();
    if (!chromium)
        GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/setup.sh does)";
    TempDir tmp("cli_view_page_reload");
    const Camera cam = testing::test_camera(96, 72);
    write_model_and_light(tmp, cam, 400);
    const auto scene_of = [&](const std::string& ply) {
        const TrainedRun run = load_run_or_ply(ply);
        const ResolvedLight light = resolve_light(tmp / "env.txt", run, PanoramaOptions{});
        return view::scene_json(view::describe_scene(run, {light}, {0, 0, 1}, std::nullopt));
    };
    view::ViewerSite site(view::encode_model_payload(load_relightable_ply(tmp / "model.ply")),
                          scene_of(tmp / "model.ply"), {});
    // The newer model replaces model.ply, which expect_shots_match renders.
    save_relightable_ply(tmp / "model.ply", relight_test::random_model(cam, 33, 300));
    std::atomic<bool> fetched{false};
    bool replaced = false;
    const auto route = [&](const view::HttpRequest& request) {
        const auto target = view::parse_request_target(request.target);
        if (target && target->path == "model.bin") fetched = true;
        return site.handle(request);
    };
    const auto hand_over_the_newer_model = [&] {
        if (!fetched || replaced) return;
        site.replace(view::encode_model_payload(load_relightable_ply(tmp / "model.ply")),
                     scene_of(tmp / "model.ply"));
        replaced = true;
    };
    const auto report = report_from_page(tmp, *chromium, "/?bench=1&reload=300&cam=" + camera_param(cam),
                                         route, hand_over_the_newer_model);
    ASSERT_TRUE(replaced) << "the page never fetched the model\n" << read_text(tmp / "browser.txt");
    ASSERT_TRUE(report);
    const nlohmann::json& r = *report;
    EXPECT_TRUE(r["errors"].empty()) << r["errors"].dump(2);
    EXPECT_EQ(r["splats"], 300);
    EXPECT_EQ(r["reloads"], 1);
    EXPECT_EQ(r["version"], 2);
    expect_shots_match(tmp, cam, 0, r, {{"shadowed", 40}, {"albedo", 40}});
}

// A light with a sky residual (an SH file's "#sky" rows, as fit-light writes them) draws light + residual
// behind the surfels, turned with the light: the page's image is the C++ render's (relight_job.cpp: the sky
// of the turned light plus the residual turned by rotate_sh4), and without the residual it would not be.
TEST(CliViewBrowser, DrawsALightsSkyResidualTurnedWithTheLight) {
    const std::optional<std::string> chromium = find_chromium();
    if (!chromium)
        GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/setup.sh does)";
    TempDir tmp("cli_view_browser_sky");
    const Camera cam = testing::test_camera(96, 72);
    save_relightable_ply(tmp / "model.ply", relight_test::random_model(cam, 21, 60));
    const ShCoeffs<double> light = relight_test::bright_sh(8);
    Sh4Coeffs<float> residual{};
    residual.c[0] = {0.3f, 0.4f, 0.6f};
    residual.c[3] = {0.2f, -0.1f, 0.1f};
    residual.c[13] = {-0.15f, 0.1f, 0.2f};
    residual.c[19] = {0.1f, 0.2f, -0.1f};
    write_sh_text(tmp / "env.txt", light, &residual);
    const double rotate = 30;
    const auto run = run_in_browser(tmp, *chromium, "bench=2&sky&rot=30&cam=" + camera_param(cam));
    ASSERT_TRUE(run);
    const nlohmann::json& r = run->report;
    EXPECT_TRUE(r["errors"].empty()) << r["errors"].dump(2);

    const Vec3d up{0, 0, 1};  // the page's default up for a PLY
    const ShCoeffs<float> env = rotate_about_up(light, up, rotate).cast<float>();
    const Sh4Coeffs<float> turned =
        rotate_sh4(residual, rotation_about_axis(up, rotate * std::numbers::pi / 180));
    const SurfelModel model = load_relightable_ply(tmp / "model.ply");  // the renderer keeps a reference
    RelitRenderer renderer(model);
    const RasterImages<float>& raster = renderer.render(cam, env);
    const Image alpha = alpha_image(raster);
    std::size_t uncovered = 0;
    for (float a : alpha.pixels) uncovered += a < 0.5f;
    ASSERT_GT(uncovered, alpha.pixels.size() / 4) << "the sky must matter";
    const auto over_sky = [&](const Sh4Coeffs<float>* sky_residual) {
        Image im = over_background_image(raster_channels(raster, kRelitShadowed, 3), alpha,
                                         sky_image(cam, env, sky_residual));
        for (float& v : im.pixels) v = std::clamp(v, 0.0f, 1.0f);
        return im;
    };
    const nlohmann::json& shot = r["shots"]["shadowed"];
    const std::vector<unsigned char> rgb = base64_decode(shot["rgb"]);
    const Image want = over_sky(&turned);
    ASSERT_EQ(rgb.size(), want.pixels.size());
    const double p = psnr(rgb, want);
    std::printf("  shadowed over the sky with its residual: PSNR %.1f dB\n", p);
    // 58.9 dB when written; the same light without its residual 19.5 dB, with the residual left unturned
    // 36.4 dB (the camera looks almost along the up axis, where a turn changes the least).
    EXPECT_GE(p, 45.0);
    EXPECT_LT(psnr(rgb, over_sky(nullptr)), 30.0) << "the residual must show";
    EXPECT_LT(psnr(rgb, over_sky(&residual)), 42.0) << "the residual must turn with the light";
}

TEST(CliViewBrowser, EightBitFallbackRendersTheColourViews) {
    const std::optional<std::string> chromium = find_chromium();
    if (!chromium)
        GTEST_SKIP() << "chromium is not installed (apt-get install chromium; scripts/setup.sh does)";
    TempDir tmp("cli_view_browser8");
    const Camera cam = testing::test_camera(96, 72);
    write_model_and_light(tmp, cam, 400);
    const auto run = run_in_browser(tmp, *chromium, "bench=2&target8&cam=" + camera_param(cam));
    ASSERT_TRUE(run);
    const nlohmann::json& r = run->report;
    EXPECT_TRUE(r["errors"].empty()) << r["errors"].dump(2);
    EXPECT_FALSE(r["float_target"].get<bool>());
    // Without a float target every blend step is rounded to 8 bits (and clamped to [0, 1]): a few 1/255 per
    // pixel after a dozen layers. The signed views (normals, shadow) are only approximated there: no bound.
    expect_shots_match(tmp, cam, 0, r, {{"shadowed", 30}, {"unshadowed", 30}, {"albedo", 30}});
}

}  // namespace
}  // namespace lumigauss
