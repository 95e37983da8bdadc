// The MP4 step of the relighting tool (relight/video.h): shell quoting survives any file name, '%' in paths
// is escaped for ffmpeg's image pattern, and encode_video renames a finished encode into place and leaves
// nothing behind when the encoder fails (checked with stand-in `ffmpeg` scripts, so no ffmpeg is needed).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

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

}  // namespace
}  // namespace lumigauss
