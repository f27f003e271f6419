#include "nimbus/render/first_vertex.h"

#include "nimbus/media/medium_field.h"

namespace nimbus {

void FirstVertexRecorder::record_medium(const Scene& scene, const Ray& ray, double t, int inside) {
  camera_ray_ends(t);
  Rgb mu_s(0.0), mu_t(0.0);
  for_each_medium_at(scene, ray.at(t), inside, [&](int m, double density) {
    const Medium& medium = scene.media[size_t(m)];
    mu_s += medium.sigma_s.rgb * density;
    mu_t += (medium.sigma_a.rgb + medium.sigma_s.rgb) * density;
  });
  Rgb albedo(0.0);
  for (int c = 0; c < 3; ++c)
    if (mu_t[c] > 0) albedo[c] = mu_s[c] / mu_t[c];
  set(albedo, -ray.d);
  pending_ = false;
}

}  // namespace nimbus
