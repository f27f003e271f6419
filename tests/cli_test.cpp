// The nimbus command line, run as a program: exit codes, one-line errors naming the JSON path,
// no output left behind by a failed run, and the outputs of a good one.

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "nimbus/render/settings.h"
#include "nimbus/render/wavelength_counts.h"
#include "support/process.h"

namespace cli_test {

namespace fs = std::filesystem;
using nimbus::test::fresh_test_dir;
using nimbus::test::Ran;
using nimbus::test::run_nimbus_in;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_test_dir("nimbus_cli"); }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  Ran run(const std::string& args) { return run_nimbus_in(dir_, args); }
  // `args` is refused with exit 2 and exactly the one line `err`.
  void expect_refused(const std::string& args, const std::string& err) {
    const Ran r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err, err) << args;
  }
  // Everything left in the directory besides the scene files.
  std::vector<std::string> outputs() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().extension() != ".json") out.push_back(e.path().filename().string());
    return out;
  }
  fs::path dir_;
};

// A small valid scene; tests break one thing in it.
nlohmann::json good_scene() {
  return nlohmann::json::parse(R"({
    "film": {"width": 16, "height": 12},
    "camera": {"type": "perspective", "from": [0, 1, 6], "to": [0, 0, 0], "fov": 35},
    "integrator": {"spp": 2, "seed": 1},
    "lights": [{"type": "environment", "radiance": [0.8, 0.9, 1.0]},
               {"type": "sphere", "center": [0, 5, 0], "radius": 0.5, "radiance": 20}],
    "shapes": {
      "ball": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
      "bump": {"type": "quadric", "coefficients": [-4, -4, -4, 0, 0, 0, 0, 0, 4, -0.75]},
      "blob": {"type": "freeform", "base": "ball", "perturbations": [{"shape": "bump", "weight": 2.5}]},
      "floor": {"type": "box", "min": [-5, -1.2, -5], "max": [5, -1, 5]}
    },
    "media": {"fog": {"sigma_a": 0.1, "sigma_s": [1, 2, 3]}},
    "objects": [
      {"shape": "blob", "surface": {"type": "diffuse", "albedo": [0.7, 0.5, 0.3]}},
      {"shape": "floor", "surface": {"type": "diffuse", "albedo": 0.5}},
      {"shape": {"type": "sphere", "center": [2, 0, 0], "radius": 0.5}, "medium": "fog"}
    ]
  })");
}

struct BadCase {
  const char* name;
  const char* pointer;  // JSON pointer to change ("" to replace the whole text)
  const char* value;    // JSON value to put there, or raw text, or "DELETE"
  const char* message;  // the expected stderr line after "scene.json: "
};

const BadCase kBad[] = {
    {"syntax", "", "{\"film\": {\"width\": 16,}}", "parse error"},
    {"no_camera", "/camera", "DELETE", "/camera: required key is missing"},
    {"width_type", "/film/width", "\"wide\"", "/film/width: expected an integer"},
    {"width_zero", "/film/width", "0", "/film/width: must be"},
    {"unknown_key", "/camera/fvo", "30", "/camera/fvo: unknown key"},
    {"unknown_camera", "/camera/type", "\"fisheye\"", "/camera/type:"},
    {"fov_range", "/camera/fov", "180", "/camera/fov: must be"},
    {"camera_degenerate", "/camera/to", "[0, 1, 6]", "/camera"},
    {"spp_negative", "/integrator/spp", "-3", "/integrator/spp: must be"},
    {"unknown_tracking", "/integrator/tracking", "\"magic\"", "/integrator/tracking:"},
    {"unknown_shape", "/objects/1/shape", "\"blobb\"", "/objects/1/shape: unknown shape \"blobb\""},
    {"unknown_primitive", "/shapes/ball/type", "\"torus\"", "/shapes/ball/type:"},
    {"negative_radius", "/shapes/ball/radius", "-1", "/shapes/ball/radius: must be"},
    {"cycle", "/shapes/ball", "{\"type\": \"freeform\", \"base\": \"blob\", \"perturbations\": []}",
     "cycle in shape references"},
    {"coefficients_short", "/shapes/bump/coefficients", "[1, 2, 3]", "/shapes/bump/coefficients:"},
    {"degenerate_transform", "/shapes/blob/transform", "[{\"scale\": 0}]",
     "/shapes/blob/transform/0"},
    {"albedo_above_one", "/objects/0/surface/albedo", "1.5", "/objects/0/surface/albedo: must be"},
    {"ior_below_one", "/objects/0/surface", "{\"type\": \"dielectric\", \"ior\": 0.8}",
     "/objects/0/surface/ior: must be"},
    {"negative_sigma", "/media/fog/sigma_s/1", "-2", "/media/fog/sigma_s/1: must be"},
    {"unknown_medium", "/objects/2/medium", "\"smoke\"", "/objects/2/medium:"},
    {"hg_range", "/media/fog/phase", "{\"type\": \"hg\", \"g\": 1.0}",
     "/media/fog/phase/g: must be"},
    {"light_type", "/lights/0/type", "\"area\"", "/lights/0/type:"},
    {"zero_direction", "/lights/1",
     "{\"type\": \"directional\", \"direction\": [0, 0, 0], \"irradiance\": 1}",
     "/lights/1/direction:"},
    {"unbounded", "/objects/1/shape",
     "{\"type\": \"halfspace\", \"point\": [0, -1, 0], \"normal\": [0, -1, 0]}",
     "/objects/1/shape: shape \"inline\" is unbounded"},
    // Found by the fuzzer: a coefficient so large that tracking's steps stopped advancing. A
    // gray one is fine now (issue 13: it costs real collisions only); a chromatic one costs
    // null collisions in its thinner channels.
    {"optical_thickness", "/media/fog/sigma_s", "[1e7, 1, 1]",
     "/objects/2/medium: medium \"fog\" may cost 1.73e+07 null collisions along a ray"},
    {"optical_thickness_spectral", "/media/fog/sigma_a",
     "{\"spectrum\": [[400, 1], [520, 2.5e307], [700, 1]]}",
     "/objects/2/medium: medium \"fog\" may cost"},
};

TEST_F(Cli, MalformedScenesExitTwoWithOneLineAndNoOutput) {
  int checked = 0;
  for (const BadCase& c : kBad) {
    std::string text;
    if (std::string(c.pointer).empty()) {
      text = c.value;
    } else {
      nlohmann::json j = good_scene();
      const nlohmann::json::json_pointer ptr(c.pointer);
      if (std::string(c.value) == "DELETE")
        j.at(ptr.parent_pointer()).erase(ptr.back());
      else
        j[ptr] = nlohmann::json::parse(c.value);
      text = j.dump(2);
    }
    write("scene.json", text);
    const Ran r = run("render scene.json --quiet");
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.name << ": " << r.err;
    EXPECT_EQ(r.err.rfind("scene.json: ", 0), 0u) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos)
        << c.name << ": expected \"" << c.message << "\" in: " << r.err;
    EXPECT_TRUE(outputs().empty()) << c.name << " left an output behind";
    ++checked;
  }
  EXPECT_GE(checked, 20);
}

TEST_F(Cli, UsageErrorsExitTwo) {
  write("scene.json", good_scene().dump());
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("render").code, 2);
  // Range errors say the range in words (issue 16), not CLI11's double bounds.
  // One line each (issue 29: CLI11 added "Run with --help for more information.").
  const Ran spp0 = run("render scene.json --spp 0");
  EXPECT_EQ(spp0.code, 2);
  EXPECT_EQ(spp0.err, "nimbus: --spp: must be >= 1, not 0\n");
  const Ran huge = run("render scene.json --spp 1099511627776");
  EXPECT_EQ(huge.code, 2);
  EXPECT_NE(huge.err.find("--spp: must be <= 2147483647, not 1099511627776"), std::string::npos)
      << huge.err;
  const Ran threads0 = run("render scene.json --threads 0");
  EXPECT_EQ(threads0.code, 2);
  EXPECT_EQ(threads0.err, "nimbus: --threads: must be >= 1, not 0\n");
  // The seed's range is the scene file's, [0, 2^64 - 1] (issue 29: it stopped at 2^63 - 1).
  const Ran seed_top = run("render scene.json --seed 18446744073709551615 --spp 1 -o top.png");
  EXPECT_EQ(seed_top.code, 0) << seed_top.err;
  fs::remove(dir_ / "top.png");
  expect_refused("render scene.json --seed 18446744073709551616",
                 "nimbus: --seed: must be <= 18446744073709551615, not 18446744073709551616\n");
  const Ran words = run("render scene.json --seed many");
  EXPECT_EQ(words.code, 2);
  EXPECT_NE(words.err.find("--seed: must be a whole number, not \"many\""), std::string::npos)
      << words.err;
  const Ran set_huge = run("render scene.json --set integrator.spp=1099511627776");
  EXPECT_EQ(set_huge.code, 2);
  EXPECT_EQ(set_huge.err,
            "--set integrator.spp=1099511627776: /integrator/spp: must be in [1, 2147483647]\n");
  EXPECT_EQ(run("render scene.json --bogus").code, 2);
  const Ran missing = run("render nowhere.json");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("nowhere.json: cannot open file"), std::string::npos) << missing.err;
  const Ran bad_ext = run("render scene.json -o out.jpg");
  EXPECT_EQ(bad_ext.code, 2);
  EXPECT_NE(bad_ext.err.find("out.jpg: unknown image format"), std::string::npos) << bad_ext.err;
  const Ran bad_dir = run("render scene.json -o nodir/out.png");
  EXPECT_EQ(bad_dir.code, 2);
  // Issue 29: a legal 255-byte name failed after the render (its temporary file's name was too
  // long); now before it.
  const std::string long_name = std::string(251, 'a') + ".png";
  const Ran too_long = run("render scene.json -o " + long_name);
  EXPECT_EQ(too_long.code, 2);
  EXPECT_EQ(too_long.err, "nimbus: " + long_name +
                              ": the file name has 255 bytes; an output's may have at most 231 "
                              "(the folder's 255, less room for its temporary file)\n");
  const Ran bad_set = run("render scene.json --set integrator.spp=abc");
  EXPECT_EQ(bad_set.code, 2);
  EXPECT_NE(bad_set.err.find("--set integrator.spp=abc"), std::string::npos) << bad_set.err;
  EXPECT_TRUE(outputs().empty());
  EXPECT_EQ(run("--version").code, 0);
  EXPECT_EQ(run("--help").code, 0);
}

TEST_F(Cli, RendersDefaultOutputsAndStats) {
  write("scene.json", good_scene().dump());
  const Ran r = run("render scene.json --stats stats.json --set film.width=8 --spp 3 --threads 2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "scene.exr"));
  EXPECT_TRUE(fs::exists(dir_ / "scene.png"));
  std::ifstream f(dir_ / "stats.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  EXPECT_EQ(s["settings"]["film"]["width"], 8);
  EXPECT_EQ(s["settings"]["integrator"]["spp"], 3);
  EXPECT_EQ(s["threads"], 2);
  EXPECT_EQ(s["counters"]["paths"], 8 * 12 * 3);
  EXPECT_EQ(s["samples"], 8 * 12 * 3);
  EXPECT_GT(s["samples_per_second"].get<double>(), 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(s["image_mean"][c].get<double>(), 0);
    EXPECT_GT(s["image_mean_standard_error"][c].get<double>(), 0);
  }
  EXPECT_GT(s["counters"]["density_lookups"].get<long>(), 0);
  EXPECT_GT(s["counters"]["shadow_ray_lookups"].get<long>(), 0);
  EXPECT_LT(s["counters"]["shadow_ray_lookups"].get<long>(),
            s["counters"]["density_lookups"].get<long>());
  const double null_fraction = s["counters"]["null_collision_fraction"].get<double>();
  EXPECT_TRUE(null_fraction >= 0 && null_fraction < 1);
  EXPECT_GT(s["counters"]["density_lookups_per_real_collision"].get<double>(), 0);
  EXPECT_GT(s["octree"]["nodes"].get<long>(), 0);
  EXPECT_GE(s["octree"]["built_nodes"].get<long>(), s["octree"]["nodes"].get<long>());
  EXPECT_GT(s["octree"]["bytes"].get<long>(), 0);
  EXPECT_GE(s["octree"]["build_seconds"].get<double>(), 0);
  EXPECT_GE(s["octree"]["depth"].get<int>(), 0);
  EXPECT_EQ(s["settings"]["spectrum"]["mode"], "rgb");
  EXPECT_EQ(s["channels"], 3);
  EXPECT_EQ(s["settings"]["integrator"]["sampler"], "zsobol");
  EXPECT_EQ(s["settings"]["integrator"]["tracking"], "spectral-mis");
  EXPECT_EQ(s["settings"]["integrator"]["absorption"], "weight");
  // Every declared setting, by its scene-file key (render/settings.h).
  for (const nimbus::Setting& setting : nimbus::render_settings()) {
    nlohmann::json at = s["settings"];
    std::string key(setting.key);
    for (size_t dot; (dot = key.find('.')) != std::string::npos; key = key.substr(dot + 1))
      at = at[key.substr(0, dot)];
    EXPECT_TRUE(at.contains(key)) << setting.key;
  }
  EXPECT_EQ(s["counters"]["rejected_samples"], 0);
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

// Issue 16: a sample whose value overflows the film never enters it; it is counted, reported
// once, and the rest is written. Emitted light is at most 1e30 and the film follows it (issue
// 29), so the overflow here is geometric: a point light of intensity 1 hangs 1e-10 above a
// diffuse floor seen from above, where I cos θ / d² reaches 1e20, past the film's 2^62.
TEST_F(Cli, OverflowingSamplesAreRejectedCountedAndReported) {
  write("scene.json", R"({"film": {"width": 8, "height": 8},
    "camera": {"type": "orthographic", "from": [0, 1, 0], "to": [0, 0, 0], "up": [0, 0, 1],
               "width": 4e-9},
    "lights": [{"type": "point", "position": [0, 1e-10, 0], "intensity": 1}],
    "shapes": {"floor": {"type": "box", "min": [-1, -1, -1], "max": [1, 0, 1]}},
    "objects": [{"shape": "floor", "surface": {"type": "diffuse", "albedo": 0.5}}]})");
  const Ran r = run("render scene.json --stats stats.json --spp 8 -o out.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream f(dir_ / "stats.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  const long rejected = s["counters"]["rejected_samples"].get<long>();
  EXPECT_GT(rejected, 0);
  EXPECT_LE(rejected, 8 * 8 * 8 / 4);
  EXPECT_NE(r.err.find("warning: " + std::to_string(rejected) +
                       " samples were NaN or of magnitude 4.61e+18 or more and counted as 0"),
            std::string::npos)
      << r.err;
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(s["image_mean"][c].is_number()) << "not null: finite";
}

TEST_F(Cli, RendersInSpectralModeFromTheCommandLine) {
  write("scene.json", good_scene().dump());
  // The largest count this build renders (16, or 8 in the sanitized build): not the default 8
  // where there is another.
  const int n_built = nimbus::built_wavelength_counts().back();
  const Ran r =
      run("render scene.json --stats stats.json --set film.width=8 --spp 2 --set "
          "spectrum.mode=spectral --set spectrum.wavelengths=" +
          std::to_string(n_built) + " -o s.exr --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "s.exr"));
  std::ifstream f(dir_ / "stats.json");
  const nlohmann::json s = nlohmann::json::parse(f);
  EXPECT_EQ(s["settings"]["spectrum"]["mode"], "spectral");
  EXPECT_EQ(s["channels"], n_built);
  for (int c = 0; c < 3; ++c) EXPECT_GT(s["image_mean"][c].get<double>(), 0);
  // A wavelength count this build does not render is a scene error: exit 2, one line, no output.
  for (const char* n : {"6", "32"}) {
    const Ran bad = run(std::string("render scene.json --set spectrum.mode=spectral ") +
                        "--set spectrum.wavelengths=" + n + " -o bad.exr");
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find(fmt::format("/spectrum/wavelengths: must be one of {} (the counts this "
                                       "build renders: CMake option NIMBUS_WAVELENGTH_COUNTS)\n",
                                       fmt::join(nimbus::built_wavelength_counts(), ", "))),
              std::string::npos)
        << bad.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad.exr"));
  }
}

// Shell: waits until process $pid catches SIGINT (signal 2: the value 2 in its SigCgt mask), so
// that a signal sent next finds nimbus's handlers. Before them a SIGINT is lost (a background job
// of a shell ignores it) or kills without a word: under the sanitizers, on a loaded machine,
// start-up took longer than the half second the tests used to wait.
constexpr const char* kAwaitHandlers =
    "for i in $(seq 2400); do [ -e /proc/$pid ] || break; "
    "m=$(sed -n 's/^SigCgt:[[:space:]]*//p' /proc/$pid/status 2>/dev/null); "
    "m=${m#????????}; [ $((0x${m:-0} & 2)) -ne 0 ] && break; sleep 0.05; done; ";

// Issue 16: SIGINT and SIGTERM stop a render cleanly: exit 128 + the signal, one line, and no
// output or temporary file left behind.
TEST_F(Cli, SignalsStopTheRenderAndWriteNothing) {
  write("scene.json", good_scene().dump());
  for (const auto& [sig, code] : {std::pair<const char*, int>{"INT", 130}, {"TERM", 143}}) {
    const std::string script =
        std::string("cd '") + dir_.string() + "' && ('" + NIMBUS_BINARY +
        "' render scene.json --spp 20000 -o out.png -o out.exr --stats s.json 2>err.txt & "
        "pid=$!; " +
        kAwaitHandlers + "sleep 1; kill -" + sig + " $pid; wait $pid; echo $? > code.txt)";
    ASSERT_EQ(std::system(script.c_str()), 0);
    std::ifstream code_file(dir_ / "code.txt"), err_file(dir_ / "err.txt");
    int exit_code = -1;
    code_file >> exit_code;
    EXPECT_EQ(exit_code, code) << sig;
    std::stringstream err;
    err << err_file.rdbuf();
    EXPECT_NE(err.str().find("before the render finished; nothing written"), std::string::npos)
        << err.str();
    fs::remove(dir_ / "code.txt");
    fs::remove(dir_ / "err.txt");
    EXPECT_TRUE(outputs().empty()) << outputs().front();
  }
}

// Issue 16: a deep octree with sampled bounds builds for seconds; a signal stops that too.
TEST_F(Cli, SignalsStopTheOctreeBuildAndWriteNothing) {
  const std::string script = std::string("cd '") + dir_.string() + "' && ('" + NIMBUS_BINARY +
                             "' render '" + NIMBUS_SOURCE_DIR +
                             "/scenes/cloud.json' --set integrator.octree.depth=16 --set "
                             "integrator.majorant.source=sample "
                             "-o out.png 2>err.txt & pid=$!; " +
                             kAwaitHandlers +
                             "sleep 0.5; kill -INT $pid; wait $pid; echo $? > code.txt)";
  ASSERT_EQ(std::system(script.c_str()), 0);
  std::ifstream code_file(dir_ / "code.txt"), err_file(dir_ / "err.txt");
  int exit_code = -1;
  code_file >> exit_code;
  EXPECT_EQ(exit_code, 130);
  std::stringstream err;
  err << err_file.rdbuf();
  EXPECT_EQ(err.str(), "nimbus: stopped by SIGINT while compiling the scene; nothing written\n");
  fs::remove(dir_ / "code.txt");
  fs::remove(dir_ / "err.txt");
  EXPECT_TRUE(outputs().empty());
}

// Issue 16: a 16384 x 16384 film took 15.7 GB without a word. The render's memory is estimated
// before anything large is allocated and refused past the available memory or --max-memory.
TEST_F(Cli, RendersThatWouldNotFitAreRefusedUpFront) {
  write("scene.json", good_scene().dump());
  const Ran big = run(
      "render scene.json --set film.width=16384 --set film.height=16384 --max-memory 16G -o a.png");
  EXPECT_EQ(big.code, 2);
  EXPECT_EQ(
      big.err,
      "nimbus: the render needs about 25.1 GiB (film 19.0 GiB, image 6.0 GiB, majorant "
      "octrees 56.0 MiB, media lists 2.3 MiB), more than the 16.0 GiB allowed by --max-memory\n");
  EXPECT_TRUE(outputs().empty());
  const Ran bad = run("render scene.json --max-memory 10x -o a.png");
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(bad.err, "nimbus: --max-memory: \"10x\": unknown size suffix \"x\" (K, M, G or T)\n");
  // Issue 29: an empty size was taken as the default, and 0x10 as 16 bytes.
  for (const std::string size : {"", "0x10"})
    expect_refused("render scene.json --max-memory '" + size + "' -o a.png",
                   "nimbus: --max-memory: \"" + size +
                       "\" is not a size (a positive number with K, M, G or T)\n");
  EXPECT_TRUE(outputs().empty());
  EXPECT_EQ(run("render scene.json --max-memory 1.5G --spp 1 -o a.png").code, 0);
  // Issue 29: a scene without media was charged 42 MiB of octrees, so --max-memory 32M refused
  // a 16 x 16 render of it.
  write("plain.json", R"({"film": {"width": 16, "height": 16},
    "camera": {"from": [0, 0, 4], "to": [0, 0, 0]},
    "lights": [{"type": "environment", "radiance": 1}],
    "objects": [{"shape": {"type": "sphere", "center": [0, 0, 0], "radius": 1}}]})");
  const Ran plain = run("render plain.json --max-memory 32M --spp 1 -o p.png");
  EXPECT_EQ(plain.code, 0) << plain.err;
  // Issue 26: 1 024 dielectric spheres holding one homogeneous medium were refused as needing
  // 42 GiB of octrees; each octree is one node. As many of a cloud density are still charged
  // the node budget each, and refused.
  nlohmann::json many = {{"film", {{"width", 16}, {"height", 16}}},
                         {"camera", {{"from", {0, 4, 6}}, {"to", {0, 0, 0}}}},
                         {"lights", {{{"type", "environment"}, {"radiance", 1}}}},
                         {"media", {{"wax", {{"sigma_s", {5, 4, 3}}, {"sigma_a", 0.1}}}}},
                         {"objects", nlohmann::json::array()}};
  for (int i = 0; i < 1024; ++i)
    many["objects"].push_back({{"shape",
                                {{"type", "sphere"},
                                 {"center", {i % 32 * 0.25 - 4, 0.1, i / 32 * 0.25 - 4}},
                                 {"radius", 0.1}}},
                               {"surface", {{"type", "dielectric"}}},
                               {"medium", "wax"}});
  write("many.json", many.dump());
  const Ran homogeneous = run("render many.json --max-memory 256M --spp 1 -o m.png");
  EXPECT_EQ(homogeneous.code, 0) << homogeneous.err;
  many["media"]["wax"]["density"] = {{"type", "cloud"}};
  write("many.json", many.dump());
  const Ran cloudy = run("render many.json --max-memory 256M --spp 1 -o c.png");
  EXPECT_EQ(cloudy.code, 2);
  EXPECT_NE(cloudy.err.find("majorant octrees 56.0 GiB"), std::string::npos) << cloudy.err;
}

// Issue 29: --max-memory above what the machine can give ended in "nimbus: std::bad_alloc". Under
// an address-space limit of 1.5 GB, a 16384 x 16384 render allowed 100 GB ends in one line.
TEST_F(Cli, OutOfMemoryIsOneLine) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer cannot start under an address-space limit";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  GTEST_SKIP() << "AddressSanitizer cannot start under an address-space limit";
#endif
#endif
  write("scene.json", good_scene().dump());
  const Ran r = nimbus::test::run_in(dir_, std::string("ulimit -v 1500000 && '") + NIMBUS_BINARY +
                                               "' render scene.json --set film.width=16384 --set "
                                               "film.height=16384 --max-memory 100G -q -o a.png");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err,
            "nimbus: out of memory: the machine could not give what the run needed (does "
            "--max-memory allow more than it has?)\n");
  EXPECT_TRUE(outputs().empty());
}

TEST_F(Cli, OutputIsTheSameForOneAndTwoThreads) {
  write("scene.json", good_scene().dump());
  ASSERT_EQ(run("render scene.json -o one.exr --threads 1 --quiet").code, 0);
  ASSERT_EQ(run("render scene.json -o two.exr --threads 2 --quiet").code, 0);
  auto bytes = [&](const char* name) {
    std::ifstream f(dir_ / name, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  EXPECT_EQ(bytes("one.exr"), bytes("two.exr"));
  EXPECT_EQ(run("render scene.json -q").err, "");
}

}  // namespace cli_test
