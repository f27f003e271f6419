#include "nimbus/job/checkpoint.h"

#include <fmt/format.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "nimbus/io/atomic_file.h"
#include "nimbus/io/film_file.h"
#include "nimbus/os/regular_file.h"
#include "nimbus/scene/json_text.h"

namespace nimbus {

namespace {

constexpr char kMagic[8] = {'N', 'I', 'M', 'C', 'K', 'P', 'T', '\0'};
// 2: a CRC-32 of everything before it ends the file, so that a damaged checkpoint is refused
// rather than resumed (issue 29: one flipped byte of a pixel gave an image mean of -5e12).
constexpr uint32_t kVersion = 2;
constexpr uint32_t kMaxFingerprintBytes = 64u << 20;  // a scene file's limit (scene/json_text.h)

// zlib's CRC-32 of the `length` bytes from the stream's start (the stream is left after them).
uint32_t crc32_of(std::istream& in, uint64_t length, const std::string& path) {
  in.clear();
  in.seekg(0);
  std::vector<char> buffer(1 << 20);
  uLong crc = crc32_z(0, nullptr, 0);
  while (length > 0) {
    const size_t n = size_t(std::min<uint64_t>(length, buffer.size()));
    if (!in.read(buffer.data(), std::streamsize(n)))
      throw std::runtime_error(path + ": cannot read the checkpoint back");
    crc = crc32_z(crc, reinterpret_cast<const Bytef*>(buffer.data()), n);
    length -= n;
  }
  return uint32_t(crc);
}

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
    out.close();
    if (!out) throw std::runtime_error("cannot write the checkpoint");
    // The checksum of the bytes as the file holds them.
    RegularFile written(temp);
    const uint32_t crc = crc32_of(written.stream(), written.size(), temp);
    std::ofstream tail(temp, std::ios::binary | std::ios::app);
    tail.write(reinterpret_cast<const char*>(&crc), sizeof crc);
    tail.close();
    if (!tail) throw std::runtime_error("cannot write the checkpoint");
  });
}

Checkpoint load_checkpoint(const std::string& path) {
  RegularFile file(path);  // a FIFO, a device or a directory is refused without blocking
  std::istream& in = file.stream();
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
  // The checksum first: nothing of a damaged file is trusted, not even the film's size.
  const uint64_t bytes = file.size();
  uint32_t crc = 0;
  if (bytes < sizeof kMagic + sizeof version + sizeof crc)
    throw std::runtime_error(path + ": the checkpoint is cut short");
  const uint64_t covered = bytes - sizeof crc;
  in.seekg(std::streamoff(covered));
  get(crc);
  if (crc != crc32_of(in, covered, path))
    throw std::runtime_error(path +
                             ": the checkpoint is damaged or cut short (its checksum does not "
                             "match)");
  // A file with the right checksum may still be made to harm its reader: every size in it is
  // checked against the bytes that follow, and its JSON against the scene loader's limits.
  in.seekg(std::streamoff(sizeof kMagic + sizeof version));
  Checkpoint c;
  int32_t spp = 0;
  get(spp);
  c.spp = spp;
  get(c.majorants);
  uint32_t size = 0;
  get(size);
  if (size > kMaxFingerprintBytes || size > covered - uint64_t(in.tellg()))
    throw std::runtime_error(path + ": not a nimbus checkpoint (its fingerprint's size)");
  std::string fingerprint(size, '\0');
  in.read(fingerprint.data(), size);
  if (!in) throw std::runtime_error(path + ": the checkpoint is cut short");
  try {
    // The scene's document sits one level down in the fingerprint (job/fingerprint.h).
    c.fingerprint = parse_json_text(fingerprint, path + ": the fingerprint", kMaxJsonDepth + 1);
  } catch (const SceneError& e) {
    throw std::runtime_error(e.what());
  }
  if (!c.fingerprint.is_object() || spp < 1)
    throw std::runtime_error(path + ": not a nimbus checkpoint");
  const uint64_t film_at = uint64_t(in.tellg());
  c.film = read_film(in, path, covered - film_at);
  if (uint64_t(in.tellg()) != covered)
    throw std::runtime_error(path + ": trailing bytes after the checkpoint");
  return c;
}

uint64_t samples_held(const Film& film) {
  uint64_t n = 0;
  for (uint32_t s : film.samples) n += s;
  return n;
}

}  // namespace nimbus
