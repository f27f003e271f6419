#include "nimbus/io/film_file.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "nimbus/io/atomic_file.h"

namespace nimbus {

namespace {

constexpr char kFilmMagic[8] = {'N', 'I', 'M', 'F', 'I', 'L', 'M', '\0'};
// 2: exact sums (128-bit fixed point); 3: the film's exponent (version 2 files read as 0); 4: the
// AOV sums (earlier versions read as a film without them).
constexpr uint32_t kFilmVersion = 4;
static_assert(std::endian::native == std::endian::little, "film files are little endian");

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

Film read_film(std::istream& in, const std::string& name) {
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
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the film file");
  Film film = read_film(in, path);
  if (in.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path + ": trailing bytes after the film");
  return film;
}

}  // namespace nimbus
