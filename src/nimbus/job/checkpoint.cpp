#include "nimbus/job/checkpoint.h"

#include <fmt/format.h>

#include <cstring>
#include <fstream>
#include <stdexcept>

#include "nimbus/io/atomic_file.h"
#include "nimbus/io/film_file.h"

namespace nimbus {

namespace {

constexpr char kMagic[8] = {'N', 'I', 'M', 'C', 'K', 'P', 'T', '\0'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kMaxFingerprintBytes = 64u << 20;  // a scene file's limit (scene/load.h)

}  // namespace

void save_checkpoint(const Checkpoint& c, const std::string& path) {
  const std::string fingerprint = c.fingerprint.dump();
  write_atomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary);
    auto put = [&](const auto& v) { out.write(reinterpret_cast<const char*>(&v), sizeof v); };
    out.write(kMagic, sizeof kMagic);
    put(kVersion);
    put(static_cast<int32_t>(c.spp));
    put(c.majorants);
    put(static_cast<uint32_t>(fingerprint.size()));
    out.write(fingerprint.data(), std::streamsize(fingerprint.size()));
    write_film(out, c.film);
    out.flush();
    if (!out) throw std::runtime_error("cannot write the checkpoint");
  });
}

Checkpoint load_checkpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open the checkpoint");
  auto get = [&](auto& v) {
    in.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!in) throw std::runtime_error(path + ": the checkpoint is cut short");
  };
  char magic[sizeof kMagic];
  in.read(magic, sizeof magic);
  if (!in || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw std::runtime_error(path + ": not a nimbus checkpoint");
  uint32_t version = 0;
  get(version);
  if (version != kVersion)
    throw std::runtime_error(
        fmt::format("{}: checkpoint version {}, this nimbus reads {}", path, version, kVersion));
  Checkpoint c;
  int32_t spp = 0;
  get(spp);
  c.spp = spp;
  get(c.majorants);
  uint32_t size = 0;
  get(size);
  if (size > kMaxFingerprintBytes) throw std::runtime_error(path + ": not a nimbus checkpoint");
  std::string fingerprint(size, '\0');
  in.read(fingerprint.data(), size);
  if (!in) throw std::runtime_error(path + ": the checkpoint is cut short");
  c.fingerprint = nlohmann::json::parse(fingerprint, nullptr, false);
  if (c.fingerprint.is_discarded() || spp < 1)
    throw std::runtime_error(path + ": not a nimbus checkpoint");
  c.film = read_film(in, path);
  if (in.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path + ": trailing bytes after the checkpoint");
  return c;
}

uint64_t samples_held(const Film& film) {
  uint64_t n = 0;
  for (uint32_t s : film.samples) n += s;
  return n;
}

}  // namespace nimbus
