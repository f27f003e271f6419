// libFuzzer target (docs/testing.md, "Fuzzing"): arbitrary bytes as a VDB file, read by nimbus's
// reader (media/vdb_file.h) into a "vdb" density. The reader takes a file name (OpenVDB's and
// NanoVDB's readers work on files), so each input is written to a file of this process first. A
// VdbError is the expected answer to bad input; any other exception, a crash, a sanitizer report,
// a hang, or a grid that loads but answers a value that is negative, not finite or outside its
// own range() is a finding.

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "nimbus/nimbus.h"

namespace {

// /dev/shm keeps the writes in memory where there is one.
std::string scratch_file() {
  const std::filesystem::path dir = std::filesystem::is_directory("/dev/shm")
                                        ? "/dev/shm"
                                        : std::filesystem::temp_directory_path();
  return (dir / ("nimbus_vdb_fuzz_" + std::to_string(::getpid()) + ".vdb")).string();
}

[[noreturn]] void finding(const char* what, double value) {
  std::fprintf(stderr, "vdb fuzz: %s (%g)\n", what, value);
  std::abort();
}

// A loaded grid must keep the density's promises: values >= 0 and finite, inside range() over a
// box that holds them. The probes, 4³ points, cover the voxels around the origin, where the
// corpus's grids and most mutated ones lie.
void check(const nimbus::Density& d) {
  const nimbus::Box box{{-4, -4, -4}, {4, 4, 4}};
  const nimbus::Interval r = d.range(box, {1, 1});
  if (!(r.lo >= 0) || !(r.lo <= r.hi)) finding("range() is not an interval of densities", r.lo);
  for (int i = 0; i < 64; ++i) {
    const nimbus::Vec3 x{-3.9 + 2.6 * (i % 4), -3.9 + 2.6 * (i / 4 % 4), -3.9 + 2.6 * (i / 16)};
    const double v = d.value(x, 1);
    if (!std::isfinite(v) || v < 0) finding("value() is not a finite density", v);
    if (v < r.lo || v > r.hi) finding("value() lies outside range()", v);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string file = scratch_file();
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  nimbus::VdbParams params;
  params.file = file;
  params.isolate_reader = false;  // coverage of OpenVDB's reading is gathered in this process
  try {
    check(*nimbus::make_vdb_density(params));
  } catch (const nimbus::VdbError&) {
    return 0;
  }
  return 0;
}
