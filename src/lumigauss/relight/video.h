#pragma once
// MP4s of rendered frame sequences through an installed `ffmpeg` (nothing is linked; without ffmpeg on the
// PATH no video is made). Frames are numbered PNGs (printf-style pattern with one %0Nd); the video is written
// to a temporary name and renamed, so a failed encode leaves no half-written MP4.
#include <string>

namespace lumigauss {

// The full path of an executable file `name` found in the directories of $PATH, or "" if none.
std::string find_on_path(const std::string& name);

// `s` as one POSIX shell word: single-quoted, with every ' written as '\''.
std::string shell_quote(const std::string& s);

// '%' doubled, so that a path can be embedded in an ffmpeg image2 pattern literally.
std::string escape_percent(const std::string& s);

// The ffmpeg command line that encodes `pattern` (e.g. "out/orbit_%03d_shadowed.png") at `fps` frames per
// second into `output` (.mp4): H.264-compatible yuv420p, sizes padded to even, quiet, overwrite.
std::string ffmpeg_command(const std::string& ffmpeg, const std::string& pattern, const std::string& output,
                           int fps);

// Runs ffmpeg_command into output + ".tmp.mp4", then renames it to `output`. Returns false (and removes the
// temporary file) when ffmpeg fails.
bool encode_video(const std::string& ffmpeg, const std::string& pattern, const std::string& output, int fps);

}  // namespace lumigauss
