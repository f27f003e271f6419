#pragma once
// A fast look at a scene while its camera moves (`nimbus view`): one ray through each pixel's
// centre, the exact first surface lit by a light at the eye, the index-matched media along the
// way as absorption, emission and scattering of a uniform unit light, by ray marching. No
// shadows, no bounces: not an estimate of the image, a picture of the shapes.

#include "nimbus/io/image.h"
#include "nimbus/render/scene.h"

namespace nimbus {

struct PreviewOptions {
  // The image is the film's size divided by this (rounded up): a preview of a large film stays
  // quick, and the viewer scales it up.
  int downscale = 1;
  int steps = 32;  // ray-marching steps through the media's bounds
};

// The preview of the scene through its camera. Deterministic (no random numbers).
Image render_preview(const Scene& scene, const PreviewOptions& options = {});

// The downscale that keeps a preview of a width × height film within `pixels` pixels.
int preview_downscale(int width, int height, int pixels);

}  // namespace nimbus
