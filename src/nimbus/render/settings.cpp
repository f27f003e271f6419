#include "nimbus/render/settings.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "nimbus/media/octree.h"
#include "nimbus/render/setting_names.h"
#include "nimbus/render/wavelength_counts.h"

namespace nimbus {
namespace {

using Kind = SettingType::Kind;

// A setting held as a T and written in the file as a JSON number or boolean. `field` is a
// generic lambda returning a reference to the member, const or not.
template <class T, class Field>
Setting plain(std::string_view key, Kind kind, Range range, std::string_view doc, Field field) {
  return {key,
          {kind, range, {}, {}},
          doc,
          [field](const RenderSettings& s) { return nlohmann::json(field(s)); },
          [field](RenderSettings& s, const nlohmann::json& v) { field(s) = v.get<T>(); },
          {},
          {}};
}

template <class Field>
Setting integer(std::string_view key, Range range, std::string_view doc, Field field) {
  return plain<int>(key, Kind::Integer, range, doc, field);
}

template <class Field>
Setting number(std::string_view key, Range range, std::string_view doc, Field field) {
  return plain<double>(key, Kind::Number, range, doc, field);
}

template <class Field>
Setting boolean(std::string_view key, std::string_view doc, Field field) {
  return plain<bool>(key, Kind::Boolean, {}, doc, field);
}

// A named choice, its names from setting_names.h.
template <class E, size_t K, class Field>
Setting choice(std::string_view key, std::string_view noun,
               const std::array<std::pair<std::string_view, E>, K>& table, std::string_view doc,
               Field field) {
  std::vector<std::string_view> names;
  for (const auto& entry : table) names.push_back(entry.first);
  return {key,
          {Kind::Choice, {}, names, noun},
          doc,
          [field, &table](const RenderSettings& s) {
            return nlohmann::json(std::string(name_of(table, field(s))));
          },
          [field, &table](RenderSettings& s, const nlohmann::json& v) {
            for (const auto& [name, value] : table)
              if (name == v.get<std::string>()) field(s) = value;
          },
          {},
          {}};
}

// The set of AOVs, written as an array of their names in the order of kAovNames.
Setting aov_list(std::string_view key, std::string_view doc) {
  std::vector<std::string_view> names;
  for (const auto& entry : kAovNames) names.push_back(entry.first);
  return {key,
          {Kind::ChoiceList, {}, names, "AOV"},
          doc,
          [](const RenderSettings& s) {
            nlohmann::json list = nlohmann::json::array();
            for (const auto& [name, aov] : kAovNames)
              if (s.aovs.has(aov)) list.push_back(std::string(name));
            return list;
          },
          [](RenderSettings& s, const nlohmann::json& v) {
            s.aovs = {};
            for (const auto& [name, aov] : kAovNames)
              for (const nlohmann::json& given : v)
                if (given.get<std::string>() == name) s.aovs.add(aov);
          },
          {},
          {}};
}

std::vector<Setting> make_settings() {
  Setting seed = plain<uint64_t>(
      "integrator.seed", Kind::Unsigned, {},
      "seed of every random stream: one stream per seed, pixel and sample index",
      [](auto& s) -> auto& { return s.seed; });
  seed.type_text = "integer in [0, 2⁶⁴ − 1]";
  std::vector<Setting> all = {
      integer(
          "film.width", between(1, 16384), "image width in pixels",
          [](auto& s) -> auto& { return s.width; }),
      integer(
          "film.height", between(1, 16384), "image height in pixels",
          [](auto& s) -> auto& { return s.height; }),
      aov_list("film.aov",
               "AOV layers written into the EXR beside the colour, for denoisers (as `--aov`)"),
      integer(
          "integrator.spp", at_least(1),
          "samples per pixel; with a noise target, the most a pixel takes",
          [](auto& s) -> auto& { return s.spp; }),
      number(
          "integrator.noise_target", between(0, 1),
          "> 0: each 8 × 8 block of pixels takes samples until its estimated relative error is at "
          "most this, or spp (as `--noise-target`; docs/noise-target.md); 0: every pixel takes spp",
          [](auto& s) -> auto& { return s.noise_target; }),
      integer(
          "integrator.noise_min_spp", at_least(2),
          "with a noise target, the samples every block takes before its error is first estimated",
          [](auto& s) -> auto& { return s.noise_min_spp; }),
      seed,
      integer(
          "integrator.max_depth", at_least(1),
          "most scattering or reflection events along one path",
          [](auto& s) -> auto& { return s.max_depth; }),
      choice(
          "integrator.sampler", "sampler", kSamplerNames,
          "where a pixel sample's numbers come from", [](auto& s) -> auto& { return s.sampler; }),
      choice(
          "integrator.light_sampling", "light_sampling", kLightSamplingNames,
          "next-event estimation: one light picked by its fluence, or every light",
          [](auto& s) -> auto& { return s.light_sampling; }),
      boolean(
          "integrator.manifold",
          "manifold next-event estimation: lights reach media and diffuse surfaces through smooth "
          "dielectric boundaries",
          [](auto& s) -> auto& { return s.manifold; }),
      boolean(
          "integrator.manifold_area_caustics",
          "manifold next-event estimation also through a solid from outside (caustics) to sphere "
          "lights and emissive surfaces, which BSDF sampling finds as well; point and directional "
          "lights always",
          [](auto& s) -> auto& { return s.manifold_area_caustics; }),
      choice(
          "integrator.tracking", "tracking", kTrackingModeNames, "free-path sampling in media",
          [](auto& s) -> auto& { return s.tracking.mode; }),
      choice(
          "integrator.absorption", "absorption", kAbsorptionNames,
          "absorption carried by the weights, or an event that ends the path (spectral-mis: "
          "always)",
          [](auto& s) -> auto& { return s.tracking.absorption; }),
      boolean(
          "integrator.decomposition",
          "decomposition tracking: the minorant's part of μ_t sampled in closed form",
          [](auto& s) -> auto& { return s.tracking.decomposition; }),
      choice(
          "integrator.transmittance", "transmittance", kTransmittanceNames,
          "the shadow rays' transmittance estimator (spectral-mis has its own)",
          [](auto& s) -> auto& { return s.tracking.transmittance; }),
      choice(
          "integrator.majorant.source", "majorant source", kMajorantSourceNames,
          "the octree's bounds of μ_t: interval bounds, or a preliminary sampling pass",
          [](auto& s) -> auto& { return s.tracking.majorant_source; }),
      integer(
          "integrator.majorant.samples", at_least(1),
          "points per non-empty octree leaf of the sampling pass (source \"sample\")",
          [](auto& s) -> auto& { return s.tracking.majorant_samples; }),
      number(
          "integrator.majorant.scale", above(0), "factor applied to every majorant",
          [](auto& s) -> auto& { return s.tracking.majorant_scale; }),
      integer(
          "integrator.octree.depth", between(0, kOctreeMaxDepth),
          "deepest level of the majorant octree; 0: one node over all media (a node over more than "
          "eight index-matched media objects splits further whatever the depth)",
          [](auto& s) -> auto& { return s.tracking.octree_depth; }),
      choice(
          "spectrum.mode", "spectrum mode", kSpectrumModeNames,
          "three fixed channels (linear sRGB), or wavelengths sampled per path",
          [](auto& s) -> auto& { return s.spectral.mode; }),
      integer(
          "spectrum.wavelengths", {}, "wavelengths per path in spectral mode",
          [](auto& s) -> auto& { return s.spectral.wavelengths; }),
  };
  Setting& wavelengths = all.back();
  wavelengths.check = [](const nlohmann::json& v) -> std::string {
    if (is_built_wavelength_count(v.get<int>())) return {};
    return fmt::format(
        "must be one of {} (the counts this build renders: CMake option "
        "NIMBUS_WAVELENGTH_COUNTS)",
        fmt::join(built_wavelength_counts(), ", "));
  };
  // The counts are a build option (NIMBUS_WAVELENGTH_COUNTS); the docs name the default build's.
  wavelengths.type_text = "one of the build's counts (by default 4, 8, 12, 16)";
  return all;
}

std::string type_text(const Setting& s) {
  if (!s.type_text.empty()) return std::string(s.type_text);
  switch (s.type.kind) {
    case Kind::Integer:
      return "integer " + range_text(s.type.range);
    case Kind::Number:
      return "number " + range_text(s.type.range);
    case Kind::Unsigned:
      return "integer >= 0";
    case Kind::Boolean:
      return "boolean";
    case Kind::Choice:
    case Kind::ChoiceList: {
      std::vector<std::string> quoted;
      for (std::string_view n : s.type.names) quoted.push_back(fmt::format("`\"{}\"`", n));
      const std::string names = fmt::format("{}", fmt::join(quoted, ", "));
      return s.type.kind == Kind::Choice ? names : "array of distinct " + names;
    }
  }
  return "";
}

}  // namespace

std::span<const Setting> render_settings() {
  static const std::vector<Setting> all = make_settings();
  return all;
}

nlohmann::json settings_json(const RenderSettings& settings) {
  nlohmann::json j = nlohmann::json::object();
  for (const Setting& s : render_settings()) {
    // Down the key's dotted parts.
    nlohmann::json* at = &j;
    std::string_view rest = s.key;
    for (size_t dot; (dot = rest.find('.')) != std::string_view::npos; rest.remove_prefix(dot + 1))
      at = &(*at)[std::string(rest.substr(0, dot))];
    (*at)[std::string(rest)] = s.get(settings);
  }
  return j;
}

std::string settings_markdown(std::string_view section) {
  const std::string prefix = std::string(section) + ".";
  std::string out = "| Key | Type | Default | Meaning |\n|---|---|---|---|\n";
  const RenderSettings defaults;
  for (const Setting& s : render_settings()) {
    if (!s.key.starts_with(prefix)) continue;
    out += fmt::format("| `{}` | {} | `{}` | {} |\n", s.key.substr(prefix.size()), type_text(s),
                       s.get(defaults).dump(), s.doc);
  }
  return out;
}

}  // namespace nimbus
