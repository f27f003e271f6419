#pragma once
// 8-bit sRGB PNG files: the preview output, for looking at, not for measuring.

#include <cstdint>
#include <string>

#include "nimbus/io/image.h"

namespace nimbus {

// The sRGB transfer function (IEC 61966-2-1) of a linear value clamped to [0, 1], rounded to
// 8 bits. NaN maps to 0.
uint8_t encode_srgb8(float linear);

// Writes the image as 8-bit RGB with an sRGB chunk, atomically. Throws
// std::runtime_error("PATH: problem").
void write_png(const std::string& path, const Image& image);

// The same image as the bytes of a PNG file (what write_png writes), for serving. Throws
// std::runtime_error("libpng: problem").
std::string encode_png(const Image& image);

}  // namespace nimbus
