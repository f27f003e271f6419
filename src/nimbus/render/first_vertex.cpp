#include "nimbus/render/first_vertex.h"

#include "nimbus/media/medium_field.h"

namespace nimbus {

void FirstVertexRecorder::record_medium(const Scene& scene, const Ray& ray, double t, int inside) {
  camera_ray_ends(t);
  Rgb mu_s(0.0), mu_t(0.0);
  const Vec3 x = ray.at(t);
  for_each_medium_at(scene, x, inside, [&](int m, double density, double F, int object) {
    const Medium& medium = scene.media[size_t(m)];
    const Vec3 xt = texture_point(scene, scene.objects[size_t(object)], x);
    const Rgb s = textured_rgb(medium.sigma_s, medium.sigma_s_to, medium.sigma_s_texture, xt, F);
    const Rgb a = textured_rgb(medium.sigma_a, medium.sigma_a_to, medium.sigma_a_texture, xt, F);
    mu_s += s * density;
    mu_t += (a + s) * density;
  });
  Rgb albedo(0.0);
  for (int c = 0; c < 3; ++c)
    if (mu_t[c] > 0) albedo[c] = mu_s[c] / mu_t[c];
  set(albedo, -ray.d);
  pending_ = false;
}

}  // namespace nimbus
