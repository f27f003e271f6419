#pragma once
// Reference images by quadrature: each pixel's mean of a closed-form radiance over its
// footprint, for the render tests to compare against (film_chi2.h).

#include <functional>
#include <vector>

#include "nimbus/math/ray.h"
#include "nimbus/render/camera.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus::test {

// Each pixel's mean of radiance(ray) over a k × k grid of its footprint.
inline std::vector<Rgb> pixel_references(const Camera& camera, int width, int height, int k,
                                         const std::function<Rgb(const Ray&)>& radiance) {
  std::vector<Rgb> ref(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Rgb sum(0.0);
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j)
          sum += radiance(camera.generate(x + (i + 0.5) / k, y + (j + 0.5) / k));
      ref[size_t(y) * width + x] = sum / double(k * k);
    }
  return ref;
}

}  // namespace nimbus::test
