// The files fuzzer's seed corpus (fuzz/files_corpus/, docs/testing.md): a checkpoint, a film file,
// an .npy instances file and a viewer camera body that read, and the hostile ones of issue 44
// beside them, written by the suite's generators (tests/support/crafted_files.h). The test
// checks that the corpus is there, small, and that each file reads as the fuzzer expects: to a
// value or to a one-line error. NIMBUS_WRITE_FUZZ_CORPUS=1 (re)writes it.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>

#include "nimbus/io/film_file.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/scene/instances_file.h"
#include "nimbus/view/camera_body.h"
#include "support/crafted_files.h"

namespace nimbus {
namespace files_fuzz_corpus_test {

namespace fs = std::filesystem;

const std::string kCorpus = std::string(NIMBUS_SOURCE_DIR) + "/fuzz/files_corpus/";

std::map<std::string, std::string> seeds() {
  using namespace test;
  const std::string pixel = film_bytes(1, 1, 1);
  const std::string translations(6 * 8, '\0');  // (2, 3) float64 zeros
  return {
      {"film.film", film_bytes(2, 3, 6)},
      {"film_claims_4096.film", film_bytes(4096, 4096, 0)},
      {"checkpoint.nck", checkpoint_bytes(R"({"scene": {"film": {"width": 1}}})", pixel)},
      {"checkpoint_film_claims.nck", checkpoint_bytes("{}", film_bytes(2, 2, 1))},
      {"checkpoint_deep.nck", checkpoint_bytes(nested_arrays(2000), pixel)},
      {"checkpoint_twice.nck", checkpoint_bytes(R"({"a": 1, "a": 2})", pixel)},
      {"checkpoint_1e999.nck", checkpoint_bytes(R"({"a": 1e999})", pixel)},
      {"checkpoint_fingerprint_past_end.nck", checkpoint_bytes("{}", pixel, 4, 1u << 25)},
      {"instances.npy",
       npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", translations)},
      {"instances_negative_shape.npy",
       npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (-1, 3), }", translations)},
      {"instances_float_shape.npy",
       npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (2.3, 4), }", translations)},
      {"instances_descr_twice.npy",
       npy_bytes("{'descr': '<f4', 'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",
                 translations)},
      {"instances_no_brace.npy",
       npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), ", translations)},
      {"camera.json",
       R"({"type": "perspective", "from": [0, 1, 5], "to": [0, 0, 0], "up": [0, 1, 0], "fov": 30})"},
      {"camera_1e999.json", R"({"type": "perspective", "from": [0, 1, 1e999], "to": [0, 0, 0]})"},
      {"camera_twice.json", R"({"from": [0, 1, 5], "from": [0, 0, 0]})"},
      {"camera_deep.json", "{\"from\": " + nested_arrays(2000) + "}"},
  };
}

void write_corpus() {
  fs::create_directories(kCorpus);
  for (const auto& [name, bytes] : seeds())
    std::ofstream(kCorpus + name, std::ios::binary) << bytes;
}

// "" when `read` returns, else its one-line error.
std::string error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  return "";
}

TEST(FilesFuzzCorpus, EveryFileReadsToAValueOrOneLine) {
  if (std::getenv("NIMBUS_WRITE_FUZZ_CORPUS")) write_corpus();
  std::map<std::string, int> read;
  for (const auto& [name, bytes] : seeds()) {
    const std::string path = kCorpus + name;
    ASSERT_TRUE(fs::exists(path)) << path << " (NIMBUS_WRITE_FUZZ_CORPUS=1 writes it)";
    EXPECT_LE(fs::file_size(path), 8192u) << path << ": the seeds stay small";
    std::ifstream in(path, std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), {}};
    EXPECT_EQ(text, bytes) << path << " differs from what the generator writes";
    // As the fuzzer reads every input: with every reader.
    if (error_of([&] { load_checkpoint(path); }).empty()) ++read["checkpoint"];
    if (error_of([&] { load_film(path); }).empty()) ++read["film"];
    if (error_of([&] { read_instances_file(path); }).empty()) ++read["npy"];
    if (error_of([&] { parse_camera_body(text); }).empty()) ++read["camera"];
  }
  EXPECT_EQ(read, (std::map<std::string, int>{
                      {"camera", 1}, {"checkpoint", 1}, {"film", 1}, {"npy", 1}}));
}

}  // namespace files_fuzz_corpus_test
}  // namespace nimbus
