// The MP4 step of the relighting tool (relight/video.h): shell quoting survives any file name, '%' in paths
// is escaped for ffmpeg's image pattern, and encode_video renames a finished encode into place and leaves
// nothing behind when the encoder fails (checked with stand-in `ffmpeg` scripts, so no ffmpeg is needed);
// where ffmpeg is installed (scripts/setup.sh installs it), a real encode is read back with ffprobe.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lumigauss/io/image.h"
#include "lumigauss/relight/video.h"
#include "support/temp_dir.h"

namespace lumigauss {
namespace {

using lumigauss::testing::TempDir;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string read_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

void write_script(const std::string& path, const std::string& body) {
    {
        std::ofstream f(path);
        f << "#!/bin/sh\n" << body;
    }
    ::chmod(path.c_str(), 0755);
}

TEST(RelightVideo, ShellQuotingSurvivesAwkwardNames) {
    TempDir tmp("relight_quote");
    for (const std::string s : {"plain", "with space", "it's", "a'b'c", "$HOME `x` \"q\" \\ ; & | *", ""}) {
        const std::string out = tmp / "out.txt";
        const std::string cmd = "printf '%s' " + shell_quote(s) + " > " + shell_quote(out);
        ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
        EXPECT_EQ(read_file(out), s);
    }
    EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
}

TEST(RelightVideo, PercentIsEscapedForThePattern) {
    EXPECT_EQ(escape_percent("a%b/c%%d"), "a%%b/c%%%%d");
    EXPECT_EQ(escape_percent("plain"), "plain");
}

TEST(RelightVideo, CommandLine) {
    const std::string cmd =
        ffmpeg_command("/usr/bin/ffmpeg", "out dir/x_%03d_shadowed.png", "out dir/x.mp4", 15);
    EXPECT_THAT(cmd, HasSubstr("'/usr/bin/ffmpeg'"));
    EXPECT_THAT(cmd, HasSubstr("-framerate 15"));
    EXPECT_THAT(cmd, HasSubstr("-i 'out dir/x_%03d_shadowed.png'"));
    EXPECT_THAT(cmd, HasSubstr("-pix_fmt yuv420p"));
    EXPECT_THAT(cmd, HasSubstr("'out dir/x.mp4'"));
}

TEST(RelightVideo, FindsExecutablesOnThePath) {
    EXPECT_FALSE(find_on_path("sh").empty());
    EXPECT_TRUE(find_on_path("lumigauss-no-such-program-xyz").empty());
}

TEST(RelightVideo, EncodeRenamesIntoPlaceOrLeavesNothing) {
    TempDir tmp("relight_encode");
    // A stand-in encoder writing its last argument (the output file).
    const std::string good = tmp / "good-ffmpeg";
    write_script(good, "for a in \"$@\"; do last=$a; done\necho video > \"$last\"\n");
    const std::string out = tmp / "it's a video.mp4";
    EXPECT_TRUE(encode_video(good, tmp / "f_%03d.png", out, 15));
    EXPECT_EQ(read_file(out), "video\n");
    EXPECT_FALSE(fs::exists(out + ".tmp.mp4"));

    // A failing encoder that still leaves a partial file: nothing stays behind.
    const std::string bad = tmp / "bad-ffmpeg";
    write_script(bad, "for a in \"$@\"; do last=$a; done\necho partial > \"$last\"\nexit 1\n");
    const std::string out2 = tmp / "second.mp4";
    EXPECT_FALSE(encode_video(bad, tmp / "f_%03d.png", out2, 15));
    EXPECT_FALSE(fs::exists(out2));
    EXPECT_FALSE(fs::exists(out2 + ".tmp.mp4"));
}

// The real encoder: odd-sized frames come out as an MP4 (ISO base media: an `ftyp` box first) of even size
// with every frame, and the frames' order survives (a bright square moves across).
TEST(RelightVideo, RealFfmpegEncodesEveryFrame) {
    const std::string ffmpeg = find_on_path("ffmpeg");
    if (ffmpeg.empty()) GTEST_SKIP() << "ffmpeg is not installed (scripts/setup.sh installs it)";
    TempDir tmp("relight_ffmpeg");
    const int frames = 5, width = 33, height = 21;
    for (int k = 0; k < frames; ++k) {
        Image frame(width, height, 3, 0.1f);
        for (int y = 8; y < 14; ++y)
            for (int x = 4 * k; x < 4 * k + 6; ++x)
                for (int c = 0; c < 3; ++c) frame.at(x, y, c) = 0.9f;
        char name[32];
        std::snprintf(name, sizeof name, "f %% %03d.png", k);
        write_png(tmp / name, frame);
    }
    const std::string out = tmp / "turn table.mp4";
    ASSERT_TRUE(encode_video(ffmpeg, escape_percent(tmp / "f % ") + "%03d.png", out, 15));
    const std::string bytes = read_file(out);
    ASSERT_GT(bytes.size(), 8u);
    EXPECT_EQ(bytes.substr(4, 4), "ftyp");
    EXPECT_FALSE(fs::exists(out + ".tmp.mp4"));

    const std::string ffprobe = find_on_path("ffprobe");
    if (ffprobe.empty()) return;
    const std::string probe = tmp / "probe.txt";
    const std::string cmd = shell_quote(ffprobe) +
                            " -v error -count_frames -select_streams v:0 -show_entries "
                            "stream=width,height,nb_read_frames -of csv=p=0 " +
                            shell_quote(out) + " > " + shell_quote(probe);
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_EQ(read_file(probe), "34,22,5\n");  // padded to even sizes, all five frames

    // The last frame decoded: the square is where frame 4 had it, not where frame 0 did.
    const std::string last = tmp / "last.png";
    const std::string decode = shell_quote(ffmpeg) + " -v error -i " + shell_quote(out) +
                               " -vf 'select=eq(n\\,4)' -frames:v 1 " + shell_quote(last);
    ASSERT_EQ(std::system(decode.c_str()), 0) << decode;
    const Image decoded = read_image(last);
    ASSERT_EQ(decoded.width, 34);
    EXPECT_GT(decoded.at(18, 10, 1), 0.7f);  // inside frame 4's square (x 16..21)
    EXPECT_LT(decoded.at(2, 10, 1), 0.3f);   // inside frame 0's square only
}

}  // namespace
}  // namespace lumigauss
