#include "nimbus/io/film_image.h"

#include <stdexcept>
#include <string>
#include <type_traits>

#include "nimbus/render/setting_names.h"

namespace nimbus {
namespace {

// The layer of `aov`, each pixel's values from value(pixel) (an Rgb, Vec3 or double).
template <class Value>
ImageLayer layer(const Film& film, Aov aov, std::vector<std::string> channels, Value&& value) {
  ImageLayer l{std::string(name_of(kAovNames, aov)), std::move(channels), {}};
  l.values.reserve(l.channels.size() * size_t(film.pixels()));
  for (int p = 0; p < film.pixels(); ++p) {
    const auto v = value(p);
    if constexpr (std::is_same_v<decltype(v), const double>) {
      l.values.push_back(static_cast<float>(v));
    } else {
      for (int c = 0; c < 3; ++c) l.values.push_back(static_cast<float>(v[c]));
    }
  }
  return l;
}

}  // namespace

Image to_image(const Film& film, AovSet aovs) {
  Image img{film.width, film.height, std::vector<float>(size_t(film.width) * film.height * 3)};
  for (int p = 0; p < film.width * film.height; ++p) {
    const Rgb m = film.mean(p);
    for (int c = 0; c < 3; ++c) img.rgb[3 * size_t(p) + c] = static_cast<float>(m[c]);
  }
  const AovSums& a = film.aov;
  for (Aov aov : kAllAovs) {
    if (!aovs.has(aov)) continue;
    if (aov != Aov::Variance && aov != Aov::Samples && !a.layers.has(aov))
      throw std::invalid_argument(std::string("the film holds no sums of the AOV ") +
                                  std::string(name_of(kAovNames, aov)));
    switch (aov) {
      case Aov::Albedo:
        img.layers.push_back(layer(film, aov, {"R", "G", "B"},
                                   [&](int p) { return a.albedo_mean(p, film.samples[p]); }));
        break;
      case Aov::Normal:
        img.layers.push_back(layer(film, aov, {"X", "Y", "Z"},
                                   [&](int p) { return a.normal_mean(p, film.samples[p]); }));
        break;
      case Aov::Depth:
        img.layers.push_back(layer(film, aov, {"Z"}, [&](int p) { return a.depth_mean(p); }));
        break;
      case Aov::Variance:
        img.layers.push_back(
            layer(film, aov, {"R", "G", "B"}, [&](int p) { return film.variance_of_mean(p); }));
        break;
      case Aov::Samples:
        img.layers.push_back(
            layer(film, aov, {"N"}, [&](int p) { return double(film.samples[p]); }));
        break;
      case Aov::Half:
        break;
    }
  }
  return img;
}

}  // namespace nimbus
