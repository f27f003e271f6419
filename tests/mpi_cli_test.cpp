// `mpirun -np K nimbus render` (issue 15): the pixels of K processes are those of one, to the
// bit, for any K and threads per rank; --stats says who rendered what; a scene error is one line
// from rank 0 and exit 2; checkpoints work across ranks. Skipped when the build has no MPI.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "nimbus/job/checkpoint.h"
#include "support/process.h"

namespace nimbus {
namespace mpi_cli_test {

namespace fs = std::filesystem;
using namespace nimbus::test;

// A dense cloud in one corner of the image and thin haze elsewhere: 40 x 24 pixels.
constexpr const char* kScene = R"({
  "film": {"width": 40, "height": 24},
  "camera": {"type": "perspective", "from": [0, 0, 6], "to": [0, 0, 0], "fov": 40},
  "integrator": {"spp": 6, "seed": 11},
  "lights": [{"type": "environment", "radiance": [0.6, 0.7, 0.9]},
             {"type": "directional", "direction": [-0.5, -1, -0.4], "irradiance": 3}],
  "media": {
    "cloud": {"sigma_a": 0.1, "sigma_s": [20, 22, 24],
              "density": {"type": "cloud", "octaves": 3, "frequency": 2.5, "edge": 0.5}},
    "haze": {"sigma_a": 0.05, "sigma_s": 0.3}
  },
  "objects": [
    {"shape": {"type": "sphere", "center": [-1.3, 0.7, 0], "radius": 0.8}, "medium": "cloud"},
    {"shape": {"type": "box", "min": [-3, -2, -1], "max": [3, 2, 1]}, "medium": "haze"}
  ]
})";

class Mpi : public ::testing::Test {
 protected:
  void SetUp() override {
#ifndef NIMBUS_MPIEXEC
    GTEST_SKIP() << "built without MPI (CMake found none)";
#endif
    dir_ = fresh_test_dir("nimbus_mpi");
    std::ofstream(dir_ / "scene.json") << kScene;
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  Ran nimbus(const std::string& args) {
    return run_nimbus_in(dir_, "render scene.json -q " + args);
  }
  // OpenMPI refuses root unless told (CI runs as root); -q drops mpirun's own report of a rank's
  // non-zero exit, so that stderr holds what nimbus printed. OpenMPI's dynamically loaded
  // components leak at exit (measured: 121 kB in 3 347 allocations from unknown modules), which
  // LeakSanitizer turns into a failing rank in the sanitized build: leak checks are off for the
  // ranks (every other test keeps them).
  Ran mpirun(int ranks, const std::string& args) {
#ifdef NIMBUS_MPIEXEC
    return run_in(dir_, std::string("ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}"
                                    "detect_leaks=0\" OMPI_ALLOW_RUN_AS_ROOT=1 "
                                    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '") +
                            NIMBUS_MPIEXEC + "' -q --oversubscribe -np " + std::to_string(ranks) +
                            " '" + NIMBUS_BINARY + "' render scene.json -q " + args);
#else
    (void)ranks;
    (void)args;
    return {};
#endif
  }
  fs::path dir_;
};

void expect_same_pixels(const fs::path& a, const fs::path& b) {
  const Checkpoint x = load_checkpoint(a.string()), y = load_checkpoint(b.string());
  EXPECT_EQ(x.film.samples, y.film.samples);
  EXPECT_TRUE(x.film.sum == y.film.sum) << a << " and " << b << " hold different sums";
}

TEST_F(Mpi, RanksRenderTheBitsOfOneProcess) {
  ASSERT_EQ(nimbus("--threads 2 -o one.exr --checkpoint one.nck").code, 0);
  const Ran two = mpirun(2, "--threads 1 -o two.exr --checkpoint two.nck --stats two.json");
  ASSERT_EQ(two.code, 0) << two.err;
  const Ran three = mpirun(3, "--threads 2 -o three.exr --checkpoint three.nck");
  ASSERT_EQ(three.code, 0) << three.err;
  EXPECT_TRUE(same_bytes(dir_ / "two.exr", dir_ / "one.exr"));
  EXPECT_TRUE(same_bytes(dir_ / "three.exr", dir_ / "one.exr"));
  expect_same_pixels(dir_ / "one.nck", dir_ / "two.nck");
  expect_same_pixels(dir_ / "one.nck", dir_ / "three.nck");

  std::ifstream f(dir_ / "two.json");
  const nlohmann::json stats = nlohmann::json::parse(f);
  EXPECT_EQ(stats["mpi"]["ranks"], 2);
  const auto per_rank = stats["mpi"]["samples_per_rank"].get<std::vector<uint64_t>>();
  ASSERT_EQ(per_rank.size(), 2u);
  EXPECT_EQ(per_rank[0] + per_rank[1], uint64_t(40 * 24 * 6));
  EXPECT_EQ(stats["counters"]["paths"], 40 * 24 * 6);  // every rank's counters
}

// The AOVs' sums travel with the pixels (job/film_patch.h) and are exact: albedo, normal and
// depth on 2 ranks are the bytes of one process without work units.
// To a noise target a unit carries its lane's state to the rank that continues it
// (job/work_queue.h): the blocks stop at the same counts with the same bits.
TEST_F(Mpi, RanksRenderToANoiseTargetTheBitsOfOneProcess) {
  const std::string target = "--noise-target 0.05 --spp 400 --aov samples ";
  ASSERT_EQ(nimbus(target + "--threads 2 -o one.exr --checkpoint one.nck").code, 0);
  const Ran two = mpirun(2, target + "--threads 1 -o two.exr --checkpoint two.nck");
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_TRUE(same_bytes(dir_ / "two.exr", dir_ / "one.exr"));
  expect_same_pixels(dir_ / "one.nck", dir_ / "two.nck");
  const Checkpoint one = load_checkpoint((dir_ / "one.nck").string());
  const auto [least, most] = std::minmax_element(one.film.samples.begin(), one.film.samples.end());
  EXPECT_LT(*least, *most);
}

TEST_F(Mpi, RanksRenderTheAovLayersOfOneProcess) {
  ASSERT_EQ(nimbus("--threads 2 -o one.exr --aov albedo,normal,depth").code, 0);
  const Ran two = mpirun(2, "--threads 1 -o two.exr --aov albedo,normal,depth");
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_TRUE(same_bytes(dir_ / "two.exr", dir_ / "one.exr"));
}

TEST_F(Mpi, ASceneErrorIsOneLineFromRankZeroAndExitTwo) {
  const Ran bad = mpirun(3, "--set film.width=0 -o bad.exr");
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(bad.err, "--set film.width=0: /film/width: must be in [1, 16384]\n");
  EXPECT_FALSE(fs::exists(dir_ / "bad.exr"));
}

// A checkpoint written by two ranks is continued by three, to more samples, and gives the pixels
// of one process rendering them at once (either sampler; here the independent one, while the
// checkpoint tests check the default).
TEST_F(Mpi, CheckpointsCarryAcrossRankCounts) {
  const std::string sampler = "--set integrator.sampler=independent ";
  ASSERT_EQ(mpirun(2, sampler + "--spp 3 --checkpoint ck.nck -o a.exr").code, 0);
  const Ran more = mpirun(3, sampler + "--resume ck.nck --spp 8 -o b.exr");
  ASSERT_EQ(more.code, 0) << more.err;
  ASSERT_EQ(nimbus(sampler + "--spp 8 -o once.exr").code, 0);
  EXPECT_TRUE(same_bytes(dir_ / "b.exr", dir_ / "once.exr")) << "b.exr and once.exr differ";
}

// The process of `rank` that mpirun `launcher` started (OpenMPI starts the ranks of one node
// as its children, each with OMPI_COMM_WORLD_RANK in its environment); -1 if none.
pid_t rank_process(pid_t launcher, int rank) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string pid, comm, state;
    pid_t parent = 0;
    stat >> pid >> comm >> state >> parent;
    if (parent != launcher) continue;
    const std::string env = file_bytes(e.path() / "environ");
    if (env.find("OMPI_COMM_WORLD_RANK=" + std::to_string(rank) + '\0') != std::string::npos)
      return std::stoi(name);
  }
  return -1;
}

// A rank killed outright ends the job (mpirun ends the others): no output is written, none is
// left half written, and the checkpoint that rank 0 saved continues the render to the pixels of
// an uninterrupted one.
TEST_F(Mpi, ARankKilledLeavesNoOutputAndTheCheckpointResumes) {
#ifdef NIMBUS_MPIEXEC
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  const pid_t launcher = spawn_in(dir_, {NIMBUS_MPIEXEC,
                                         "-q",
                                         "--oversubscribe",
                                         "-np",
                                         "2",
                                         NIMBUS_BINARY,
                                         "render",
                                         "scene.json",
                                         "-q",
                                         "--spp",
                                         "150",
                                         "--threads",
                                         "1",
                                         "--checkpoint",
                                         "ck.nck",
                                         "--checkpoint-interval",
                                         "0.05",
                                         "-o",
                                         "out.exr",
                                         "-o",
                                         "out.png"});
  ASSERT_TRUE(wait_for_file(dir_ / "ck.nck"));
  const pid_t rank1 = rank_process(launcher, 1);
  ASSERT_GT(rank1, 0);
  ASSERT_EQ(::kill(rank1, SIGKILL), 0);
  EXPECT_NE(wait_for(launcher), 0);
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
  EXPECT_FALSE(fs::exists(dir_ / "out.png"));
  const uint64_t held = samples_held(load_checkpoint((dir_ / "ck.nck").string()).film);
  EXPECT_LT(held, uint64_t(40 * 24 * 150)) << "the job ended before the rank was killed";

  const Ran resumed = mpirun(2, "--resume ck.nck -o out.exr");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  ASSERT_EQ(nimbus("--spp 150 -o once.exr").code, 0);
  EXPECT_TRUE(same_bytes(dir_ / "out.exr", dir_ / "once.exr")) << "out.exr and once.exr differ";
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
#endif
}

}  // namespace mpi_cli_test
}  // namespace nimbus
