#pragma once
// A film's pixel means as an image for the writers.

#include "nimbus/io/image.h"
#include "nimbus/render/film.h"

namespace nimbus {

Image to_image(const Film& film);

}  // namespace nimbus
