#pragma once
// A path's spectra (docs/spectra.md): its N channels (spectral/channels.h) and, at them, the
// media's coefficients and the lights' emission, evaluated once per path, so the tracking
// estimators see plain Spectrum<N> values in either mode and run unchanged; the film turns a
// path's channels into linear sRGB.

#include <algorithm>
#include <array>
#include <vector>

#include "nimbus/media/medium.h"
#include "nimbus/render/scene.h"
#include "nimbus/spectral/channels.h"
#include "nimbus/spectral/cie.h"
#include "nimbus/spectral/color.h"
#include "nimbus/spectral/spectral_param.h"
#include "nimbus/spectral/spectrum.h"
#include "nimbus/spectral/wavelengths.h"

namespace nimbus {

template <int N>
struct PathSpectra {
  Channels<N> ch;
  std::vector<MediumCoefficients<N>> media;  // indexed as scene.media
  // Each light's emission, indexed as scene.lights, for a scene of few lights (no light tree);
  // with thousands, evaluating them all per path cost more than the path (issue 26), and
  // light_emission evaluates the one asked for.
  std::vector<Spectrum<N>> lights;
};

// Light l's emission at the path's channels.
template <int N>
Spectrum<N> light_emission(const PathSpectra<N>& ps, const Scene& scene, int l) {
  return size_t(l) < ps.lights.size() ? ps.lights[size_t(l)]
                                      : evaluate(scene.lights[size_t(l)].emission, ps.ch);
}

// The octree bounds mu_t = density · sigma_t per wavelength bin, with each medium's sigma_t at its
// upper bound over the bin (SpectralParam::bin_max); a channel's own mu_t is bounded by that
// majorant times max over media of sigma_t(λ) / (its bound over λ's bin), which is 1 at most.
// Free paths and shadow rays then take collisions at the rate of each channel's own wavelength,
// not at the highest over its bin, which for a chromatic medium is far above it where sigma_t
// changes fast with λ (scenes/bench/chromatic_cloud.json, 4 wavelengths: 24.2 density lookups
// per sample before, 19.4 after, rgb mode 20.5). Stays 1 where a bound is unknown.
template <int N>
void channel_majorant_factors(PathSpectra<N>& ps, const Scene& scene) {
  for (int i = 0; i < N; ++i) {
    double f = 0;
    for (size_t m = 0; m < scene.media.size() && f < 1; ++m) {
      const Medium& med = scene.media[m];
      if (med.sigma_a.bin_max.empty() || med.sigma_s.bin_max.empty() ||
          (med.sigma_a_texture && med.sigma_a_to.bin_max.empty()) ||
          (med.sigma_s_texture && med.sigma_s_to.bin_max.empty())) {
        f = 1;
        break;
      }
      // A textured coefficient at its larger end, over the larger of its ends' bounds.
      const int bin = ps.ch.bin[i];
      const MediumCoefficients<N>& c = ps.media[m];
      double bound = med.sigma_a.bin_max[bin] + med.sigma_s.bin_max[bin];
      double sigma_t = c.sigma_a[i] + c.sigma_s[i];
      if (med.sigma_a_texture || med.sigma_s_texture) {
        const bool a = bool(med.sigma_a_texture), s = bool(med.sigma_s_texture);
        bound = std::max(med.sigma_a.bin_max[bin], a ? med.sigma_a_to.bin_max[bin] : 0.0) +
                std::max(med.sigma_s.bin_max[bin], s ? med.sigma_s_to.bin_max[bin] : 0.0);
        sigma_t = std::max(c.sigma_a[i], a ? c.sigma_a_to[i] : 0.0) +
                  std::max(c.sigma_s[i], s ? c.sigma_s_to[i] : 0.0);
      }
      if (bound > 0) f = std::max(f, sigma_t / bound);
    }
    // A medium without extinction in the bin leaves its majorant 0 there anyway.
    ps.ch.majorant_factor[i] = f > 0 ? std::min(f, 1.0) : 1.0;
  }
}

// Sets up ps for a path of `scene`: in rgb mode the RGB channels (u unused); in spectral mode
// N wavelengths from the uniform number u. Reuses ps's storage.
template <int N>
void prepare_path_spectra(PathSpectra<N>& ps, const Scene& scene, double u) {
  ps.ch.spectral = scene.settings.spectral.mode == SpectralSettings::Mode::Spectral;
  if (ps.ch.spectral) {
    ps.ch.wl = sample_wavelengths<N>(u);
    for (int i = 0; i < N; ++i)
      ps.ch.bin[i] = std::min(kSpectralBins - 1, static_cast<int>(ps.ch.wl.u[i] * kSpectralBins));
  } else {
    for (int i = 0; i < N; ++i) ps.ch.bin[i] = i;
  }
  ps.media.resize(scene.media.size());
  for (size_t m = 0; m < scene.media.size(); ++m) {
    const Medium& med = scene.media[m];
    MediumCoefficients<N>& c = ps.media[m];
    c.sigma_a = evaluate(med.sigma_a, ps.ch);
    c.sigma_s = evaluate(med.sigma_s, ps.ch);
    c.sigma_a_texture = med.sigma_a_texture ? &med.sigma_a_texture : nullptr;
    c.sigma_s_texture = med.sigma_s_texture ? &med.sigma_s_texture : nullptr;
    if (c.sigma_a_texture) c.sigma_a_to = evaluate(med.sigma_a_to, ps.ch);
    if (c.sigma_s_texture) c.sigma_s_to = evaluate(med.sigma_s_to, ps.ch);
    c.emission = evaluate(med.emission, ps.ch);
    c.emission_grid = med.emission_grid.get();
    c.j = evaluate(med.j, ps.ch);
    c.j_grid = med.j_grid.get();
    if (c.emission_grid || c.j_grid) {
      c.spectral = ps.ch.spectral;
      c.lambda = ps.ch.wl.lambda;
    }
  }
  if (ps.ch.spectral) channel_majorant_factors(ps, scene);
  ps.lights.resize(scene.light_tree.nodes.empty() ? scene.lights.size() : 0);
  for (size_t l = 0; l < ps.lights.size(); ++l)
    ps.lights[l] = evaluate(scene.lights[l].emission, ps.ch);
}

// A path's radiance at its channels as linear sRGB: itself in rgb mode; in spectral mode the
// estimate XYZ = (1/N) Σ_i L_i (x̄, ȳ, z̄)(λ_i) / (p(λ_i) ∫ȳ), converted to linear sRGB.
template <int N>
Rgb to_film_rgb(const Spectrum<N>& L, const Channels<N>& ch) {
  if constexpr (N == 3) {
    if (!ch.spectral) return L;
  }
  Vec3 xyz;
  for (int i = 0; i < N; ++i)
    if (L[i] != 0) xyz += cie_xyz_bar(ch.wl.lambda[i]) * (L[i] / ch.wl.pdf[i]);
  return xyz_to_linear_srgb(xyz * (1.0 / (N * cie_y_integral())));
}

}  // namespace nimbus
