#pragma once
// The path tracer: radiance arriving along a camera ray.

#include "nimbus/math/ray.h"
#include "nimbus/math/rng.h"
#include "nimbus/render/counters.h"
#include "nimbus/render/scene.h"
#include "nimbus/spectral/spectrum.h"

namespace nimbus {

Rgb radiance(const Scene& scene, Ray ray, Rng& rng, Counters& counters);

}  // namespace nimbus
