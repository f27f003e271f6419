#include "nimbus/io/png.h"

#include <png.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "nimbus/io/atomic_file.h"

namespace nimbus {

uint8_t encode_srgb8(float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  if (linear >= 1.0f) return 255;
  const double v = linear;
  const double encoded = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
  return static_cast<uint8_t>(std::lround(255.0 * encoded));
}

namespace {

// The image's pixels in 8-bit sRGB and libpng's description of them.
std::vector<uint8_t> srgb8_pixels(const Image& image, png_image& png) {
  std::vector<uint8_t> bytes(image.rgb.size());
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = encode_srgb8(image.rgb[i]);
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  return bytes;
}

}  // namespace

void write_png(const std::string& path, const Image& image) {
  if (!is_well_formed(image))
    throw std::runtime_error(path + ": image size does not match its pixel data");
  png_image png;
  const std::vector<uint8_t> bytes = srgb8_pixels(image, png);
  write_atomically(path, [&](const std::string& temp) {
    // libpng's simplified interface reports errors through its return value, so no longjmp
    // crosses C++ frames. It marks 8-bit output as sRGB.
    const int ok = png_image_write_to_file(&png, temp.c_str(), 0, bytes.data(), 0, nullptr);
    const std::string message = png.message;
    png_image_free(&png);
    if (!ok) throw std::runtime_error("libpng: " + message);
  });
}

std::string encode_png(const Image& image) {
  if (!is_well_formed(image))
    throw std::runtime_error("libpng: image size does not match its pixel data");
  png_image png;
  const std::vector<uint8_t> bytes = srgb8_pixels(image, png);
  // Asked first for its size, libpng then writes into a buffer of that size.
  png_alloc_size_t size = 0;
  if (png_image_write_to_memory(&png, nullptr, &size, 0, bytes.data(), 0, nullptr)) {
    std::string out(size, '\0');
    if (png_image_write_to_memory(&png, out.data(), &size, 0, bytes.data(), 0, nullptr)) {
      png_image_free(&png);
      out.resize(size);
      return out;
    }
  }
  const std::string message = png.message;
  png_image_free(&png);
  throw std::runtime_error("libpng: " + message);
}

}  // namespace nimbus
