#include "nimbus/io/output.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include "nimbus/io/atomic_file.h"
#include "nimbus/io/exr.h"
#include "nimbus/io/png.h"

namespace nimbus {
namespace {

enum class Format { Exr, Png };

Format format_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".exr") return Format::Exr;
  if (ext == ".png") return Format::Png;
  throw std::runtime_error(path + ": unknown image format (use .exr or .png)");
}

}  // namespace

void write_image(const std::string& path, const Image& image) {
  switch (format_of(path)) {
    case Format::Exr:
      write_exr(path, image);
      return;
    case Format::Png:
      write_png(path, image);
      return;
  }
}

void check_output_path(const std::string& path) {
  format_of(path);
  check_writable_path(path);
}

void check_writable_path(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path parent = fs::path(path).parent_path();
  const fs::path dir = parent.empty() ? fs::path(".") : parent;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw std::runtime_error(path + ": directory " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0)
    throw std::runtime_error(path + ": directory " + dir.string() + " is not writable");
  if (fs::is_directory(path, ec)) throw std::runtime_error(path + ": is a directory");
  // The temporary file's name is longer than the target's (io/atomic_file.h): a name that is
  // legal but leaves no room for it failed only after the render (issue 29).
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  const size_t most = size_t(name_max > 0 ? name_max : 255) - kTempSuffixMaxBytes;
  if (const size_t name = fs::path(path).filename().string().size(); name > most)
    throw std::runtime_error(fmt::format(
        "{}: the file name has {} bytes; an output's may have at most {} (the folder's {}, less "
        "room for its temporary file)",
        path, name, most, name_max > 0 ? name_max : 255));
  // Files there are devices and kernel interfaces, not images: /dev/full.exr was written.
  const std::string real = fs::weakly_canonical(fs::absolute(dir), ec).string();
  for (const char* special : {"/dev", "/proc", "/sys"})
    if (real == special || real.rfind(std::string(special) + "/", 0) == 0)
      throw std::runtime_error(path + ": refusing to write into " + special +
                               " (a folder of devices and kernel files)");
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))
    throw std::runtime_error(path + ": exists and is not a regular file");
}

bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return ca == cb;
}

void check_outputs_distinct(const std::vector<NamedFile>& outputs,
                            const std::vector<NamedFile>& inputs, const std::string& reader) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    const NamedFile& out = outputs[i];
    for (const NamedFile& in : inputs)
      if (same_file(out.path, in.path))
        throw std::runtime_error(fmt::format("{} {}: is {} ({}), which {} reads", out.what,
                                             out.path, in.what, in.path, reader));
    for (size_t j = 0; j < i; ++j)
      if (same_file(out.path, outputs[j].path))
        throw std::runtime_error(fmt::format("{} {}: is also the output of {} ({})", out.what,
                                             out.path, outputs[j].what, outputs[j].path));
  }
}

std::vector<NamedFile> scene_inputs(const std::string& scene_file,
                                    const std::vector<InputFile>& read) {
  std::vector<NamedFile> inputs;
  if (!scene_file.empty()) inputs.push_back({"the scene file", scene_file});
  for (const InputFile& f : read) inputs.push_back({"the file of " + f.pointer, f.path});
  return inputs;
}

}  // namespace nimbus
