#pragma once
// Pinhole (perspective) and orthographic cameras. Raster coordinates: x right, y down, pixel
// (i, j) covers [i, i+1) × [j, j+1).

#include "nimbus/math/ray.h"
#include "nimbus/math/vec3.h"

namespace nimbus {

struct Camera {
  enum class Type { Perspective, Orthographic };
  Type type = Type::Perspective;
  Vec3 origin;
  Vec3 forward, right, up;  // orthonormal
  double half_width = 1;    // of the image plane at distance 1 (perspective) or in scene units
  double half_height = 1;
  int width = 1, height = 1;

  // A unit-direction ray through raster position (x, y).
  Ray generate(double x, double y) const;
};

// fov_degrees is the vertical field of view.
Camera perspective_camera(const Vec3& from, const Vec3& to, const Vec3& up, double fov_degrees,
                          int width, int height);
// view_width is the width of the view in scene units; the height follows the film's aspect.
Camera orthographic_camera(const Vec3& from, const Vec3& to, const Vec3& up, double view_width,
                           int width, int height);

}  // namespace nimbus
