// nimbus_openvdb.so (issue 45, media/vdb_module.h): the nimbus executable loads libopenvdb only
// when a scene reads a VDB file or export-vdb writes one, through the module; every other process
// (--version, a render without VDB) does without it. A module that cannot be loaded costs a VDB
// scene one line naming the file and the loader's reason (exit 2), and nothing else. That a VDB
// scene renders the same bits through the module is ImageChecksums' (vdb_cloud, vdb_fire,
// recorded before the module). Run as programs under the loader's LD_DEBUG=files, which names each
// library a process loads (this test binary links OpenVDB itself for its grids).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/process.h"

namespace openvdb_module_test {

namespace fs = std::filesystem;
using nimbus::test::fresh_test_dir;
using nimbus::test::Ran;
using nimbus::test::run_in;

class OpenVdbModule : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_test_dir("nimbus_openvdb_module"); }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs nimbus with `args` (and `env`, "NAME=value ..." before it) under LD_DEBUG=files, and
  // returns whether any of its processes (the reader's child too) loaded `library`.
  bool loads(const std::string& args, const std::string& library, Ran* ran = nullptr,
             const std::string& env = "") {
    const fs::path logs = dir_ / "ld";
    fs::remove_all(logs);
    fs::create_directories(logs);
    const Ran r = run_in(dir_, env + " LD_DEBUG=files LD_DEBUG_OUTPUT='" + (logs / "ld").string() +
                                   "' '" + NIMBUS_BINARY + "' " + args);
    if (ran) *ran = r;
    bool found = false;
    int files = 0;
    for (const auto& e : fs::directory_iterator(logs)) {
      std::ifstream f(e.path());
      std::stringstream text;
      text << f.rdbuf();
      ++files;
      found = found || text.str().find("file=" + library) != std::string::npos;
    }
    EXPECT_GE(files, 1) << "LD_DEBUG wrote nothing: " << args;
    return found;
  }
  std::string scene(const std::string& name) const {
    return std::string(NIMBUS_SOURCE_DIR) + "/scenes/" + name;
  }
  static constexpr const char* kSmall =
      " --spp 1 --set film.width=16 --set film.height=12 --quiet -o out.png";

  fs::path dir_;
};

TEST_F(OpenVdbModule, OnlyAProcessThatReadsAVdbFileLoadsOpenVdb) {
  Ran r;
  EXPECT_FALSE(loads("--version", "libopenvdb", &r));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(loads("--version", "nimbus_openvdb", &r));
  EXPECT_FALSE(loads("render '" + scene("demo.json") + "'" + kSmall, "libopenvdb", &r));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(loads("render '" + scene("cloud_sunlit.json") + "'" + kSmall, "libopenvdb", &r));
  EXPECT_EQ(r.code, 0) << r.err;
  // The checks see what they look for: a VDB scene loads the module, and OpenVDB through it.
  EXPECT_TRUE(loads("render '" + scene("vdb_cloud.json") + "'" + kSmall, "libopenvdb", &r));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.png"));
  EXPECT_TRUE(loads("export-vdb '" + scene("cloud_sunlit.json") +
                        "' -o out.vdb --voxel-size 0.1 --object 0 --quiet",
                    "libopenvdb", &r));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out.vdb"));
}

TEST_F(OpenVdbModule, AModuleThatCannotBeLoadedIsOneLineForAVdbSceneOnly) {
  std::ofstream(dir_ / "broken.so") << "not a shared object\n";
  struct Case {
    std::string module, reason;
  };
  const Case cases[] = {
      {(dir_ / "missing.so").string(), "missing.so (no such file; set by NIMBUS_OPENVDB_MODULE)"},
      {(dir_ / "broken.so").string(), "broken.so: file too short"},
  };
  for (const Case& c : cases) {
    const std::string env = "NIMBUS_OPENVDB_MODULE='" + c.module + "'";
    Ran r;
    // Without VDB, nothing changes.
    EXPECT_FALSE(loads("render '" + scene("demo.json") + "'" + kSmall, "libopenvdb", &r, env));
    EXPECT_EQ(r.code, 0) << r.err;
    fs::remove(dir_ / "out.png");
    for (const std::string& args :
         {"render '" + scene("vdb_cloud.json") + "'" + kSmall,
          "export-vdb '" + scene("cloud_sunlit.json") + "' -o out.vdb --voxel-size 0.1 --quiet"}) {
      loads(args, "libopenvdb", &r, env);
      EXPECT_EQ(r.code, 2) << args << ": " << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_NE(r.err.find("needs nimbus's OpenVDB module: cannot load " + c.module),
                std::string::npos)
          << r.err;
      EXPECT_NE(r.err.find(c.reason), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(dir_ / "out.png") || fs::exists(dir_ / "out.vdb")) << args;
    }
  }
}

}  // namespace openvdb_module_test
