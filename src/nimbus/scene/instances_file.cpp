#include "nimbus/scene/instances_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <optional>

#include "nimbus/os/regular_file.h"
#include "nimbus/scene/npy_header.h"

namespace nimbus {
namespace {

constexpr char kMagic[] = "\x93NUMPY";

std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

}  // namespace

std::vector<Mat4> read_instances_file(const std::string& path) {
  static_assert(std::endian::native == std::endian::little, "reads little-endian data in place");
  std::optional<RegularFile> file;
  try {
    file.emplace(path);
  } catch (const FileOpenError& e) {
    throw InstancesFileError(e.reason);
  }
  std::istream& in = file->stream();
  const uint64_t file_bytes = file->size();

  std::array<char, 8> lead{};
  if (!in.read(lead.data(), lead.size()) || std::memcmp(lead.data(), kMagic, 6) != 0)
    throw InstancesFileError("not a .npy file (write it with numpy.save)");
  const int major = static_cast<unsigned char>(lead[6]);
  const int minor = static_cast<unsigned char>(lead[7]);
  std::size_t header_bytes = 0;
  if (major == 1) {
    std::array<unsigned char, 2> n{};
    in.read(reinterpret_cast<char*>(n.data()), 2);
    header_bytes = n[0] | std::size_t(n[1]) << 8;
  } else if (major == 2 || major == 3) {
    std::array<unsigned char, 4> n{};
    in.read(reinterpret_cast<char*>(n.data()), 4);
    header_bytes =
        n[0] | std::size_t(n[1]) << 8 | std::size_t(n[2]) << 16 | std::size_t(n[3]) << 24;
  }
  // numpy reads versions 1.0, 2.0 and 3.0 only.
  if (major < 1 || major > 3 || minor != 0)
    throw InstancesFileError(fmt::format(
        ".npy format version {}.{} is not supported (1.0, 2.0 and 3.0 are)", major, minor));
  if (!in) throw InstancesFileError("a broken .npy header: the file ends in its length");
  const std::size_t preamble = major == 1 ? 10 : 12;
  // Checked before anything is allocated: a length past the file or numpy's limit.
  if (header_bytes > file_bytes - std::min<std::uintmax_t>(file_bytes, preamble))
    throw InstancesFileError(fmt::format(
        "a broken .npy header: its length, {} bytes, is past the end of the file", header_bytes));
  if (header_bytes > kMaxNpyHeaderBytes)
    throw InstancesFileError(fmt::format("a .npy header of {} bytes; numpy reads at most {}",
                                         header_bytes, kMaxNpyHeaderBytes));
  std::string text(header_bytes, '\0');
  if (!in.read(text.data(), std::streamsize(header_bytes)))
    throw InstancesFileError("a broken .npy header: the file ends in it");
  NpyHeader h;
  try {
    h = parse_npy_header(text);
  } catch (const NpyHeaderError& e) {
    throw InstancesFileError(e.what());
  }

  const auto& s = h.shape;
  const bool translations = s.size() == 2 && s[1] == 3;
  const bool rows = s.size() == 3 && s[1] == 3 && s[2] == 4;
  const bool matrices = s.size() == 3 && s[1] == 4 && s[2] == 4;
  if (!translations && !rows && !matrices)
    throw InstancesFileError(fmt::format(
        "holds an array of shape {}; expected (N, 3) translations, (N, 3, 4) or (N, 4, 4) "
        "transforms",
        shape_text(s)));
  const std::size_t n = s[0];
  if (n == 0) throw InstancesFileError("holds no instances");
  if (n > kMaxInstances)
    throw InstancesFileError(
        fmt::format("holds {} instances; an object may have at most {}", n, kMaxInstances));
  const std::size_t per = translations ? 3 : rows ? 12 : 16;
  const std::size_t data_bytes = n * per * std::size_t(h.item_bytes);
  const std::size_t offset = std::size_t(in.tellg());
  if (file_bytes != offset + data_bytes)
    throw InstancesFileError(fmt::format("has {} bytes of data; an array of shape {} needs {}",
                                         file_bytes - std::min<std::uintmax_t>(file_bytes, offset),
                                         shape_text(s), data_bytes));

  std::vector<Mat4> transforms(n);
  std::vector<char> chunk(std::size_t{1} << 20);
  const std::size_t record = per * std::size_t(h.item_bytes);
  const std::size_t per_chunk = chunk.size() / record;
  for (std::size_t first = 0; first < n; first += per_chunk) {
    const std::size_t count = std::min(per_chunk, n - first);
    if (!in.read(chunk.data(), std::streamsize(count * record)))
      throw InstancesFileError(fmt::format("cannot read file ({})", std::strerror(errno)));
    for (std::size_t k = 0; k < count; ++k) {
      const char* p = chunk.data() + k * record;
      const auto value = [&](std::size_t i) {
        if (h.item_bytes == 8) {
          double v;
          std::memcpy(&v, p + 8 * i, 8);
          return v;
        }
        float v;
        std::memcpy(&v, p + 4 * i, 4);
        return double(v);
      };
      Mat4& m = transforms[first + k];
      if (translations) {
        m = Mat4::translate({value(0), value(1), value(2)});
        continue;
      }
      for (int r = 0; r < (rows ? 3 : 4); ++r)
        for (int c = 0; c < 4; ++c) m(r, c) = value(std::size_t(4 * r + c));
      if (rows) m.m[3] = {0, 0, 0, 1};
      if (matrices && (m(3, 0) != 0 || m(3, 1) != 0 || m(3, 2) != 0 || m(3, 3) != 1))
        throw InstancesFileError(fmt::format(
            "instance {}: the last row is not 0 0 0 1 (only affine transforms place a shape)",
            first + k));
    }
  }
  return transforms;
}

}  // namespace nimbus
