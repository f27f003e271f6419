#include "nimbus/media/cloud_density.h"

#include <algorithm>
#include <atomic>

namespace nimbus {
namespace {

constexpr Vec3 kWarpOffset[3] = {{5.2, 1.3, 7.7}, {1.7, 9.2, 3.1}, {8.3, 2.8, 4.6}};

double profile(double F, double edge) {
  const double u = std::clamp(F / edge, 0.0, 1.0);
  return u * u * (3 - 2 * u);
}

// d = clamp((s − E)/(1 − E), 0, 1).
double eroded(double s, double E) {
  return std::clamp((s - E) / (1 - E), 0.0, 1.0);
}

double noise01(double n) {
  return std::clamp(0.5 + kCloudContrast * n, 0.0, 1.0);
}

}  // namespace

CloudNoise make_cloud_noise(const CloudParams& params) {
  static std::atomic<std::uint64_t> made{0};
  return {params, make_noise(params.seed), ++made};
}

DensityPtr make_cloud_density(const CloudParams& params) {
  return std::make_shared<CloudDensity>(params);
}

double cloud_density(const CloudNoise& cloud, const Vec3& x, double F) {
  const CloudParams& p = cloud.params;
  const double s = profile(F, p.edge);
  if (s <= 0) return 0;
  // In the core (F >= edge) d = (1 − E)/(1 − E) = 1 exactly, whatever the noise: skip it.
  if (s >= 1) return 1;
  // The noise does not depend on F: overlapping puffs of one cloud medium, looked up at one point
  // one after another (medium_field.h), share the last point's, per thread (issue 26). Plain
  // zero-initialised thread-locals: no initialisation guard on the hot path.
  thread_local std::uint64_t last_id = 0;
  thread_local double last_x = 0, last_y = 0, last_z = 0, last_nu = 0;
  if (last_id != cloud.id || !(last_x == x.x && last_y == x.y && last_z == x.z)) {
    const Vec3 q = p.frequency * x;
    const Vec3 warp{fbm(cloud.noise, q + kWarpOffset[0], kCloudWarpOctaves),
                    fbm(cloud.noise, q + kWarpOffset[1], kCloudWarpOctaves),
                    fbm(cloud.noise, q + kWarpOffset[2], kCloudWarpOctaves)};
    last_nu = noise01(fbm(cloud.noise, q + kCloudWarp * warp, p.octaves));
    last_id = cloud.id;
    last_x = x.x;
    last_y = x.y;
    last_z = x.z;
  }
  return eroded(s, p.amplitude * (1 - last_nu));
}

std::pair<double, double> cloud_density_range(double F_lo, double F_hi, const CloudParams& p) {
  const double b = fbm_bound(p.octaves);
  const double E_max = p.amplitude * (1 - noise01(-b));
  const double E_min = p.amplitude * (1 - noise01(b));
  return {eroded(profile(F_lo, p.edge), E_max), eroded(profile(F_hi, p.edge), E_min)};
}

}  // namespace nimbus
