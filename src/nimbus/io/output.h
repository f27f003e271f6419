#pragma once
// Choosing the image writer from the output file's extension, and checking an output path before
// a long render rather than after it.

#include <string>

#include "nimbus/io/image.h"

namespace nimbus {

// Writes `.exr` (linear float) or `.png` (8-bit sRGB), extension case-insensitive. Throws
// std::runtime_error("PATH: unknown image format (use .exr or .png)") for any other extension.
void write_image(const std::string& path, const Image& image);

// Throws std::runtime_error("PATH: problem") unless the extension is known, the directory exists
// and is writable and is not /dev, /proc or /sys (or inside them), and the path is not itself a
// directory or another file that is not a regular one.
void check_output_path(const std::string& path);

// The same check for a file of any kind: the directory exists and is writable, and the path is
// not itself a directory.
void check_writable_path(const std::string& path);

}  // namespace nimbus
