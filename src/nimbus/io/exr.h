#pragma once
// OpenEXR files of linear float RGB: the renderer's lossless output and the format of reference
// images.

#include <string>

#include "nimbus/io/image.h"

namespace nimbus {

// Writes R, G, B as 32-bit float channels (ZIP compressed, lossless), atomically. Throws
// std::runtime_error("PATH: problem").
void write_exr(const std::string& path, const Image& image);

// Reads the R, G and B channels of a scanline or tiled EXR (half or float) as floats. Throws
// std::runtime_error("PATH: problem").
Image read_exr(const std::string& path);

}  // namespace nimbus
