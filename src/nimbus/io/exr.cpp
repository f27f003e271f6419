#include "nimbus/io/exr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>

#include <stdexcept>

#include "nimbus/io/atomic_file.h"

namespace nimbus {
namespace {

constexpr const char* kChannels[3] = {"R", "G", "B"};

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
    Imf::OutputFile file(temp.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  });
}

Image read_exr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    Image image;
    image.width = window.max.x - window.min.x + 1;
    image.height = window.max.y - window.min.y + 1;
    image.rgb.assign(3 * static_cast<size_t>(image.width) * image.height, 0.0f);
    Imf::FrameBuffer frame;
    for (int c = 0; c < 3; ++c) {
      if (!file.header().channels().findChannel(kChannels[c]))
        throw std::runtime_error(std::string("no ") + kChannels[c] + " channel");
      frame.insert(kChannels[c],
                   Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, window, 3 * sizeof(float),
                                    3 * sizeof(float) * image.width));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace nimbus
