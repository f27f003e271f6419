#pragma once
// OpenEXR files of linear float RGB: the renderer's lossless output and the format of reference
// images.

#include <string>

#include "nimbus/io/image.h"

namespace nimbus {

// Writes R, G, B and each layer's channels (`albedo.R`, ...) as 32-bit float channels (ZIP
// compressed, lossless), atomically. Throws std::runtime_error("PATH: problem").
void write_exr(const std::string& path, const Image& image);

// Reads the R, G and B channels of a scanline or tiled EXR (half or float) as floats, and its
// channels `NAME.C` as layers (NAME the part before the last dot): the channels R, G, B, A, X, Y,
// Z of a layer in that order, then the others by name. Throws std::runtime_error("PATH:
// problem").
Image read_exr(const std::string& path);

}  // namespace nimbus
