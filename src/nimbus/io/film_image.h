#pragma once
// A film's pixel means as an image for the writers, with the AOV layers asked for.

#include "nimbus/io/image.h"
#include "nimbus/render/aov.h"
#include "nimbus/render/film.h"

namespace nimbus {

// The colour, and a layer per AOV of `aovs` (render/aov.h): albedo.R/G/B, normal.X/Y/Z, depth.Z
// and variance.R/G/B, in that order. std::invalid_argument if the film does not hold the sums
// of one of them (make_film with the AOVs in the scene's settings).
Image to_image(const Film& film, AovSet aovs = {});

}  // namespace nimbus
