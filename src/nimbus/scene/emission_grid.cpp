#include "nimbus/scene/emission_grid.h"

#include <fmt/format.h>

#include <algorithm>

#include "nimbus/scene/load.h"

namespace nimbus {
namespace {

// The grid's hottest voxel must not emit more than kMaxEmission, as any emitted light in a scene
// file (issue 29: a grid at 3e38 K made NaN samples; its radiance, about 1e40, is beyond an
// EXR's floats).
void check_brightness(const TemperatureEmission& e, const VdbParams& p) {
  const double kelvin =
      e.kelvin_scale * e.kelvin->range(Box::everything(), Interval::point(1.0)).hi;
  if (!(kelvin >= kMinEmittingKelvin)) return;
  const double brightest = brightest_temperature_emission(e, kelvin);
  if (!(brightest <= kMaxEmission))
    throw VdbError("grid", fmt::format("{}: grid \"{}\" reaches {:.3g} K, where the emitted "
                                       "radiance (times scale {:.3g}) is {:.3g}; emitted light "
                                       "may be at most {:.0e}",
                                       p.file, p.grid, kelvin, e.scale, brightest, kMaxEmission));
}

}  // namespace

bool is_emission_grid(const JsonValue& v) {
  return v.json().is_object() && (v.json().contains("file") || v.json().contains("grid"));
}

EmissionGridMaker read_emission_grid(const JsonValue& v) {
  JsonObject o(v);
  const JsonValue file = o.required("file");
  const auto grid = o.optional("grid");
  const auto scale = o.optional("scale");
  const auto transform = o.optional("transform");
  const auto law = o.optional("law");
  const auto kelvin_scale = o.optional("temperature_scale");
  GridInput in;
  in.params.grid = "temperature";
  in.params.file = file.file();  // relative to the scene file's folder, as the "vdb" density's
  if (grid) in.params.grid = grid->string();
  if (in.params.grid.empty()) grid->fail("must name a grid");
  const double s = scale ? scale->number(kEmission) : 1.0;
  if (transform) in.params.transform = read_transform(*transform);
  using Law = TemperatureEmission::Law;
  const Law l = law && law->choice("law", {"planck", "stefan-boltzmann"}) == 1
                    ? Law::StefanBoltzmann
                    : Law::Planck;
  const double k = kelvin_scale ? kelvin_scale->number(between(0, kMaxEmission)) : 1.0;
  o.finish("for a temperature grid's emission");
  in.file_pointer = file.pointer();
  in.file_blame = file.blame();
  if (grid) in.grid_blame = grid->blame();
  in.object_blame = v.blame();
  return [in, s, k, l](std::vector<InputFile>& inputs) {
    return in.read(inputs, [s, k, l](const VdbParams& p) {
      auto e = make_temperature_emission(p, s, k, l);
      check_brightness(*e, p);
      return e;
    });
  };
}

}  // namespace nimbus
