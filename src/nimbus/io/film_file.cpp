#include "nimbus/io/film_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "nimbus/io/atomic_file.h"
#include "nimbus/os/regular_file.h"
#include "nimbus/render/memory_estimate.h"

namespace nimbus {

namespace {

constexpr char kFilmMagic[8] = {'N', 'I', 'M', 'F', 'I', 'L', 'M', '\0'};
// 2: exact sums (128-bit fixed point); 3: the film's exponent (version 2 files read as 0); 4: the
// AOV sums (earlier versions read as a film without them).
constexpr uint32_t kFilmVersion = 4;
static_assert(std::endian::native == std::endian::little, "film files are little endian");

// The bytes a pixel takes in the file (and, as much again, in memory): its count and sums, and
// the sums of each AOV layer.
uint64_t film_bytes_per_pixel(AovSet aovs) {
  const Film one(1, 1, 0, aovs, 0);
  uint64_t bytes = sizeof one.samples[0] + 3 * sizeof one.sum[0].c[0] + 3 * sizeof one.sum_sq[0][0];
  one.aov.for_each_vector([&](const auto& v) { bytes += v.size() * sizeof v[0]; });
  return bytes;
}

}  // namespace

void write_film(std::ostream& out, const Film& film) {
  auto put = [&](const auto& v) { out.write(reinterpret_cast<const char*>(&v), sizeof v); };
  out.write(kFilmMagic, sizeof kFilmMagic);
  put(kFilmVersion);
  put(static_cast<int32_t>(film.width));
  put(static_cast<int32_t>(film.height));
  put(static_cast<int32_t>(film.exponent));
  put(film.aov.layers.bits());
  put(static_cast<int32_t>(film.aov.depth_exponent));
  for (int p = 0; p < film.pixels(); ++p) {
    put(film.samples[p]);
    for (int c = 0; c < 3; ++c) put(film.sum[p].c[c]);
    for (int c = 0; c < 3; ++c) put(film.sum_sq[p][c]);
  }
  film.aov.for_each_vector([&](const auto& v) {
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof v[0]));
  });
}

Film read_film(std::istream& in, const std::string& name, uint64_t bytes) {
  const uint64_t start = uint64_t(in.tellg());
  auto get = [&](auto& v) {
    in.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!in) throw std::runtime_error(name + ": the film file is cut short");
  };
  char magic[sizeof kFilmMagic];
  in.read(magic, sizeof magic);
  if (!in || std::memcmp(magic, kFilmMagic, sizeof magic) != 0)
    throw std::runtime_error(name + ": not a nimbus film file");
  uint32_t version = 0;
  get(version);
  if (version < 2 || version > kFilmVersion)
    throw std::runtime_error(
        fmt::format("{}: film file version {}, this nimbus reads {}", name, version, kFilmVersion));
  int32_t w = 0, h = 0;
  get(w);
  get(h);
  if (w <= 0 || h <= 0 || w > 1 << 16 || h > 1 << 16)
    throw std::runtime_error(fmt::format("{}: a film of {}x{} pixels", name, w, h));
  int32_t exponent = 0;
  if (version >= 3) get(exponent);
  // film_exponent of any finite brightness lies well within this.
  if (exponent < -1200 || exponent > 1100)
    throw std::runtime_error(fmt::format("{}: a film of exponent {}", name, exponent));
  uint8_t layers = 0;
  int32_t depth_exponent = 0;
  if (version >= 4) {
    get(layers);
    get(depth_exponent);
  }
  const AovSet aovs = AovSet::from_bits(layers);
  if (aovs.recorded() != aovs)
    throw std::runtime_error(fmt::format("{}: a film of unknown AOV layers ({})", name, layers));
  if (depth_exponent < -1200 || depth_exponent > 1100)
    throw std::runtime_error(fmt::format("{}: a film of depth exponent {}", name, depth_exponent));
  // The pixels' size from the header, checked before anything of that size is allocated (issue
  // 44: 29 bytes claiming 4096 x 4096 pixels allocated 1.3 GB before saying "cut short").
  const uint64_t pixels = uint64_t(w) * uint64_t(h);
  const uint64_t need = pixels * film_bytes_per_pixel(aovs);
  const uint64_t have = bytes - std::min(bytes, uint64_t(in.tellg()) - start);
  if (need > have)
    throw std::runtime_error(fmt::format(
        "{}: the film file is damaged or cut short (its header claims {}x{} pixels, {} bytes, "
        "and {} follow)",
        name, w, h, need, have));
  if (const uint64_t free = available_memory(); free != 0 && need > free)
    throw std::runtime_error(fmt::format("{}: a film of {}x{} pixels needs {}; {} is available",
                                         name, w, h, format_memory(double(need)),
                                         format_memory(double(free))));
  Film film(w, h, exponent, aovs, depth_exponent);
  for (int p = 0; p < film.pixels(); ++p) {
    get(film.samples[p]);
    for (int c = 0; c < 3; ++c) get(film.sum[p].c[c]);
    for (int c = 0; c < 3; ++c) get(film.sum_sq[p][c]);
  }
  film.aov.for_each_vector([&](auto& v) {
    in.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * sizeof v[0]));
    if (!in) throw std::runtime_error(name + ": the film file is cut short");
  });
  return film;
}

void save_film(const Film& film, const std::string& path) {
  write_atomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary);
    write_film(out, film);
    out.flush();
    if (!out) throw std::runtime_error("cannot write the film");
  });
}

Film load_film(const std::string& path) {
  RegularFile file(path);  // a FIFO, a device or a directory is refused without blocking
  std::istream& in = file.stream();
  Film film = read_film(in, path, file.size());
  if (in.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path + ": trailing bytes after the film");
  return film;
}

}  // namespace nimbus
