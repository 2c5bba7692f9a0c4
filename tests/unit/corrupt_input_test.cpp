// Corrupt and truncated input files (docs/robustness.md): each is refused
// with one InputError line that names the file, or read if it is still valid;
// never a crash, a sanitizer report, std::bad_alloc or another exception.
// The regression tests for what tests/fuzz found; every file is written here
// (OpenVDB, OpenEXR) and then damaged.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cstring>
#include <future>
#include <fstream>
#include <sstream>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "geometry/Mesh.h"
#include "image/ImageIo.h"
#include "light/EnvironmentMap.h"
#include "scene/MediumVolume.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "util/Error.h"
#include "volume/VdbInfo.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace corrupt_input {  // a unity batch shares one translation unit: names of its own

namespace fs = std::filesystem;
using Bytes = std::vector<char>;

Bytes read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& p, const Bytes& b, size_t n) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(b.data(), std::streamsize(n));
}

// Where to cut or damage a file of n bytes: every byte of the first 160
// (headers, metadata, descriptors), then about 160 spread over the rest
// (32 under AddressSanitizer, where the VDB damage sweep took 49 s of the
// sanitizer stage with 160; fuzz_vdb and fuzz_image damage the rest there).
std::vector<size_t> sample_positions(size_t n) {
  std::vector<size_t> at;
  for (size_t i = 0; i < n && i < 160; ++i) at.push_back(i);
  const size_t spread = test::address_sanitizer() ? 32 : 160;
  const size_t step = std::max<size_t>(1, (n > 160 ? n - 160 : 0) / spread);
  for (size_t i = 160; i < n; i += step) at.push_back(i);
  return at;
}

// What a bad file may do: throw InputError "FILE: ..." on one line. Returns
// the message ("" when the file was read).
template <class F>
std::string outcome(const fs::path& p, F&& read) {
  try {
    read();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(p.string(), 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    return msg;
  }
  return "";
}

// ---- VDB ----

// A damaged root origin can spread the few voxels over a legitimately huge
// box: refuse it (InputError) instead of filling gigabytes.
struct DenseLimit {
  DenseLimit() { set_max_dense_texels(uint64_t(1) << 24); }
} const dense_limit_once;

fs::path small_vdb(const fs::path& dir, test::VdbCompression compression) {
  return test::write_reader_paths_vdb(dir / "small.vdb", compression);
}

std::string vdb_outcome(const fs::path& p) {
  std::string msg;
  for (bool values : {false, true}) {
    std::ostringstream out;
    msg += outcome(p, [&] { run_info_command(p, values, out); });
  }
  Medium m = test::vdb_file_medium(p);
  return msg + outcome(p, [&] { load_volume(m, true); });
}

TEST(CorruptVdb, TheUndamagedFileLoads) {
  const auto dir = test::temp_dir("vdbok");
  for (test::VdbCompression c : {test::VdbCompression::ZipActiveMask, test::VdbCompression::Blosc,
                                  test::VdbCompression::None})
    EXPECT_EQ(vdb_outcome(small_vdb(dir, c)), "") << "compression " << int(c);
}

// Found by fuzz_vdb: OpenVDB sized a string by its 4-byte length field
// (here the first file metadata name's) and allocated 2 GB for a 500-byte file.
TEST(CorruptVdb, HugeMetadataStringLengthIsAnInputError) {
  const auto dir = test::temp_dir("vdbstr");
  const fs::path p = small_vdb(dir, test::VdbCompression::None);
  Bytes b = read_bytes(p);
  // magic 8, version 4, library version 8, offsets flag 1, UUID 36, count 4
  const size_t at = 8 + 4 + 8 + 1 + 36 + 4;
  const uint32_t huge = 0x7ffffff0;
  std::memcpy(b.data() + at, &huge, 4);
  write_bytes(p, b, b.size());
  const std::string msg = vdb_outcome(p);
  EXPECT_NE(msg.find("metadata name claims 2147483632 bytes"), std::string::npos) << msg;
}

// Found by fuzz_vdb: a tab inside the file's UUID failed OpenVDB's stream
// (boost reads the UUID with operator>>), and its later reads left their
// values unset: a transform name's length from uninitialised memory asked for
// 4 GiB. Every byte of the UUID is checked; a damaged one is refused, naming
// the byte, and an undamaged UUID in capitals (OpenVDB 11 writes those) loads.
TEST(CorruptVdb, AUuidOpenVdbCannotParseIsAnInputError) {
  const auto dir = test::temp_dir("vdbuuid");
  const fs::path p = small_vdb(dir, test::VdbCompression::None);
  const Bytes good = read_bytes(p);
  const size_t at = 8 + 4 + 8 + 1;  // magic, version, library version, offsets flag
  Bytes upper = good;
  for (size_t i = at; i < at + 36; ++i) upper[i] = char(std::toupper(static_cast<unsigned char>(upper[i])));
  write_bytes(p, upper, upper.size());
  EXPECT_EQ(vdb_outcome(p), "");
  for (size_t i = 0; i < 36; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    for (char v : {'\t', ' ', dash ? 'a' : '-', dash ? '-' : 'g'}) {
      if (v == good[at + i]) continue;
      Bytes b = good;
      b[at + i] = v;
      write_bytes(p, b, b.size());
      const std::string msg = vdb_outcome(p);
      EXPECT_NE(msg.find("file UUID is not 32 hex digits in the 8-4-4-4-12 form (byte " + std::to_string(i) + ")"),
                std::string::npos)
          << "byte " << i << " = " << int(v) << ": " << msg;
    }
  }
}

TEST(CorruptVdb, EveryTruncationIsAnInputError) {
  const auto dir = test::temp_dir("vdbcut");
  for (test::VdbCompression c : {test::VdbCompression::ZipActiveMask, test::VdbCompression::Blosc}) {
    const fs::path good = small_vdb(dir, c);
    const Bytes b = read_bytes(good);
    const fs::path p = dir / "cut.vdb";
    for (size_t n : sample_positions(b.size())) {
      write_bytes(p, b, n);
      Medium m = test::vdb_file_medium(p);
      EXPECT_NE(outcome(p, [&] { load_volume(m, true); }), "") << "cut at " << n << " of " << b.size();
      std::ostringstream out;
      EXPECT_NE(outcome(p, [&] { run_info_command(p, false, out); }), "") << "cut at " << n;
    }
  }
}

// Each byte in turn replaced by 0xff and by 0x7f: lengths, counts, offsets,
// masks, chunk sizes and Blosc headers all get hit. Under AddressSanitizer
// (three reads a file at ~15 ms each) a byte gets one of the two, in turn.
TEST(CorruptVdb, EveryDamagedByteIsReadOrRefused) {
  const auto dir = test::temp_dir("vdbflip");
  for (test::VdbCompression c : {test::VdbCompression::ZipActiveMask, test::VdbCompression::Blosc}) {
    const Bytes good = read_bytes(small_vdb(dir, c));
    const fs::path p = dir / "flip.vdb";
    int refused = 0, tried = 0;
    for (size_t i : sample_positions(good.size()))
      for (char v : {char(0xff), char(0x7f)}) {
        if (good[i] == v) continue;
        if (test::address_sanitizer() && (v == char(0xff)) != (i % 2 == 0)) continue;
        Bytes b = good;
        b[i] = v;
        write_bytes(p, b, b.size());
        refused += !vdb_outcome(p).empty();
        ++tried;
      }
    // Not every byte matters (values, UUID, padding), but most framing does.
    EXPECT_GT(refused, tried / 4);
  }
}

// ---- EXR ----

fs::path small_exr(const fs::path& dir, Imf::Compression compression) {
  const int w = 5, h = 4;
  Imf::Header header(w, h);
  header.compression() = compression;
  std::vector<float> px(size_t(w) * h * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = 0.1f * float(i % 17);
  Imf::FrameBuffer fb;
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(px.data() + c), 12, 12 * w));
  }
  const fs::path p = dir / "small.exr";
  Imf::OutputFile out(p.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(h);
  return p;
}

// Finds an attribute's value in an EXR header by name.
size_t attribute_value(const Bytes& b, const std::string& name) {
  const std::string key = name + '\0';
  const size_t at = std::string(b.begin(), b.end()).find(key);
  EXPECT_NE(at, std::string::npos) << name;
  size_t p = at + key.size();
  while (b[p] != 0) ++p;  // type name
  return p + 1 + 4;        // past the size
}

// A data window of 2^31 - 1 square pixels in a 300-byte file: OpenEXR sized
// its line-offset table and buffers from it before reading any pixel.
TEST(CorruptExr, HugeDataWindowIsAnInputError) {
  const auto dir = test::temp_dir("exrdw");
  const fs::path p = small_exr(dir, Imf::ZIP_COMPRESSION);
  Bytes b = read_bytes(p);
  const int32_t big = 0x7fffffff;
  const size_t v = attribute_value(b, "dataWindow");
  std::memcpy(b.data() + v + 8, &big, 4);
  std::memcpy(b.data() + v + 12, &big, 4);
  write_bytes(p, b, b.size());
  const std::string msg = outcome(p, [&] { read_image(p); });
  EXPECT_NE(msg.find("corrupt EXR: data window"), std::string::npos) << msg;
}

TEST(CorruptExr, EveryTruncationAndDamagedByteIsReadOrRefused) {
  const auto dir = test::temp_dir("exrflip");
  for (Imf::Compression c : {Imf::ZIP_COMPRESSION, Imf::PIZ_COMPRESSION, Imf::NO_COMPRESSION}) {
    const Bytes good = read_bytes(small_exr(dir, c));
    EXPECT_EQ(outcome(dir / "small.exr", [&] { EnvironmentMap::load(dir / "small.exr"); }), "");
    const fs::path p = dir / "bad.exr";
    for (size_t n : sample_positions(good.size())) {
      write_bytes(p, good, n);
      EXPECT_NE(outcome(p, [&] { read_image(p); }), "") << "cut at " << n;
    }
    for (size_t i : sample_positions(good.size()))
      for (char v : {char(0xff), char(0x7f)}) {
        Bytes b = good;
        b[i] = v;
        write_bytes(p, b, b.size());
        outcome(p, [&] { EnvironmentMap::load(p); });
      }
  }
}

// Found by fuzz_image: stb_image "decodes" a truncated TGA as zeros, so a
// 61-byte header claiming 20000 x 20000 pixels became 4.5 GB of floats.
TEST(CorruptImage, TruncatedTgaWithHugeHeaderIsAnInputError) {
  const auto dir = test::temp_dir("tga");
  // Uncompressed true-colour TGA header: 18 bytes, width and height at 12 and 14.
  Bytes b(61, 0);
  b[2] = 2;
  const uint16_t side = 20000;
  std::memcpy(b.data() + 12, &side, 2);
  std::memcpy(b.data() + 14, &side, 2);
  b[16] = 24;
  const fs::path p = dir / "huge.tga";
  write_bytes(p, b, b.size());
  const std::string msg = outcome(p, [&] { read_image(p); });
  EXPECT_NE(msg.find("image header claims 20000 x 20000 pixels"), std::string::npos) << msg;
}

// ---- OBJ ----

// load_obj ignores materials, so it must not open what a `mtllib` line names:
// tinyobjloader's ParseFromFile did, and a FIFO (or /dev/zero) there blocked
// (or read) forever. Here the FIFO has no writer: opening it would block.
TEST(CorruptObj, MtllibIsNotOpened) {
  const auto dir = test::temp_dir("objmtl");
  const fs::path fifo = dir / "m.mtl";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const fs::path obj = dir / "m.obj";
  test::write_file(obj, "mtllib m.mtl\nusemtl stone\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  auto done = std::async(std::launch::async, [&] { return geometry::load_obj(obj).triangles.size(); });
  const bool finished = done.wait_for(std::chrono::seconds(20)) == std::future_status::ready;
  if (!finished) {  // unblock the reader so the test can end (and fail)
    const int fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) close(fd);
  }
  EXPECT_TRUE(finished) << "load_obj opened the mtllib FIFO";
  EXPECT_EQ(done.get(), 1u);
}

// load_obj hands tinyobjloader only v, vn, vt, f, o and g lines. Its `vw`
// parser converts a float joint id to int: 1e35 is undefined behaviour (UBSan
// float-cast-overflow under tools/sanitize; fuzz_obj found it). The dropped
// lines must not change the mesh, and every kind of line end must still split
// lines (CRLF, lone CR, LF, none at the end).
TEST(CorruptObj, StatementsPyrolumeIgnoresAreNotParsed) {
  const auto dir = test::temp_dir("objskip");
  const fs::path obj = dir / "skip.obj";
  test::write_file(obj,
                   "# skin weights, tags, smoothing, lines, points, materials\r\n"
                   "vw 1 1e35 0.5\r\n"
                   "t crease 2/1/0 1 2 4.5\r"
                   "s 1\n"
                   "usemtl rock\r\n"
                   "  v 0 0 0\r"
                   "v 1 0 0\r\n"
                   "v 0 1 0\n"
                   "\tv 1 1 0\n"
                   "l 1 2\n"
                   "p 3\n"
                   "g top\n"
                   "f 1 2 3\r\n"
                   "f 2 4 3");
  const geometry::Mesh mesh = geometry::load_obj(obj);
  EXPECT_EQ(mesh.positions.size(), 4u);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[1][1].position, 3u);
  EXPECT_EQ(mesh.positions[3], glm::vec3(1, 1, 0));
}

// Dropped lines are blanked, not removed: tinyobjloader's line numbers still
// point into the user's file.
TEST(CorruptObj, ParseErrorsKeepTheFilesLineNumbers) {
  const auto dir = test::temp_dir("objline");
  const fs::path obj = dir / "zero.obj";
  test::write_file(obj, "mtllib a.mtl\r\nusemtl a\rs off\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  const std::string msg = outcome(obj, [&] { geometry::load_obj(obj); });
  EXPECT_NE(msg.find("line 7"), std::string::npos) << msg;
}

}  // namespace corrupt_input
}  // namespace pyrolume
