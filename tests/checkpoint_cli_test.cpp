// `nimbus render --checkpoint / --resume` run as a program (issue 15): a render killed outright
// and resumed, or stopped by Ctrl-C and resumed, or continued to more samples, writes the same
// pixels as one render; a checkpoint of other settings is refused.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "nimbus/job/checkpoint.h"
#include "support/process.h"

namespace nimbus {
namespace {

namespace fs = std::filesystem;
using namespace nimbus::testing;

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
  EXPECT_EQ(missing.err, "nimbus: --resume: none.nck: cannot open the checkpoint\n");
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

}  // namespace
}  // namespace nimbus
