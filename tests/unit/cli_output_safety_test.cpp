// Outputs never damage what the user has (docs/robustness.md "Outputs"): an
// output that is an input (through symlinks and hard links) or another output
// is refused before rendering, with exit 2, one line and nothing written;
// only regular files are replaced; FIFOs, devices and /dev/stdout are written
// in place; a location that cannot be written is found before the render.
// CPU backend, 8×8 at 1 spp: each run takes a few tens of milliseconds.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <thread>

#include <nlohmann/json.hpp>

#include "image/AtomicFile.h"
#include "image/ImageIo.h"
#include "support/AccumulationChecks.h"
#include "util/Error.h"

namespace pyrolume {
namespace {
using namespace pyrolume::test;
namespace fs = std::filesystem;

// A scene that reads an environment map (sky.exr) and a texture (rock.png).
void write_scene(const fs::path& dir) {
  write_image(dir / "sky.exr", make_image(4, 2));
  Image rock = make_image(2, 2);
  for (float& v : rock.rgb) v = 0.5f;
  write_image(dir / "rock.png", rock);
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1},
    "environment": {"file": "sky.exr"},
    "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "rock.png"}}}]})");
}

// Every file and folder under dir, relative, sorted.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir)) names.push_back(fs::relative(e.path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

struct Refusal {
  std::string label, args, expect;
};

// Each refusal: exit 2 before rendering, one line naming the output and the
// reason, nothing written, nothing changed (the inputs keep their bytes).
void expect_refused(const fs::path& dir, const Refusal& c) {
  const std::vector<std::string> before = listing(dir);
  const std::string scene = read_file(dir / "s.json"), sky = read_file(dir / "sky.exr");
  CliResult r = run_cli("render " + q(dir / "s.json") + " --backend cpu " + c.args);
  EXPECT_EQ(r.status, 2) << c.label << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.label << ": " << r.err;
  EXPECT_EQ(r.err.rfind("pyrolume: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.label << ": expected '" << c.expect << "' in " << r.err;
  EXPECT_TRUE(r.out.empty()) << c.label << ": " << r.out;
  EXPECT_EQ(listing(dir), before) << c.label << ": files appeared or vanished";
  EXPECT_EQ(read_file(dir / "s.json"), scene) << c.label;
  EXPECT_EQ(read_file(dir / "sky.exr"), sky) << c.label;
}

TEST(CliOutputSafety, AnOutputThatIsAnInputOrAnotherOutputIsRefusedBeforeRendering) {
  auto dir = temp_dir("out-safety");
  write_scene(dir);
  fs::create_symlink(dir / "s.json", dir / "scene_link.exr");    // -o through a symlink to the scene
  fs::create_hard_link(dir / "sky.exr", dir / "sky_copy.exr");  // the same inode under another name
  fs::create_symlink("rock.png", dir / "rock_link.png");
  const std::string d = dir.string() + "/";
  const Refusal cases[] = {
      {"-o is the environment map", "-o " + q(dir / "sky.exr"), d + "sky.exr: -o: is the same file as environment.file"},
      {"-o is a hard link of it", "-o " + q(dir / "sky_copy.exr"), "-o: is the same file as environment.file"},
      {"-o is a symlink to the scene", "-o " + q(dir / "scene_link.exr"), "-o: is the same file as the scene"},
      {"-o is the texture through a relative symlink", "-o " + q(dir / "rock_link.png"),
       "-o: is the same file as shapes[0].material.diffuse.texture"},
      {"--stats is the scene", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "s.json"),
       "--stats: is the same file as the scene"},
      {"--stats is -o", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "o.exr"), "--stats: is the same file as -o"},
      {"--stats is -o, spelled differently", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "." / "sub/../o.exr"),
       "--stats: is the same file as -o"},
      {"--stats is the checkpoint", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "o.exr.checkpoint"),
       "-o + .checkpoint"},
      {"--stats is the environment map", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "sky.exr"),
       "--stats: is the same file as environment.file"},
  };
  for (const Refusal& c : cases) expect_refused(dir, c);
  fs::remove_all(dir);
}

TEST(CliOutputSafety, OutputLocationsAreCheckedBeforeRendering) {
  auto dir = temp_dir("out-where");
  write_scene(dir);
  fs::create_directory(dir / "taken.json");
  write_file(dir / "plain", "a file, not a folder");
  // A listening Unix socket where --stats should go.
  const int sock = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::string sock_path = (dir / "sock.json").string();
  ASSERT_LT(sock_path.size(), sizeof addr.sun_path);
  std::strcpy(addr.sun_path, sock_path.c_str());
  ASSERT_EQ(::bind(sock, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const Refusal cases[] = {
      {"--stats is a folder", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "taken.json"), "taken.json: is a folder"},
      {"--stats under a file", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "plain/st.json"), "plain"},
      {"-o under a file", "-o " + q(dir / "plain/o.exr"), "plain"},
      {"--stats is a socket", "-o " + q(dir / "o.exr") + " --stats " + q(dir / "sock.json"), "is a socket"},
      // Made for the outputs, then removed again with the refusal.
      {"new folders, then a clash", "-o " + q(dir / "new/deeper/o.exr") + " --stats " + q(dir / "new/deeper/o.exr"),
       "--stats: is the same file as -o"},
  };
  for (const Refusal& c : cases) expect_refused(dir, c);
  ::close(sock);
  if (::geteuid() != 0) {  // root writes anywhere: only an ordinary user can test permissions
    fs::create_directory(dir / "locked");
    fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    expect_refused(dir, {"--stats into a folder nobody may write", "-o " + q(dir / "o.exr") + " --stats " +
                                                                        q(dir / "locked/st.json"),
                         "cannot write in"});
    fs::permissions(dir / "locked", fs::perms::owner_all);
  }
  fs::remove_all(dir);
}

TEST(CliOutputSafety, MissingFoldersAreCreated) {
  auto dir = temp_dir("out-mkdir");
  write_scene(dir);
  CliResult r = run_cli("render " + q(dir / "s.json") + " --backend cpu -o " + q(dir / "a/b/o.exr") + " --stats " +
                        q(dir / "c/st.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_image(dir / "a/b/o.exr").width, 8);
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "c/st.json"))["spp"], 1);
  fs::remove_all(dir);
}

TEST(CliOutputSafety, OnlyRegularFilesAreReplacedSymlinksAndStreamsAreWrittenThrough) {
  auto dir = temp_dir("out-kinds");
  write_scene(dir);
  const std::string base = "render " + q(dir / "s.json") + " --backend cpu -o " + q(dir / "o.exr");

  // A null device: written, and still the character device afterwards. Our
  // own node when we may make one: a broken build must not replace the
  // system's /dev/null (which root could, the very bug this guards against).
  fs::path null_dev = dir / "null";
  if (::mknod(null_dev.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) null_dev = ::geteuid() != 0 ? "/dev/null" : "";
  struct stat st {};
  CliResult r;
  if (!null_dev.empty()) {
    r = run_cli(base + " --stats " + q(null_dev));
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_EQ(::stat(null_dev.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
  }

  // /dev/stdout: the JSON goes to stdout (here a redirected regular file)
  // ahead of the summary line, and the file is not replaced.
  r = run_cli(base + " --stats /dev/stdout");
  ASSERT_EQ(r.status, 0) << r.err;
  const size_t end = r.out.rfind("}\n");
  ASSERT_NE(end, std::string::npos) << r.out;
  EXPECT_EQ(nlohmann::json::parse(r.out.substr(0, end + 2))["width"], 8) << r.out;
  EXPECT_EQ(r.out.substr(end + 2).rfind((dir / "o.exr").string() + ": 8x8", 0), 0u) << r.out;

  // A symlink to a regular file: the file it points to is replaced, the link stays.
  write_file(dir / "real.json", "old");
  fs::create_symlink("real.json", dir / "link.json");
  r = run_cli(base + " --stats " + q(dir / "link.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
  EXPECT_EQ(nlohmann::json::parse(read_file(dir / "real.json"))["spp"], 1);

  // A FIFO: written in place while a reader waits on the other end.
  ASSERT_EQ(::mkfifo((dir / "fifo.json").c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] {
    std::ifstream in(dir / "fifo.json", std::ios::binary);
    received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  r = run_cli(base + " --stats " + q(dir / "fifo.json"));
  if (r.status != 0) ::close(::open((dir / "fifo.json").c_str(), O_WRONLY | O_NONBLOCK));  // release the reader
  reader.join();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(received)["height"], 8) << received;
  ASSERT_EQ(::lstat((dir / "fifo.json").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  fs::remove_all(dir);
}

// A folder on /dev/shm, a tmpfs whose files are regular files though their
// paths start with /dev/; removed when the test ends. Empty where there is no
// writable /dev/shm (the test then skips).
struct ShmDir {
  fs::path path;
  explicit ShmDir(const std::string& tag) {
    std::error_code ec;
    if (!fs::is_directory("/dev/shm", ec) || ::access("/dev/shm", W_OK | X_OK) != 0) return;
    path = fs::path("/dev/shm") / ("pyrolume-" + tag + "-" + std::to_string(::getpid()));
    fs::remove_all(path, ec);
    if (!fs::create_directory(path, ec)) path.clear();
  }
  ~ShmDir() {
    std::error_code ec;
    if (!path.empty()) fs::remove_all(path, ec);
  }
};

// Regular files are replaced by rename wherever they live: on /dev/shm a
// second render used to be appended to the first (readers saw the first
// image) and checkpoints piled up until --resume refused them.
TEST(CliOutputSafety, RegularFilesUnderDevAreReplacedNotAppendedTo) {
  ShmDir shm("out-shm");
  if (shm.path.empty()) GTEST_SKIP() << "no writable /dev/shm here";
  auto dir = temp_dir("out-shm");
  write_scene(dir);
  const fs::path out = shm.path / "o.exr", stats = shm.path / "st.json", ckpt = shm.path / "o.exr.checkpoint";
  const std::string base = "render " + q(dir / "s.json") + " --backend cpu -o " + q(out) + " --stats " + q(stats);
  CliResult r = run_cli(base + " --spp 4");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_image(out).spp_target, 4);
  // Stopped after the first pass (4 spp on the CPU) of 8, twice: each time
  // the image, the stats and a checkpoint of 4 spp replace the last ones.
  std::vector<uintmax_t> checkpoint_bytes;
  for (int run = 0; run < 2; ++run) {
    r = run_cli(base + " --spp 8 --time-limit 1e-9 --checkpoint 1000");
    ASSERT_EQ(r.status, 0) << r.err;
    const Image image = read_image(out);
    EXPECT_EQ(image.spp, 4);
    EXPECT_EQ(image.spp_target, 8) << "run " << run << ": readers still see the first image";
    EXPECT_EQ(nlohmann::json::parse(read_file(stats))["spp_target"], 8) << read_file(stats);
    ASSERT_TRUE(fs::is_regular_file(ckpt)) << r.err;
    checkpoint_bytes.push_back(fs::file_size(ckpt));
  }
  EXPECT_EQ(checkpoint_bytes[1], checkpoint_bytes[0]) << "the second checkpoint piled up on the first";
  // --resume takes the checkpoint and finishes the render.
  r = run_cli(base + " --spp 8 --resume");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_image(out).spp, 8);
  EXPECT_EQ(nlohmann::json::parse(read_file(stats))["resumed_spp"], 4);
  EXPECT_EQ(listing(shm.path), (std::vector<std::string>{"o.exr", "st.json"})) << "temp files or the checkpoint left";
  fs::remove_all(dir);
}

// Runs the CLI as a farm job logs: stdout appended (>>) to `log`.
CliResult run_cli_into_log(const std::string& args, const fs::path& log) {
  const fs::path err = log.parent_path() / "stderr.txt";
  const int raw = std::system((std::string(pyrolume_bin()) + " " + args + " >>" + q(log) + " 2>" + q(err)).c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.err = read_file(err);
  fs::remove(err);
  return r;
}

// --stats that leads to the log stdout is redirected into (/dev/stdout,
// /proc/self/fd/1, a symlink to either, the log by name) adds the JSON to the
// log through stdout: what the log held stays, the summary line follows, and
// nothing is renamed over the log or a link.
TEST(CliOutputSafety, StatsThatLeadToStdoutsLogAddToItNeverReplaceIt) {
  auto dir = temp_dir("out-stdout-log");
  write_scene(dir);
  const fs::path log = dir / "job.log";
  fs::create_symlink("/dev/stdout", dir / "to_stdout.json");
  fs::create_symlink("/proc/self/fd/1", dir / "to_fd1.json");
  const fs::path spellings[] = {"/dev/stdout", "/proc/self/fd/1", dir / "to_stdout.json", dir / "to_fd1.json", log};
  for (const fs::path& stats : spellings) {
    const std::string earlier = "an earlier job's lines\n";
    write_file(log, earlier);
    struct stat before {};
    ASSERT_EQ(::stat(log.c_str(), &before), 0);
    CliResult r = run_cli_into_log("render " + q(dir / "s.json") + " --backend cpu -o " + q(dir / "o.exr") +
                                       " --stats " + q(stats),
                                   log);
    ASSERT_EQ(r.status, 0) << stats << ": " << r.err;
    const std::string text = read_file(log);
    ASSERT_EQ(text.rfind(earlier, 0), 0u) << stats << ": the log lost its content: " << text;
    const size_t end = text.rfind("}\n");
    ASSERT_NE(end, std::string::npos) << stats << ": " << text;
    EXPECT_EQ(nlohmann::json::parse(text.substr(earlier.size(), end + 2 - earlier.size()))["width"], 8) << text;
    EXPECT_EQ(text.substr(end + 2).rfind((dir / "o.exr").string() + ": 8x8", 0), 0u) << stats << ": " << text;
    struct stat after {};
    ASSERT_EQ(::stat(log.c_str(), &after), 0);
    EXPECT_EQ(after.st_ino, before.st_ino) << stats << ": the log was replaced";
  }
  EXPECT_TRUE(fs::is_symlink(dir / "to_stdout.json"));
  EXPECT_TRUE(fs::is_symlink(dir / "to_fd1.json"));

  // Another process's open file, reached through /proc/PID/fd/N, is not ours
  // to write: refused before the render (here this test's own descriptor,
  // which the CLI does not inherit).
  write_file(dir / "theirs.log", "their lines\n");
  const int theirs = ::open((dir / "theirs.log").c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  ASSERT_GE(theirs, 0);
  const fs::path via = "/proc/" + std::to_string(::getpid()) + "/fd/" + std::to_string(theirs);
  CliResult r = run_cli("render " + q(dir / "s.json") + " --backend cpu -o " + q(dir / "o2.exr") + " --stats " + q(via));
  ::close(theirs);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(via.string() + ": "), std::string::npos) << r.err;
  EXPECT_EQ(read_file(dir / "theirs.log"), "their lines\n");
  EXPECT_FALSE(fs::exists(dir / "o2.exr"));
  fs::remove_all(dir);
}

// blackbody --png goes through the same rules as every output: a symlink is
// followed (the file it points to is replaced, the link stays), a FIFO is
// written in place (it used to write its own temp file and rename it over
// whatever was there).
TEST(CliOutputSafety, BlackbodyPngFollowsTheOutputRules) {
  auto dir = temp_dir("out-swatch");
  const std::string args = "blackbody --from 1000 --to 3000 --step 1000 --png ";
  write_file(dir / "real.png", "old");
  fs::create_symlink("real.png", dir / "link.png");
  CliResult r = run_cli(args + q(dir / "link.png"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir / "link.png"));
  EXPECT_EQ(read_file(dir / "real.png").substr(1, 3), "PNG");

  ASSERT_EQ(::mkfifo((dir / "fifo.png").c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] {
    std::ifstream in(dir / "fifo.png", std::ios::binary);
    received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  r = run_cli(args + q(dir / "fifo.png"));
  if (r.status != 0) ::close(::open((dir / "fifo.png").c_str(), O_WRONLY | O_NONBLOCK));  // release the reader
  reader.join();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(received, read_file(dir / "real.png"));  // the same strip
  struct stat st {};
  ASSERT_EQ(::lstat((dir / "fifo.png").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  std::vector<std::string> names;  // by name: listing() would resolve link.png
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"fifo.png", "link.png", "real.png"})) << "temp files left";
  fs::remove_all(dir);
}

TEST(CliOutputSafety, FrameOutputsAreCheckedAgainstEachFramesInputs) {
  auto dir = temp_dir("out-frames");
  write_scene(dir);
  // Frame 1's image would be the environment map (sky_0001.exr).
  fs::copy_file(dir / "sky.exr", dir / "sky_0001.exr");
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1}, "environment": {"file": "sky_0001.exr"}})");
  expect_refused(dir, {"-o pattern hits the environment map", "--frames 1 -o " + q(dir / "sky_####.exr"),
                       "sky_0001.exr: -o: is the same file as environment.file"});
  expect_refused(dir, {"--stats pattern is the -o pattern", "--frames 0-2 -o " + q(dir / "f_####.exr") + " --stats " +
                                                                q(dir / "f_####.exr"),
                       "--stats: is the same file as -o"});
  fs::remove_all(dir);
}

using Texts = std::vector<std::pair<std::string, std::string>>;

// Writes each (file name, text) in dir as one group of outputs: `staged` runs
// while they wait, then the group commits, or, without `commit`, ends as if a
// later output had failed.
void write_texts(const fs::path& dir, const Texts& files, bool commit, const std::function<void()>& staged = [] {}) {
  OutputCommit group;
  for (const auto& [name, text] : files) write_text_atomic(dir / name, text);
  staged();
  if (commit) group.commit();
}

// dir holds these files (sorted by name), with these texts, and nothing else.
void expect_only_texts(const fs::path& dir, const Texts& files) {
  std::vector<std::string> names;
  for (const auto& [name, text] : files) {
    names.push_back(name);
    EXPECT_EQ(read_file(dir / name), text) << name;
  }
  EXPECT_EQ(listing(dir), names);
}

TEST(OutputCommit, OutputsAppearTogetherOrNotAtAll) {
  auto dir = temp_dir("commit");
  write_file(dir / "b.json", "old b");
  const Texts both = {{"a.json", "new a"}, {"b.json", "new b"}};
  write_texts(dir, both, /*commit=*/false, [&] {
    EXPECT_FALSE(fs::exists(dir / "a.json"));  // staged, not yet in place
    EXPECT_EQ(read_file(dir / "b.json"), "old b");
  });
  expect_only_texts(dir, {{"b.json", "old b"}});
  write_texts(dir, both, /*commit=*/true);
  expect_only_texts(dir, both);
  fs::remove_all(dir);
}

// What a second Ctrl-C during a save calls before it exits (host/cli/main.cpp
// on_signal): the temp files not yet renamed into place go; outputs already
// in place, and outputs written after, stay.
TEST(OutputCommit, PendingTempFilesAreRemovedAtOnce) {
  auto dir = temp_dir("pendingtemps");
  write_text_atomic(dir / "done.json", "in place");
  write_texts(dir, {{"a.json", "staged"}, {"b.json", "staged"}}, /*commit=*/false, [&] {
    ASSERT_EQ(listing(dir).size(), 3u) << "two hidden temp files beside done.json";
    remove_pending_temp_files();
    expect_only_texts(dir, {{"done.json", "in place"}});
  });  // the group then finds nothing to remove
  expect_only_texts(dir, {{"done.json", "in place"}});
  write_texts(dir, {{"a.json", "new a"}}, /*commit=*/true);
  remove_pending_temp_files();  // nothing pending: nothing removed
  expect_only_texts(dir, {{"a.json", "new a"}, {"done.json", "in place"}});
  fs::remove_all(dir);
}

TEST(OutputCommit, NothingButARegularFileIsReplaced) {
  auto dir = temp_dir("replace-kinds");
  fs::create_directory(dir / "folder.json");
  try {
    write_text_atomic(dir / "folder.json", "x");
    ADD_FAILURE() << "a folder was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(dir / "folder.json"));
  EXPECT_EQ(listing(dir), std::vector<std::string>{"folder.json"});
  // A symlink loop is refused, not followed forever.
  fs::create_symlink("loop2.json", dir / "loop1.json");
  fs::create_symlink("loop1.json", dir / "loop2.json");
  EXPECT_THROW(write_text_atomic(dir / "loop1.json", "x"), InputError);
  EXPECT_TRUE(fs::is_symlink(dir / "loop1.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
