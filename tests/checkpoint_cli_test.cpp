// `nimbus render --checkpoint / --resume` run as a program (issue 15): a render killed outright
// and resumed, or stopped by Ctrl-C and resumed, or continued to more samples, writes the same
// pixels as one render; a checkpoint of other settings is refused.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "nimbus/job/checkpoint.h"
#include "support/process.h"
#include "support/sanitizer.h"

namespace nimbus {
namespace checkpoint_cli_test {

namespace fs = std::filesystem;
using namespace nimbus::test;

// A small scene with a medium: 24 x 16 pixels.
constexpr const char* kScene = R"({
  "film": {"width": 24, "height": 16},
  "camera": {"type": "perspective", "from": [0, 1, 6], "to": [0, 0, 0], "fov": 35},
  "integrator": {"spp": 4, "seed": 7},
  "lights": [{"type": "environment", "radiance": [0.8, 0.9, 1.0]},
             {"type": "directional", "direction": [-0.5, -1, -0.4], "irradiance": 3}],
  "media": {"fog": {"sigma_a": 0.2, "sigma_s": [3, 4, 5], "density": {"type": "field"}}},
  "objects": [
    {"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1.5}, "medium": "fog"},
    {"shape": {"type": "box", "min": [-5, -1.6, -5], "max": [5, -1.5, 5]},
     "surface": {"type": "diffuse", "albedo": 0.5}}
  ]
})";

class Checkpoints : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_test_dir("nimbus_ckcli");
    std::ofstream(dir_ / "scene.json") << kScene;
  }
  void TearDown() override { fs::remove_all(dir_); }
  Ran nimbus(const std::string& args) {
    return run_nimbus_in(dir_, "render scene.json -q " + args);
  }
  // A render of 300 spp on one thread, checkpointed every 0.05 s, started in the background;
  // returns once its first checkpoint is written.
  pid_t start_checkpointed_render(const std::vector<std::string>& outputs) {
    std::vector<std::string> argv = {NIMBUS_BINARY,
                                     "render",
                                     "scene.json",
                                     "-q",
                                     "--spp",
                                     "300",
                                     "--threads",
                                     "1",
                                     "--checkpoint",
                                     "ck.nck",
                                     "--checkpoint-interval",
                                     "0.05"};
    argv.insert(argv.end(), outputs.begin(), outputs.end());
    const pid_t pid = spawn_in(dir_, argv);
    EXPECT_TRUE(wait_for_file(dir_ / "ck.nck"));
    return pid;
  }
  fs::path dir_;
};

// Issue 25: a grid read by the scene, named under a nested key (/media/m/density/file), replaced
// between the checkpoint and the resume: refused with one line naming the file.
TEST(CheckpointInputs, AGridChangedSinceTheCheckpointIsRefused) {
  const fs::path dir = fresh_test_dir("nimbus_ckgrid");
  const fs::path vdb = fs::path(NIMBUS_SOURCE_DIR) / "scenes/vdb";
  fs::copy_file(vdb / "vdb_cloud.vdb", dir / "grid.vdb");
  std::ofstream(dir / "scene.json") << R"({"film": {"width": 8, "height": 6},
    "camera": {"type": "perspective", "from": [0, 0, 5], "to": [0, 0, 0], "fov": 30},
    "integrator": {"spp": 2},
    "lights": [{"type": "environment", "radiance": 1}],
    "media": {"m": {"sigma_s": 2, "density": {"type": "vdb", "file": "grid.vdb"}}},
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}, "medium": "m"}]})";
  ASSERT_EQ(run_nimbus_in(dir, "render scene.json -q --checkpoint ck.nck -o a.exr").code, 0);
  // The same bytes again: resumed.
  const Ran same = run_nimbus_in(dir, "render scene.json -q --resume ck.nck --spp 3 -o b.exr");
  EXPECT_EQ(same.code, 0) << same.err;
  fs::copy_file(vdb / "vdb_fire.vdb", dir / "grid.vdb", fs::copy_options::overwrite_existing);
  const Ran changed = run_nimbus_in(dir, "render scene.json -q --resume ck.nck --spp 4 -o c.exr");
  EXPECT_EQ(changed.code, 2);
  EXPECT_EQ(changed.err,
            "nimbus: --resume ck.nck: the checkpoint is of another scene or other settings "
            "(grid.vdb, named at /media/m/density/file, is not the file the checkpoint's render "
            "read (its size or content differs))\n");
  EXPECT_FALSE(fs::exists(dir / "c.exr"));
  fs::remove_all(dir);
}

// The exact sums and the counts of two checkpoints' films: the pixels, to the bit.
void expect_same_pixels(const fs::path& a, const fs::path& b) {
  const Checkpoint x = load_checkpoint(a.string()), y = load_checkpoint(b.string());
  EXPECT_EQ(x.film.samples, y.film.samples);
  EXPECT_TRUE(x.film.sum == y.film.sum) << a << " and " << b << " hold different sums";
}

// A pixel's samples do not depend on spp (with either sampler), so 8 samples continued to 24 are
// the 24 of one render. The default sampler, zsobol, is the one checked here.
TEST_F(Checkpoints, EightSamplesContinuedToTwentyFourAreOneRenderOfTwentyFour) {
  const std::string sampler;
  ASSERT_EQ(nimbus(sampler + "--spp 8 --checkpoint ck.nck -o eight.exr").code, 0);
  EXPECT_EQ(load_checkpoint((dir_ / "ck.nck").string()).spp, 8);
  const Ran more = nimbus(sampler + "--resume ck.nck --spp 24 -o resumed.exr");
  ASSERT_EQ(more.code, 0) << more.err;
  ASSERT_EQ(nimbus(sampler + "--spp 24 -o once.exr").code, 0);
  ASSERT_EQ(nimbus(sampler + "--spp 24 --checkpoint once.nck -o once2.exr").code, 0);
  EXPECT_TRUE(same_bytes(dir_ / "resumed.exr", dir_ / "once.exr"))
      << "resumed.exr and once.exr differ";
  EXPECT_TRUE(same_bytes(dir_ / "once2.exr", dir_ / "once.exr")) << "once2.exr and once.exr differ";
  expect_same_pixels(dir_ / "ck.nck", dir_ / "once.nck");  // the resume saved to ck.nck
  EXPECT_FALSE(same_bytes(dir_ / "eight.exr", dir_ / "once.exr"));
}

// Killed outright (SIGKILL) while rendering, then resumed: the pixels of an uninterrupted render.
TEST_F(Checkpoints, KilledAndResumedIsTheUninterruptedRender) {
  const pid_t pid = start_checkpointed_render({"-o", "out.exr"});
  ASSERT_EQ(::kill(pid, SIGKILL), 0);
  ASSERT_EQ(wait_for(pid), 128 + SIGKILL) << "the render ended before it was killed";
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
  const Checkpoint saved = load_checkpoint((dir_ / "ck.nck").string());
  const uint64_t held = samples_held(saved.film);
  EXPECT_GT(held, 0u);
  EXPECT_LT(held, uint64_t(24 * 16 * 300));
  EXPECT_EQ(saved.spp, 300);

  const Ran resumed = nimbus("--threads 2 --resume ck.nck -o out.exr");  // 300 spp, as saved
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  ASSERT_EQ(nimbus("--spp 300 -o once.exr").code, 0);
  EXPECT_TRUE(same_bytes(dir_ / "out.exr", dir_ / "once.exr")) << "out.exr and once.exr differ";
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
}

// Ctrl-C: the checkpoint and the image so far, written whole; the resume finishes the render.
TEST_F(Checkpoints, InterruptedWritesTheImageSoFarAndResumes) {
  const pid_t pid = start_checkpointed_render({"-o", "out.exr", "-o", "out.png"});
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  ASSERT_EQ(wait_for(pid), 130);
  EXPECT_TRUE(fs::exists(dir_ / "out.png"));
  const std::string so_far = file_bytes(dir_ / "out.exr");
  const Ran resumed = nimbus("--resume ck.nck -o out.exr -o out.png");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  ASSERT_EQ(nimbus("--spp 300 -o once.exr").code, 0);
  EXPECT_TRUE(so_far != file_bytes(dir_ / "once.exr"));
  EXPECT_TRUE(same_bytes(dir_ / "out.exr", dir_ / "once.exr")) << "out.exr and once.exr differ";
}

TEST_F(Checkpoints, ACheckpointOfOtherSettingsIsRefused) {
  ASSERT_EQ(nimbus("--spp 2 --checkpoint ck.nck -o a.exr").code, 0);
  const Ran seed = nimbus("--resume ck.nck --seed 3 -o b.exr");
  EXPECT_EQ(seed.code, 2);
  EXPECT_EQ(seed.err,
            "nimbus: --resume ck.nck: the checkpoint is of another scene or other settings "
            "(scene.integrator.seed: 7 in the checkpoint, 3 now)\n");
  const Ran width = nimbus("--resume ck.nck --set film.width=20 -o b.exr");
  EXPECT_EQ(width.code, 2);
  EXPECT_NE(width.err.find("(scene.film.width: 24 in the checkpoint, 20 now)"), std::string::npos)
      << width.err;
  const Ran fewer = nimbus("--resume ck.nck --spp 1 -o b.exr");
  EXPECT_EQ(fewer.code, 2);
  EXPECT_EQ(
      fewer.err,
      "nimbus: --resume ck.nck: pixels of the checkpoint hold 2 samples, more than --spp 1\n");
  const Ran missing = nimbus("--resume none.nck -o b.exr");
  EXPECT_EQ(missing.code, 2);
  EXPECT_EQ(missing.err,
            "nimbus: --resume: none.nck: cannot open file (No such file or directory)\n");
  const Ran interval = nimbus("--checkpoint-interval 5 -o b.exr");
  EXPECT_EQ(interval.code, 2);
  EXPECT_EQ(interval.err, "nimbus: --checkpoint-interval needs --checkpoint or --resume\n");
  const Ran zero = nimbus("--checkpoint ck.nck --checkpoint-interval 0 -o b.exr");
  EXPECT_EQ(zero.code, 2);
  EXPECT_NE(zero.err.find("--checkpoint-interval: must be > 0, not 0"), std::string::npos)
      << zero.err;
  EXPECT_FALSE(fs::exists(dir_ / "b.exr"));
  // Threads, outputs and spp change no pixel's samples: accepted.
  EXPECT_EQ(nimbus("--resume ck.nck --spp 3 --threads 1 -o c.png").code, 0);
}

// Issue 44: `--seed 0`, the default, was refused against a checkpoint whose scene left the seed
// out ("absent in the checkpoint, 0 now"). Every setting `nimbus settings` lists, spelt out at its
// default, is the render that leaves it out, both ways round; a setting at another value is not.
TEST_F(Checkpoints, SettingsGivenAtTheirDefaultsAreTheSameRender) {
  std::ofstream(dir_ / "plain.json") << R"({
    "film": {"width": 12, "height": 8}, "integrator": {"spp": 2},
    "camera": {"type": "perspective", "from": [0, 1, 6], "to": [0, 0, 0], "fov": 35},
    "lights": [{"type": "environment", "radiance": 1}],
    "objects": [{"shape": {"type": "sphere", "radius": 1}}]})";
  const Ran settings = run_nimbus_in(dir_, "settings");
  ASSERT_EQ(settings.code, 0) << settings.err;
  std::string defaults;  // --set KEY=DEFAULT for every setting the scene leaves out
  int count = 0;
  std::istringstream lines(settings.out);
  for (std::string key, value, rest; lines >> key >> value && std::getline(lines, rest);) {
    if (key == "film.width" || key == "film.height" || key == "integrator.spp") continue;
    defaults += " --set '" + key + "=" + value + "'";
    ++count;
  }
  EXPECT_GE(count, 15) << settings.out;
  const auto render = [&](const std::string& args) {
    return run_nimbus_in(dir_, "render plain.json -q " + args);
  };
  ASSERT_EQ(render("--checkpoint plain.nck -o a.exr").code, 0);
  const Ran spelt = render("--resume plain.nck --seed 0 --spp 3 -o b.exr" + defaults);
  EXPECT_EQ(spelt.code, 0) << spelt.err;
  ASSERT_EQ(render("--checkpoint spelt.nck --seed 0 -o c.exr" + defaults).code, 0);
  const Ran plain = render("--resume spelt.nck --spp 3 -o d.exr");
  EXPECT_EQ(plain.code, 0) << plain.err;
  EXPECT_TRUE(same_bytes(dir_ / "b.exr", dir_ / "d.exr")) << "b.exr and d.exr differ";
  const Ran other = render("--resume plain.nck --seed 1 -o e.exr");
  EXPECT_EQ(other.err,
            "nimbus: --resume plain.nck: the checkpoint is of another scene or other settings "
            "(scene.integrator.seed: 0 in the checkpoint, 1 now)\n");
}

// Issue 44: a resumed run's samples_per_second divided the whole image's samples by the run's
// own time. Its rates count what it rendered: the samples it added to the checkpoint's.
TEST_F(Checkpoints, AResumedRunsStatsCountItsOwnSamples) {
  ASSERT_EQ(nimbus("--spp 2 --checkpoint ck.nck -o a.exr").code, 0);
  const Ran resumed = nimbus("--resume ck.nck --spp 3 --stats s.json -o b.exr");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  std::ifstream f(dir_ / "s.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  const double pixels = 24 * 16;
  EXPECT_EQ(s["checkpoint"]["samples_at_start"], 2 * pixels);
  EXPECT_EQ(s["checkpoint"]["samples"], 3 * pixels);
  EXPECT_EQ(s["samples"], pixels);
  EXPECT_EQ(s["counters"]["paths"], pixels);
  const double seconds = s["wall_seconds"];
  ASSERT_GT(seconds, 0);
  EXPECT_DOUBLE_EQ(s["samples_per_second"].get<double>(), pixels / seconds);
  EXPECT_DOUBLE_EQ(s["counters"]["density_lookups_per_sample"].get<double>(),
                   s["counters"]["density_lookups"].get<double>() / pixels);
}

// Issue 29: an output named like an input or like another output destroyed it (--stats s.json
// replaced the scene; --checkpoint m.exr -o m.exr lost the checkpoint). Each is refused before
// anything is rendered, with exit 2 and one line, and every file keeps its bytes.
TEST_F(Checkpoints, OutputsThatWouldOverwriteAnInputOrEachOtherAreRefused) {
  ASSERT_EQ(nimbus("--spp 1 --checkpoint ck.nck -o m.exr").code, 0);
  fs::copy_file(fs::path(NIMBUS_SOURCE_DIR) / "scenes/vdb/vdb_cloud.vdb", dir_ / "grid.vdb");
  std::ofstream(dir_ / "grid.json") << R"({
    "film": {"width": 8, "height": 8},
    "camera": {"type": "perspective", "from": [0, 0, 6], "to": [0, 0, 0], "fov": 35},
    "lights": [{"type": "environment", "radiance": 1}],
    "media": {"cloud": {"sigma_s": 2, "density": {"type": "vdb", "file": "grid.vdb"}}},
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}, "medium": "cloud"}]
  })";
  std::map<std::string, std::string> before;
  for (const char* f : {"scene.json", "ck.nck", "m.exr", "grid.vdb", "grid.json"})
    before[f] = file_bytes(dir_ / f);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"render scene.json -o m.exr --stats scene.json",
       "--stats scene.json: is the scene file (scene.json), which the run reads"},
      {"render scene.json -o m.exr --stats m.exr",
       "--stats m.exr: is also the output of -o (m.exr)"},
      {"render scene.json -o a.exr --checkpoint ck.nck --stats ck.nck",
       "--checkpoint ck.nck: is also the output of --stats (ck.nck)"},
      {"render scene.json -o a.exr --checkpoint scene.json",
       "--checkpoint scene.json: is the scene file (scene.json), which the run reads"},
      {"render scene.json -o m.exr --checkpoint m.exr",
       "--checkpoint m.exr: is also the output of -o (m.exr)"},
      {"render scene.json -o m.exr -o ./m.exr", "-o ./m.exr: is also the output of -o (m.exr)"},
      {"render scene.json -o a.exr --resume ck.nck --stats ck.nck",
       "--resume (its later checkpoints) ck.nck: is also the output of --stats (ck.nck)"},
      {"render scene.json -o a.exr --resume ck.nck --checkpoint b.nck --stats ck.nck",
       "--stats ck.nck: is the checkpoint of --resume (ck.nck), which the run reads"},
      {"render grid.json -o a.exr --stats grid.vdb",
       "--stats grid.vdb: is the file of /media/cloud/density/file (grid.vdb), which the run "
       "reads"},
      {"export-vdb grid.json -o grid.vdb --voxel-size 0.1",
       "-o grid.vdb: is the file of /media/cloud/density/file (grid.vdb), which the run reads"},
  };
  for (const auto& [args, problem] : cases) {
    const Ran r = run_nimbus_in(dir_, args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err, "nimbus: " + problem + "\n") << args;
    EXPECT_FALSE(fs::exists(dir_ / "a.exr")) << args;
    EXPECT_FALSE(fs::exists(dir_ / "b.nck")) << args;
    for (const auto& [f, bytes] : before)
      EXPECT_EQ(file_bytes(dir_ / f), bytes) << args << ": " << f;
  }
  // Resuming into the checkpoint it reads is what --resume does.
  EXPECT_EQ(nimbus("--resume ck.nck --spp 2 -o m.exr").code, 0);
}

// Issue 29: a damaged checkpoint was resumed. One byte changed is refused, naming the file.
TEST_F(Checkpoints, ADamagedCheckpointIsNotResumed) {
  ASSERT_EQ(nimbus("--spp 2 --checkpoint ck.nck -o a.exr").code, 0);
  std::string bytes = file_bytes(dir_ / "ck.nck");
  bytes[bytes.size() - 200] = char(bytes[bytes.size() - 200] ^ 0x10);  // in a pixel's record
  std::ofstream(dir_ / "ck.nck", std::ios::binary | std::ios::trunc) << bytes;
  const Ran r = nimbus("--resume ck.nck -o b.exr");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "nimbus: --resume: ck.nck: the checkpoint is damaged or cut short (its checksum does "
            "not match)\n");
  EXPECT_FALSE(fs::exists(dir_ / "b.exr"));
}

// A render of about 2 s (one thread: 1 000 spp in Release, 100 under AddressSanitizer, which runs
// it about ten times slower; 1 000 there cost 26 s of the sanitized suite) with checkpoints into
// sub/, whose folder is removed once the first checkpoint is there (as a full disk would fail
// them), then, with `signal`, stopped 0.2 s later: the shell's report of its exit code, and its
// stderr. The removal is repeated until the folder is gone: a checkpoint's temporary file created
// while `rm` empties the folder keeps it (seen once in CI, on a loaded machine), and the render
// then saved its checkpoint there.
Ran render_losing_its_checkpoint_folder(const fs::path& dir, const std::string& signal) {
  const std::string nimbus = std::string("'") + NIMBUS_BINARY + "'";
  // One subshell, so that all of it runs in `dir`.
  const Ran r = run_in(
      dir,
      "(" + nimbus + " render scene.json -q --spp " + (test::kAddressSanitizer ? "100" : "1000") +
          " --threads 1 --checkpoint sub/ck.nck "
          "--checkpoint-interval 0.05 -o out.exr 2>render.err & pid=$!; "
          "for i in $(seq 6000); do [ -e sub/ck.nck ] && break; sleep 0.01; done; "
          "while [ -e sub ]; do rm -rf ./sub; done; " +
          (signal.empty() ? "" : "sleep 0.2; kill -" + signal + " $pid; ") + "wait $pid; echo $?)");
  return {std::stoi(r.out), file_bytes(dir / "render.err"), ""};
}

// Issue 29: a checkpoint that could not be written was reported as written, and a render whose
// last checkpoint failed ended with exit 0.
TEST_F(Checkpoints, ACheckpointThatCouldNotBeSavedIsNeverReportedAsSaved) {
  fs::create_directory(dir_ / "sub");
  const Ran stopped = render_losing_its_checkpoint_folder(dir_, "INT");
  EXPECT_EQ(stopped.code, 130) << stopped.err;
  EXPECT_NE(
      stopped.err.find("wrote the image so far to out.exr; the checkpoint was not saved (sub/"),
      std::string::npos)
      << stopped.err;
  EXPECT_EQ(stopped.err.find("continue with --resume"), std::string::npos) << stopped.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.exr"));

  fs::remove(dir_ / "out.exr");
  fs::remove_all(dir_ / "sub");
  fs::create_directory(dir_ / "sub");
  const Ran ended = render_losing_its_checkpoint_folder(dir_, "");
  EXPECT_EQ(ended.code, 1) << ended.err;
  EXPECT_NE(ended.err.find("nimbus: wrote out.exr; the last checkpoint was not saved (sub/"),
            std::string::npos)
      << ended.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.exr"));
}

// Issue 29: SIGINT before the first unit was done replaced a good out.exr with an empty image
// (and the checkpoint with an empty one). A camera inside a white medium of optical radius 300,
// whose paths take about 28 ms each (Release) and whose first unit, 8 rows of 32 pixels, about
// 7 s, is stopped 0.5 s after its start: nothing is written.
TEST_F(Checkpoints, AStopBeforeTheFirstSampleWritesNothing) {
  ASSERT_EQ(nimbus("--spp 1 --checkpoint ck.nck -o out.exr").code, 0);
  const std::string image = file_bytes(dir_ / "out.exr"), checkpoint = file_bytes(dir_ / "ck.nck");
  std::ofstream(dir_ / "white.json") << R"({
    "film": {"width": 32, "height": 32},
    "camera": {"type": "perspective", "from": [0, 0, 0], "to": [0, 0, -1], "fov": 35},
    "integrator": {"spp": 1, "max_depth": 1000000},
    "lights": [{"type": "environment", "radiance": 1}],
    "media": {"milk": {"sigma_s": 60}},
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 5}, "medium": "milk"}]
  })";
  const pid_t pid = spawn_in(dir_, {NIMBUS_BINARY, "render", "white.json", "-q", "--threads", "1",
                                    "--checkpoint", "ck.nck", "-o", "out.exr"});
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  EXPECT_EQ(wait_for(pid), 130);
  EXPECT_TRUE(file_bytes(dir_ / "out.exr") == image) << "out.exr was replaced";
  EXPECT_TRUE(file_bytes(dir_ / "ck.nck") == checkpoint) << "ck.nck was replaced";
}

}  // namespace checkpoint_cli_test
}  // namespace nimbus
