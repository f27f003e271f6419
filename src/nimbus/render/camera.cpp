#include "nimbus/render/camera.h"

#include <cmath>
#include <numbers>

namespace nimbus {
namespace {

Camera frame(Camera::Type type, const Vec3& from, const Vec3& to, const Vec3& up, int width,
             int height) {
  Camera c;
  c.type = type;
  c.origin = from;
  c.forward = normalize(to - from);
  c.right = normalize(cross(c.forward, up));
  c.up = cross(c.right, c.forward);
  c.width = width;
  c.height = height;
  return c;
}

}  // namespace

Ray Camera::generate(double x, double y) const {
  const double sx = (2.0 * x / width - 1.0) * half_width;
  const double sy = (1.0 - 2.0 * y / height) * half_height;
  if (type == Type::Orthographic) return {origin + right * sx + up * sy, forward};
  return {origin, normalize(forward + right * sx + up * sy)};
}

Camera perspective_camera(const Vec3& from, const Vec3& to, const Vec3& up, double fov_degrees,
                          int width, int height) {
  Camera c = frame(Camera::Type::Perspective, from, to, up, width, height);
  c.half_height = std::tan(0.5 * fov_degrees * std::numbers::pi / 180.0);
  c.half_width = c.half_height * width / height;
  return c;
}

Camera orthographic_camera(const Vec3& from, const Vec3& to, const Vec3& up, double view_width,
                           int width, int height) {
  Camera c = frame(Camera::Type::Orthographic, from, to, up, width, height);
  c.half_width = 0.5 * view_width;
  c.half_height = c.half_width * height / width;
  return c;
}

}  // namespace nimbus
