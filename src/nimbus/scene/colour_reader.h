#pragma once
// Reading a colour input of the scene format (docs/scene-format.md, "Colours and spectra"), for
// the readers of the loader's tables (lights, media).

#include "nimbus/scene/json_reader.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

// RGB (one number or [r, g, b]) in `range`, or an object holding a sampled spectrum
// {"spectrum": [[nm, value], ...]} (values in `range`, nm strictly increasing) or, for emitted
// light only (role Illuminant), a blackbody {"blackbody": kelvin, "scale": luminance}.
SpectralParam read_colour(const JsonValue& v, SpectralRole role, const Range& range);

}  // namespace nimbus
