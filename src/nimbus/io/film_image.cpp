#include "nimbus/io/film_image.h"

namespace nimbus {

Image to_image(const Film& film) {
  Image img{film.width, film.height, std::vector<float>(size_t(film.width) * film.height * 3)};
  for (int p = 0; p < film.width * film.height; ++p) {
    const Rgb m = film.mean(p);
    for (int c = 0; c < 3; ++c) img.rgb[3 * size_t(p) + c] = static_cast<float>(m[c]);
  }
  return img;
}

}  // namespace nimbus
