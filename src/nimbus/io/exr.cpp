#include "nimbus/io/exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "nimbus/io/atomic_file.h"
#include "nimbus/os/regular_file.h"
#include "nimbus/render/memory_estimate.h"

namespace nimbus {
namespace {

constexpr const char* kChannels[3] = {"R", "G", "B"};

// OpenEXR reads through the regular file nimbus opened (os/regular_file.h), so that a FIFO or a
// device is refused before the library sees it, and the file read is the file checked.
class ExrInput : public Imf::IStream {
 public:
  explicit ExrInput(RegularFile& file) : Imf::IStream(file.path().c_str()), file_(file) {}
  bool read(char c[], int n) override {
    std::istream& in = file_.stream();
    in.read(c, n);
    if (in.gcount() != n) throw std::runtime_error("unexpected end of file");
    at_ += uint64_t(n);
    return at_ < file_.size();
  }
  uint64_t tellg() override { return at_; }
  void seekg(uint64_t pos) override {
    file_.stream().clear();
    file_.stream().seekg(std::streamoff(pos));
    at_ = pos;
  }
  void clear() override { file_.stream().clear(); }

 private:
  RegularFile& file_;
  uint64_t at_ = 0;
};

}  // namespace

void write_exr(const std::string& path, const Image& image) {
  if (!is_well_formed(image))
    throw std::runtime_error(path + ": image size does not match its pixel data");
  write_atomically(path, [&](const std::string& temp) {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    // The film's primaries are those of linear sRGB (Rec. 709), which is also OpenEXR's default;
    // stating them keeps readers from guessing.
    Imf::addChromaticities(header, Imf::Chromaticities());
    Imf::FrameBuffer frame;
    const size_t x_stride = 3 * sizeof(float), y_stride = x_stride * image.width;
    for (int c = 0; c < 3; ++c) {
      header.channels().insert(kChannels[c], Imf::Channel(Imf::FLOAT));
      // OpenEXR only reads through the slice, but its interface takes a non-const pointer.
      char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgb.data() + c));
      frame.insert(kChannels[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
    }
    for (const ImageLayer& layer : image.layers) {
      const size_t stride = layer.channels.size() * sizeof(float);
      for (size_t c = 0; c < layer.channels.size(); ++c) {
        const std::string name = layer.name + "." + layer.channels[c];
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        char* base = reinterpret_cast<char*>(const_cast<float*>(layer.values.data() + c));
        frame.insert(name, Imf::Slice(Imf::FLOAT, base, stride, stride * image.width));
      }
    }
    Imf::OutputFile file(temp.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  });
}

Image read_exr(const std::string& path) {
  RegularFile input(path);  // FileOpenError, "PATH: not a regular file (a FIFO)", as it is
  try {
    ExrInput stream(input);
    Imf::InputFile file(stream);
    const Imath::Box2i window = file.header().dataWindow();
    // The size its header claims, checked before it is allocated: a few bytes of header may claim
    // more pixels than memory holds (a compressed file's length does not bound its pixels).
    const int64_t w = int64_t(window.max.x) - window.min.x + 1;
    const int64_t h = int64_t(window.max.y) - window.min.y + 1;
    if (w <= 0 || h <= 0 || w > 1 << 20 || h > 1 << 20)
      throw std::runtime_error(fmt::format("a data window of {}x{} pixels", w, h));
    int channels = 0;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
      ++channels;
    const uint64_t need = uint64_t(w) * uint64_t(h) * uint64_t(std::max(channels, 3)) * 4;
    if (const uint64_t free = available_memory(); free != 0 && need > free)
      throw std::runtime_error(
          fmt::format("an image of {}x{} pixels in {} channels needs {}; {} "
                      "is available",
                      w, h, channels, format_memory(double(need)), format_memory(double(free))));
    Image image;
    image.width = int(w);
    image.height = int(h);
    const size_t pixels = static_cast<size_t>(image.width) * image.height;
    image.rgb.assign(3 * pixels, 0.0f);
    Imf::FrameBuffer frame;
    const auto insert = [&](const std::string& channel, float* base, size_t count) {
      frame.insert(channel, Imf::Slice::Make(Imf::FLOAT, base, window, count * sizeof(float),
                                             count * sizeof(float) * image.width));
    };
    for (int c = 0; c < 3; ++c) {
      if (!file.header().channels().findChannel(kChannels[c]))
        throw std::runtime_error(std::string("no ") + kChannels[c] + " channel");
      insert(kChannels[c], image.rgb.data() + c, 3);
    }
    const Imf::ChannelList& list = file.header().channels();
    for (auto it = list.begin(); it != list.end(); ++it) {
      const std::string channel = it.name();
      const size_t dot = channel.rfind('.');
      if (dot == std::string::npos) continue;
      const std::string name = channel.substr(0, dot);
      auto layer = std::find_if(image.layers.begin(), image.layers.end(),
                                [&](const ImageLayer& l) { return l.name == name; });
      if (layer == image.layers.end()) layer = image.layers.insert(layer, {name, {}, {}});
      layer->channels.push_back(channel.substr(dot + 1));
    }
    for (ImageLayer& layer : image.layers) {
      // Colours and vectors in their usual order; OpenEXR lists channels by name.
      const auto rank = [](const std::string& c) {
        const size_t at = std::string_view("RGBAXYZ").find(c);
        return c.size() == 1 && at != std::string_view::npos ? int(at) : 7;
      };
      std::stable_sort(
          layer.channels.begin(), layer.channels.end(),
          [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
      const size_t k = layer.channels.size();
      layer.values.assign(k * pixels, 0.0f);
      for (size_t c = 0; c < k; ++c)
        insert(layer.name + "." + layer.channels[c], layer.values.data() + c, k);
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace nimbus
