#pragma once
// A rendered image as the writers take it: linear RGB floats, row-major, top row first.

#include <cstddef>
#include <vector>

namespace nimbus {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 * width * height values: R, G, B of each pixel in turn
};

// Whether the pixel data matches the stated size; writers refuse images that are not.
inline bool is_well_formed(const Image& image) {
  return image.width > 0 && image.height > 0 &&
         image.rgb.size() == 3 * static_cast<size_t>(image.width) * image.height;
}

}  // namespace nimbus
