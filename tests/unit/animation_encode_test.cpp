// tools/encode: a PNG sequence to MP4 with Debian's ffmpeg (skipped when
// ffmpeg is not installed), and a clear message when it is missing.
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "image/ImageIo.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {
const std::string kEncode = std::string(PYROLUME_SOURCE_DIR) + "/tools/encode";

int shell(const std::string& cmd) {
  int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}
}  // namespace

TEST(AnimationEncode, SaysSoWhenFfmpegIsMissing) {
  fs::path dir = temp_dir("encode-missing");
  // A PATH without ffmpeg (the script checks with shell builtins only).
  int status = shell("env PATH=/nonexistent /bin/bash '" + kEncode + "' 'f_####.png' o.mp4 2>'" +
                     (dir / "err.txt").string() + "'");
  EXPECT_EQ(status, 1);
  EXPECT_NE(read_file(dir / "err.txt").find("ffmpeg is not installed"), std::string::npos) << read_file(dir / "err.txt");
}

TEST(AnimationEncode, PngSequenceBecomesAnMp4) {
  if (shell("command -v ffmpeg >/dev/null 2>&1") != 0) GTEST_SKIP() << "ffmpeg is not installed";
  fs::path dir = temp_dir("encode");
  // Frames 5..7 (a farm chunk need not start at 1), odd size (yuv420p needs even: the tool scales).
  for (int f = 5; f <= 7; ++f) {
    Image img = make_image(33, 17);
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = float((i + size_t(f) * 7) % 13) / 13.0f;
    char name[32];
    std::snprintf(name, sizeof name, "f_%04d.png", f);
    write_image(dir / name, img);
  }
  const fs::path mp4 = dir / "movie.mp4";
  EXPECT_EQ(shell("'" + kEncode + "' '" + (dir / "f_####.png").string() + "' '" + mp4.string() + "' --fps 12 >/dev/null"), 0);
  ASSERT_TRUE(fs::exists(mp4));
  EXPECT_GT(fs::file_size(mp4), 0u);
  if (shell("command -v ffprobe >/dev/null 2>&1") == 0) {
    const fs::path count = dir / "count.txt";
    ASSERT_EQ(shell("ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames "
                    "-of csv=p=0 '" + mp4.string() + "' >'" + count.string() + "'"),
              0);
    EXPECT_EQ(std::stoi(read_file(count)), 3);
  }
  // No frames: exit 2.
  EXPECT_EQ(shell("'" + kEncode + "' '" + (dir / "none_####.png").string() + "' '" + (dir / "x.mp4").string() +
                  "' 2>/dev/null"),
            2);
}
