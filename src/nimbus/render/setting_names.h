#pragma once
// The names a scene file gives the render settings' choices: one table per choice, read by the
// loader (an unknown name is an error that lists these) and written back by --stats and the
// tools. No other place spells them.

#include <array>
#include <string_view>
#include <utility>

#include "nimbus/render/scene.h"

namespace nimbus {

inline constexpr std::array<std::pair<std::string_view, TrackingSettings::Mode>, 4>
    kTrackingModeNames = {{{"delta", TrackingSettings::Mode::Delta},
                           {"spectral-max", TrackingSettings::Mode::SpectralMax},
                           {"spectral-history", TrackingSettings::Mode::SpectralHistory},
                           {"spectral-mis", TrackingSettings::Mode::SpectralMis}}};

inline constexpr std::array<std::pair<std::string_view, TrackingSettings::Absorption>, 2>
    kAbsorptionNames = {{{"weight", TrackingSettings::Absorption::Weight},
                         {"collide", TrackingSettings::Absorption::Collide}}};

inline constexpr std::array<std::pair<std::string_view, TrackingSettings::Transmittance>, 3>
    kTransmittanceNames = {{{"ratio", TrackingSettings::Transmittance::Ratio},
                            {"residual-ratio", TrackingSettings::Transmittance::ResidualRatio},
                            {"ray-marching", TrackingSettings::Transmittance::RayMarching}}};

inline constexpr std::array<std::pair<std::string_view, TrackingSettings::MajorantSource>, 2>
    kMajorantSourceNames = {{{"bound", TrackingSettings::MajorantSource::Bound},
                             {"sample", TrackingSettings::MajorantSource::Sample}}};

inline constexpr std::array<std::pair<std::string_view, SpectralSettings::Mode>, 2>
    kSpectrumModeNames = {
        {{"rgb", SpectralSettings::Mode::Rgb}, {"spectral", SpectralSettings::Mode::Spectral}}};

inline constexpr std::array<std::pair<std::string_view, RenderSettings::Sampler>, 2> kSamplerNames =
    {{{"zsobol", RenderSettings::Sampler::ZSobol},
      {"independent", RenderSettings::Sampler::Independent}}};

inline constexpr std::array<std::pair<std::string_view, RenderSettings::LightSampling>, 2>
    kLightSamplingNames = {
        {{"all", RenderSettings::LightSampling::All}, {"one", RenderSettings::LightSampling::One}}};

inline constexpr std::array<std::pair<std::string_view, Aov>, 5> kAovNames = {
    {{"albedo", Aov::Albedo},
     {"normal", Aov::Normal},
     {"depth", Aov::Depth},
     {"variance", Aov::Variance},
     {"samples", Aov::Samples}}};

// The name of a value in its table.
template <class E, size_t K>
constexpr std::string_view name_of(const std::array<std::pair<std::string_view, E>, K>& table,
                                   E value) {
  for (const auto& [name, v] : table)
    if (v == value) return name;
  return "?";
}

}  // namespace nimbus
