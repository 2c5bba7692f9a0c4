#include "render/Checkpoint.h"

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "image/AtomicFile.h"
#include "scene/Scene.h"
#include "util/Error.h"
#include "util/InputFile.h"
#include "util/Json.h"
#include "util/Memory.h"

namespace pyrolume {
namespace fs = std::filesystem;

namespace {

constexpr const char* kMagic = "pyrolume-checkpoint 2";
constexpr const char* kMagicV1 = "pyrolume-checkpoint 1";  // still read: its checksum covers the payload only
constexpr size_t kMaxHeaderChars = 64 * 1024;  // the JSON line; a real one is ~300 characters

uint64_t fnv1a(const void* data, size_t n, uint64_t h = 0xcbf29ce484222325ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

// FNV-1a 64 of the magic line and the JSON line, each with its '\n': where a
// version 2 checksum starts before it goes on over the payload.
uint64_t header_hash(const std::string& magic, const std::string& header) {
  const std::string lines = magic + "\n" + header + "\n";
  return fnv1a(lines.data(), lines.size());
}

}  // namespace

fs::path checkpoint_path(const fs::path& output) {
  fs::path p = output;
  p += ".checkpoint";
  return p;
}

uint64_t scene_fingerprint(const fs::path& scene_file) {
  // A bare volume is the shortest scene naming it (load_scene), not its voxels.
  const std::string text = is_volume_file(scene_file) ? shortest_scene_text(scene_file)
                                                      : read_input_file(scene_file, kMaxSceneBytes, "scene", 10.0);
  std::string canonical = text;
  try {
    canonical = nlohmann::json::parse(text, nullptr, true, /*ignore_comments=*/true).dump();
  } catch (const nlohmann::json::exception&) {
  }
  return fnv1a(canonical.data(), canonical.size());
}

void write_checkpoint(const fs::path& file, const CheckpointIdentity& id, int spp_target,
                      const AccumulationState& state) {
  nlohmann::ordered_json j;
  j["backend"] = id.backend;
  j["device"] = id.device;
  j["scene"] = id.scene;
  j["scene_hash"] = id.scene_hash;
  j["width"] = id.width;
  j["height"] = id.height;
  j["seed"] = id.seed;
  j["frame"] = id.frame;
  j["spp"] = state.spp;
  j["spp_target"] = spp_target;
  j["payload_bytes"] = state.data.size();
  const std::string json_line = j.dump();
  const std::string header = std::string(kMagic) + "\n" + json_line + "\n";
  if (state.backend != id.backend || state.width != id.width || state.height != id.height)
    throw std::logic_error("write_checkpoint: the state does not match the identity");
  const uint64_t sum = fnv1a(state.data.data(), state.data.size(), header_hash(kMagic, json_line));
  unsigned char trailer[8];
  for (int i = 0; i < 8; ++i) trailer[i] = static_cast<unsigned char>(sum >> (8 * i));
  write_file_atomic(file, [&](std::ostream& os) {
    os.write(header.data(), std::streamsize(header.size()));
    os.write(reinterpret_cast<const char*>(state.data.data()), std::streamsize(state.data.size()));
    os.write(reinterpret_cast<const char*>(trailer), 8);
  });
}

// A checkpoint whose payload size disagrees with its backend's layout
// (payload_bytes) is refused here, with its file name, not deep in a backend.
Checkpoint read_checkpoint(const fs::path& file, const PayloadBytes& payload_bytes) {
  const std::string name = file.string();
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (fs::exists(status) && !fs::is_regular_file(status))
    throw input_error(name, "", "is not a regular file, so not a checkpoint");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw input_error(name, "", std::string("cannot open checkpoint: ") + std::strerror(errno));
  const uint64_t file_size = fs::file_size(file, ec);
  if (ec) throw input_error(name, "", "cannot read checkpoint: " + ec.message());
  // Both lines are read with a bound: a file of zeros has no line end.
  auto read_line = [&](size_t max_chars, std::string& line) {
    line.clear();
    for (char c; in.get(c);) {
      if (c == '\n') return true;
      if (line.size() == max_chars) return false;
      line.push_back(c);
    }
    return false;
  };
  std::string magic, header;
  if (!read_line(64, magic) || (magic != kMagic && magic != kMagicV1))
    throw input_error(name, "", "not a pyrolume checkpoint (version 1 or 2)");
  if (!read_line(kMaxHeaderChars, header)) throw input_error(name, "", "truncated checkpoint (no complete header)");
  const bool v1 = magic == kMagicV1;
  Checkpoint c;
  uint64_t bytes = 0;
  try {
    const auto j = parse_json_unique_keys(header, name);
    CheckpointIdentity& id = c.identity;
    id.backend = j.at("backend").get<std::string>();
    id.device = j.at("device").get<std::string>();
    id.scene = j.at("scene").get<std::string>();
    id.scene_hash = j.at("scene_hash").get<uint64_t>();
    id.width = j.at("width").get<int>();
    id.height = j.at("height").get<int>();
    id.seed = j.at("seed").get<uint32_t>();
    id.frame = j.at("frame").get<uint32_t>();
    c.state.spp = j.at("spp").get<int>();
    c.spp_target = j.at("spp_target").get<int>();
    bytes = j.at("payload_bytes").get<uint64_t>();
  } catch (const nlohmann::json::exception& e) {
    throw input_error(name, "", std::string("corrupt checkpoint header: ") + e.what());
  }
  const CheckpointIdentity& id = c.identity;
  // spp 0: saved before the first pass ended.
  if (id.width < 1 || id.height < 1 || id.width > kMaxFilmSide || id.height > kMaxFilmSide ||
      (c.state.spp != 0 && !spp_in_range(c.state.spp)))
    throw input_error(name, "", "corrupt checkpoint header: impossible width, height or spp");
  if (payload_bytes(id.backend, id.width, id.height) == 0)
    throw input_error(name, "backend", "unknown backend \"" + id.backend + "\"");
  if (bytes != payload_bytes(id.backend, id.width, id.height))
    throw input_error(name, "", "corrupt checkpoint, or one from another pyrolume version: " + std::to_string(bytes) +
                                    " payload bytes where a " + std::to_string(id.width) + "x" +
                                    std::to_string(id.height) + " " + id.backend + " render has " +
                                    std::to_string(payload_bytes(id.backend, id.width, id.height)) +
                                    " (render again without --resume)");
  // The header's claim against the file before anything is allocated by it: a
  // forged 16384² header in a small file is refused here, not after 16 GiB.
  const uint64_t expected = magic.size() + 1 + header.size() + 1 + bytes + 8;
  if (file_size < expected)
    throw input_error(name, "", "truncated checkpoint: the header describes " + std::to_string(expected) +
                                    " bytes, the file has " + std::to_string(file_size));
  if (file_size > expected)
    throw input_error(name, "", "corrupt checkpoint: " + std::to_string(file_size - expected) +
                                    " trailing bytes past what the header describes");
  require_memory(name, "", "this checkpoint's accumulation", bytes);
  c.state.backend = id.backend;
  c.state.width = id.width;
  c.state.height = id.height;
  c.state.data.resize(bytes);
  unsigned char trailer[8];
  in.read(reinterpret_cast<char*>(c.state.data.data()), std::streamsize(bytes));
  in.read(reinterpret_cast<char*>(trailer), 8);
  if (!in) throw input_error(name, "", "truncated checkpoint");
  if (in.peek() != std::char_traits<char>::eof()) throw input_error(name, "", "corrupt checkpoint: trailing bytes");
  uint64_t sum = 0;
  for (int i = 0; i < 8; ++i) sum |= uint64_t(trailer[i]) << (8 * i);
  // Version 2 sums the two header lines too (a flipped bit in "spp" is
  // caught); version 1 summed the payload only.
  const uint64_t expect = v1 ? fnv1a(c.state.data.data(), c.state.data.size())
                             : fnv1a(c.state.data.data(), c.state.data.size(), header_hash(magic, header));
  if (sum != expect) throw input_error(name, "", "corrupt checkpoint: checksum mismatch (header or payload damaged)");
  return c;
}

void check_resumable(const fs::path& file, const Checkpoint& saved, const CheckpointIdentity& now, int spp_target) {
  const std::string name = file.string();
  const CheckpointIdentity& was = saved.identity;
  auto refuse = [&](const std::string& key, const std::string& then, const std::string& today) {
    throw input_error(name, key,
                      "the checkpoint was made with " + key + " " + then + ", this render has " + today +
                          " (delete the checkpoint or render without --resume)");
  };
  if (was.scene_hash != now.scene_hash)
    throw input_error(name, "scene",
                      "the checkpoint was made from a different scene (" + was.scene + " as it was then); " + now.scene +
                          " has changed or is another file (delete the checkpoint or render without --resume)");
  if (was.backend != now.backend) refuse("backend", was.backend, now.backend);
  if (was.width != now.width) refuse("width", std::to_string(was.width), std::to_string(now.width));
  if (was.height != now.height) refuse("height", std::to_string(was.height), std::to_string(now.height));
  if (was.seed != now.seed) refuse("seed", std::to_string(was.seed), std::to_string(now.seed));
  if (was.frame != now.frame) refuse("frame", std::to_string(was.frame), std::to_string(now.frame));
  if (saved.state.spp > spp_target)
    throw input_error(name, "spp",
                      "the checkpoint already has " + std::to_string(saved.state.spp) + " spp, more than the " +
                          std::to_string(spp_target) + " asked for");
}

}  // namespace pyrolume
