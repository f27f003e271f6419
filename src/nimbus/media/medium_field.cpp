#include "nimbus/media/medium_field.h"

#include <algorithm>

#include "nimbus/media/phase.h"
#include "nimbus/render/scene.h"

namespace nimbus {
namespace {

double density_at(const Medium& medium, const Vec3& x, double F) {
  switch (medium.density) {
    case Medium::Density::Constant:
      return medium.scale;
    case Medium::Density::Field:
      return medium.scale * std::max(F, 0.0);
    case Medium::Density::Cloud:
      return medium.scale * cloud_density(medium.cloud, x, F);
  }
  return 0.0;
}

void add_medium(MediumPoint& m, const Medium& medium, double density) {
  if (density <= 0 || m.media == MediumPoint::kMaxMedia) return;
  const Rgb mu_a = medium.sigma_a * density, mu_s = medium.sigma_s * density;
  m.mu_a += mu_a;
  m.mu_s += mu_s;
  m.mu_a_Le += mu_a * medium.emission;
  m.g[m.media] = medium.g;
  m.mu_s_i[m.media] = mu_s;
  ++m.media;
}

}  // namespace

MediumPoint medium_at(const Scene& scene, const Vec3& x, int inside) {
  MediumPoint m;
  if (inside >= 0) {
    const SceneObject& obj = scene.objects[inside];
    if (obj.medium >= 0) {
      const Medium& medium = scene.media[obj.medium];
      const double F = medium.density == Medium::Density::Constant ? 1.0 : evaluate(obj.tape, x);
      add_medium(m, medium, density_at(medium, x, F));
    }
    return m;
  }
  for (int i : scene.field_objects) {
    const SceneObject& obj = scene.objects[i];
    if (!obj.bounds.contains(x)) continue;
    const double F = evaluate(obj.tape, x);
    if (F <= 0) continue;
    const Medium& medium = scene.media[obj.medium];
    add_medium(m, medium, density_at(medium, x, F));
  }
  return m;
}

Rgb phase_value(const MediumPoint& m, double cos_theta) {
  Rgb p(0.0);
  for (int i = 0; i < m.media; ++i) p += m.mu_s_i[i] * hg_phase(cos_theta, m.g[i]);
  for (int c = 0; c < 3; ++c) p[c] = m.mu_s[c] > 0 ? p[c] / m.mu_s[c] : 0.0;
  return p;
}

double phase_pdf(const MediumPoint& m, double cos_theta) {
  const double total = m.mu_s.sum();
  if (m.media == 1 || total <= 0) return hg_phase(cos_theta, m.g[0]);
  double pdf = 0;
  for (int i = 0; i < m.media; ++i) pdf += m.mu_s_i[i].sum() / total * hg_phase(cos_theta, m.g[i]);
  return pdf;
}

Vec3 sample_phase(const MediumPoint& m, const Vec3& dir, double u0, double u1, double u2,
                  Rgb& weight, double& pdf) {
  if (m.media <= 1) {
    const Vec3 w = sample_hg(dir, m.g[0], u1, u2);
    weight = Rgb(1.0);
    pdf = hg_phase(dot(dir, w), m.g[0]);
    return w;
  }
  // One-sample mixture: pick a lobe ∝ its share of mu_s, weight by the exact mixture.
  const double total = m.mu_s.sum();
  int pick = m.media - 1;
  double acc = 0;
  for (int i = 0; i < m.media; ++i) {
    acc += m.mu_s_i[i].sum() / total;
    if (u0 < acc) {
      pick = i;
      break;
    }
  }
  const Vec3 w = sample_hg(dir, m.g[pick], u1, u2);
  const double cos_theta = dot(dir, w);
  pdf = phase_pdf(m, cos_theta);
  weight = pdf > 0 ? phase_value(m, cos_theta) / pdf : Rgb(0.0);
  return w;
}

}  // namespace nimbus
