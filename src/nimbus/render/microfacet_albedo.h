#pragma once
// Energy the single-scattering microfacet BSDFs (render/microfacet.h) lose, and the lobe that
// gives it back (Kulla & Conty 2017, "Revisiting physically based shading at Imageworks"): light
// that would scatter more than once between facets leaves as if from a diffuse-like lobe whose
// albedo is what single scattering misses, 1 − E(μ_o), so a white rough boundary conserves energy.
//
// E(μ) is tabulated per rough surface once, when the scene is compiled: the mean sampled weight
// G/G1 over visible normals (render/microfacet.h's samples), from a fixed stratified pattern, so
// the table is the same in every run.

#include <array>
#include <optional>
#include <vector>

namespace nimbus {

struct Surface;

// The directional albedo of one side of a rough boundary against μ = |cos θ_o|, a conductor's
// with F = 1 (its Fresnel factor is applied apart), a dielectric's reflection and refraction
// together.
struct AlbedoCurve {
  static constexpr int kNodes = 33;  // μ = i / 32
  std::array<double, kNodes> E{};
  double average = 0;    // E_avg = 2 ∫ E(μ) μ dμ
  double reflected = 0;  // the share of E_avg that reflects (1 for a conductor)
  // E at μ in [0, 1], linearly interpolated.
  double at(double mu) const;
};

struct MicrofacetAlbedo {
  AlbedoCurve outside;  // from the normal's side: the conductor's only one
  AlbedoCurve inside;   // a dielectric seen from inside its solid
};

// The tables of a rough conductor or dielectric (roughness > 0).
MicrofacetAlbedo microfacet_albedo(const Surface& s);

// A rough surface's tables over its roughnesses: one level for a fixed roughness; for a textured
// one (Surface::roughness_texture), kLevels levels at roughnesses spaced evenly from its "from"
// to its "to", blended linearly in α between them.
struct MicrofacetAlbedoLevels {
  static constexpr int kLevels = 9;
  double alpha0 = 0, alpha1 = 0;
  std::vector<MicrofacetAlbedo> levels;
  // The tables at α: a level itself, or `scratch` made the blend of the two around α (only a
  // textured roughness makes one: a table is 70 numbers).
  const MicrofacetAlbedo* at(double alpha, std::optional<MicrofacetAlbedo>& scratch) const;
};

MicrofacetAlbedoLevels microfacet_albedo_levels(const Surface& s);

}  // namespace nimbus
