#pragma once
// A rendered image as the writers take it: linear RGB floats, row-major, top row first.

#include <cstddef>
#include <string>
#include <vector>

namespace nimbus {

// A layer beside the colour, such as an AOV (render/aov.h): channels `name.C` in an EXR.
struct ImageLayer {
  std::string name;                   // "albedo"
  std::vector<std::string> channels;  // "R", "G", "B"
  std::vector<float> values;          // channels.size() per pixel, pixel by pixel
};

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;               // 3 * width * height values: R, G, B of each pixel in turn
  std::vector<ImageLayer> layers = {};  // written by the EXR writer only
};

// Whether the pixel data matches the stated size; writers refuse images that are not.
inline bool is_well_formed(const Image& image) {
  const size_t pixels = static_cast<size_t>(image.width) * image.height;
  if (image.width <= 0 || image.height <= 0 || image.rgb.size() != 3 * pixels) return false;
  for (const ImageLayer& l : image.layers)
    if (l.channels.empty() || l.values.size() != l.channels.size() * pixels) return false;
  return true;
}

}  // namespace nimbus
