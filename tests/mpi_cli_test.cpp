// `mpirun -np K nimbus render` (issue 15): the pixels of K processes are those of one, to the
// bit, for any K and threads per rank; --stats says who rendered what; a scene error is one line
// from rank 0 and exit 2; checkpoints work across ranks. Skipped when the build has no MPI.

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
    dir_ = fs::temp_directory_path() /
           ("nimbus_mpi_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "scene.json") << kScene;
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  Ran nimbus(const std::string& args) {
    return run_in(dir_, std::string("'") + NIMBUS_BINARY + "' render scene.json -q " + args);
  }
  // OpenMPI refuses root unless told (CI runs as root); -q drops mpirun's own report of a rank's
  // non-zero exit, so that stderr holds what nimbus printed.
  Ran mpirun(int ranks, const std::string& args) {
#ifdef NIMBUS_MPIEXEC
    return run_in(dir_, std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '") +
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
  const std::string one = file_bytes(dir_ / "one.exr");
  EXPECT_EQ(file_bytes(dir_ / "two.exr"), one);
  EXPECT_EQ(file_bytes(dir_ / "three.exr"), one);
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

TEST_F(Mpi, ASceneErrorIsOneLineFromRankZeroAndExitTwo) {
  const Ran bad = mpirun(3, "--set film.width=0 -o bad.exr");
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(bad.err, "--set film.width=0: /film/width: must be in [1, 16384]\n");
  const Ran usage = mpirun(2, "--spp 0 -o bad.exr");
  EXPECT_EQ(usage.code, 2);
  EXPECT_EQ(std::count(usage.err.begin(), usage.err.end(), '\n'), 2) << usage.err;  // + "--help"
  EXPECT_FALSE(fs::exists(dir_ / "bad.exr"));
}

// A checkpoint written by two ranks is continued by three, to more samples (the independent
// sampler: docs/cli.md), and gives the pixels of one process rendering them at once.
TEST_F(Mpi, CheckpointsCarryAcrossRankCounts) {
  const std::string sampler = "--set integrator.sampler=independent ";
  ASSERT_EQ(mpirun(2, sampler + "--spp 3 --checkpoint ck.nck -o a.exr").code, 0);
  const Ran more = mpirun(3, sampler + "--resume ck.nck --spp 8 -o b.exr");
  ASSERT_EQ(more.code, 0) << more.err;
  ASSERT_EQ(nimbus(sampler + "--spp 8 -o once.exr").code, 0);
  EXPECT_EQ(file_bytes(dir_ / "b.exr"), file_bytes(dir_ / "once.exr"));
}

}  // namespace
}  // namespace nimbus
