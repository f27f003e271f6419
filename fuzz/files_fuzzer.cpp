// libFuzzer target (docs/testing.md, "Fuzzing"): arbitrary bytes as each file and body nimbus
// reads from outside besides scenes and grids (issue 44): a checkpoint, a film file, an .npy
// instances file, and the viewer's camera body. The readers take files, so each input is written
// to a file of this process first. A std::runtime_error (the readers' one-line errors: the scene
// loader's SceneError, InstancesFileError, FileOpenError) is the expected answer; any other
// exception (std::bad_alloc of a size believed too soon above all), a crash, a sanitizer report,
// a hang or a process above the RSS limit is a finding.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <typeinfo>

#include "nimbus/io/film_file.h"
#include "nimbus/job/checkpoint.h"
#include "nimbus/scene/instances_file.h"
#include "nimbus/view/camera_body.h"

namespace {

// /dev/shm keeps the writes in memory where there is one.
std::string scratch_file() {
  const std::filesystem::path dir = std::filesystem::is_directory("/dev/shm")
                                        ? "/dev/shm"
                                        : std::filesystem::temp_directory_path();
  return (dir / ("nimbus_files_fuzz_" + std::to_string(::getpid()))).string();
}

template <class Read>
void expect_one_line(const char* reader, Read&& read) {
  try {
    read();
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) {
      std::fprintf(stderr, "files fuzz: %s: a message of several lines: %s\n", reader, e.what());
      std::abort();
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "files fuzz: %s: %s: %s\n", reader, typeid(e).name(), e.what());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string file = scratch_file();
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  expect_one_line("checkpoint", [] { nimbus::load_checkpoint(file); });
  expect_one_line("film file", [] { nimbus::load_film(file); });
  expect_one_line("instances file", [] { nimbus::read_instances_file(file); });
  const std::string body(reinterpret_cast<const char*>(data), size);
  expect_one_line("camera body", [&] { nimbus::parse_camera_body(body); });
  return 0;
}
