#include "nimbus/scene/instances_file.h"

#include <fmt/format.h>

#include <array>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <optional>
#include <regex>

#include "nimbus/os/regular_file.h"

namespace nimbus {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr std::size_t kMaxHeaderBytes = 1 << 16;

struct Header {
  int item_bytes = 8;  // 8: float64, 4: float32
  std::vector<std::size_t> shape;
};

// The header is a Python dict literal, e.g.
// {'descr': '<f8', 'fortran_order': False, 'shape': (1000, 3, 4), }
Header parse_header(const std::string& text) {
  const auto field = [&](const char* key, const char* value_pattern) -> std::string {
    const std::regex re(std::string("'") + key + "'\\s*:\\s*(" + value_pattern + ")");
    std::smatch m;
    if (!std::regex_search(text, m, re))
      throw InstancesFileError(fmt::format("the .npy header has no '{}'", key));
    return m[1].str();
  };
  Header h;
  const std::string descr = field("descr", "'[^']*'");
  if (descr == "'<f8'")
    h.item_bytes = 8;
  else if (descr == "'<f4'")
    h.item_bytes = 4;
  else
    throw InstancesFileError(fmt::format(
        "holds {} values; expected little-endian float64 ('<f8') or float32 ('<f4')", descr));
  if (field("fortran_order", "True|False") != "False")
    throw InstancesFileError("is in Fortran order; save a C-ordered array");
  const std::string shape = field("shape", "\\([^)]*\\)");
  const std::regex number("[0-9]+");
  for (auto it = std::sregex_iterator(shape.begin(), shape.end(), number);
       it != std::sregex_iterator(); ++it) {
    if (it->str().size() > 12) throw InstancesFileError("has a dimension too large to read");
    h.shape.push_back(std::stoull(it->str()));
  }
  return h;
}

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
  } else {
    throw InstancesFileError(
        fmt::format(".npy format version {} is not supported (1 to 3 are)", major));
  }
  if (!in || header_bytes > kMaxHeaderBytes) throw InstancesFileError("a broken .npy header");
  std::string text(header_bytes, '\0');
  if (!in.read(text.data(), std::streamsize(header_bytes)))
    throw InstancesFileError("a broken .npy header");
  const Header h = parse_header(text);

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
