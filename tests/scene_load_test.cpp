#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "nimbus/frep/primitives.h"
#include "nimbus/media/cloud_density.h"
#include "nimbus/media/field_density.h"
#include "nimbus/render/wavelength_counts.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "nimbus/spectral/color.h"

namespace nimbus {
namespace scene_load_test {

// The density a medium of a description makes when the scene is compiled.
DensityPtr made_density(const MediumDesc& m) {
  std::vector<InputFile> read;
  return m.density(read);
}

// The example of docs/scene-format.md (its first json block), so that the documentation's
// example is known to load.
std::string documented_example() {
  std::ifstream in(NIMBUS_SOURCE_DIR "/docs/scene-format.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const size_t begin = doc.find("```json\n");
  const size_t end = doc.find("\n```", begin);
  if (begin == std::string::npos || end == std::string::npos) return "(no example found)";
  return doc.substr(begin + 8, end - begin - 8);
}

SceneDesc load(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return load_scene_json(nlohmann::json::parse(text), "scene.json", overrides);
}

std::string load_error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    load(text, overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

// A document with a valid camera and the given further top-level members.
std::string with_camera(const std::string& members) {
  return R"({"camera": {"from": [0, 0, 5], "to": [0, 0, 0]})" +
         (members.empty() ? "" : ", " + members) + "}";
}

std::string with_shape(const std::string& shape) {
  return with_camera(R"("shapes": {"ball": )" + shape + "}");
}

std::string with_medium(const std::string& medium) {
  return with_camera(R"("media": {"cloud": )" + medium + "}");
}

std::string with_object(const std::string& object) {
  return with_camera(R"("media": {"smoke": {"sigma_s": 1}}, "objects": [)" + object + "]");
}

struct BadScene {
  const char* what;
  std::string text;
  std::vector<std::string> overrides;
  std::string message;
};

// Named shapes that each use the previous one twice: 2^levels spheres once compiled.
std::string doubling_shapes(int levels) {
  std::string shapes = R"("s0": {"type": "sphere", "radius": 1})";
  for (int i = 1; i <= levels; ++i)
    shapes +=
        fmt::format(R"(, "s{}": {{"type": "union", "shapes": ["s{}", "s{}"]}})", i, i - 1, i - 1);
  return with_camera(R"("media": {"m": {"sigma_s": 1}}, "shapes": {)" + shapes +
                     fmt::format(R"(}}, "objects": [{{"shape": "s{}", "medium": "m"}}])", levels));
}

std::vector<BadScene> bad_scenes() {
  const std::string ball = R"({"type": "sphere", "radius": 1})";
  return {
      // Issue 16: 2^26 spheres from 27 short definitions did not finish compiling in 20 s.
      {"exponentially many quadrics",
       doubling_shapes(15),
       {},
       "scene.json: /objects/0/shape: the shape holds more than 20000 quadrics (each use of a "
       "named shape counts)"},
      {"root is not an object", "[1, 2]", {}, "scene.json: /: expected an object, not an array"},
      {"missing camera", "{}", {}, "scene.json: /camera: required key is missing"},
      {"misspelt section",
       with_camera(R"("objcts": [])"),
       {},
       R"(scene.json: /objcts: unknown key (did you mean "objects"?))"},
      {"unknown camera key",
       R"({"camera": {"from": [0, 0, 5], "to": [0, 0, 0], "fvo": 30}})",
       {},
       R"(scene.json: /camera/fvo: unknown key (did you mean "fov"?))"},
      {"misspelt required key",
       R"({"camera": {"form": [0, 0, 5], "to": [0, 0, 0]}})",
       {},
       R"(scene.json: /camera/form: unknown key (did you mean "from"?))"},
      {"wrong type",
       with_camera(R"("film": {"width": "640"})"),
       {},
       "scene.json: /film/width: expected an integer, not a string"},
      {"fraction for integer",
       with_camera(R"("film": {"height": 480.5})"),
       {},
       "scene.json: /film/height: expected an integer, not a fraction"},
      {"film width 0",
       with_camera(R"("film": {"width": 0})"),
       {},
       "scene.json: /film/width: must be in [1, 16384]"},
      {"vector too short",
       R"({"camera": {"from": [0, 5], "to": [0, 0, 0]}})",
       {},
       "scene.json: /camera/from: expected an array of 3 numbers"},
      {"camera from == to",
       R"({"camera": {"from": [1, 2, 3], "to": [1, 2, 3]}})",
       {},
       R"(scene.json: /camera/to: must differ from "from")"},
      {"up parallel to view",
       R"({"camera": {"from": [0, 5, 0], "to": [0, 0, 0], "up": [0, 2, 0]}})",
       {},
       "scene.json: /camera/up: must not be parallel to the view direction"},
      {"view along the default up",
       R"({"camera": {"from": [0, 5, 0], "to": [0, 0, 0]}})",
       {},
       R"(scene.json: /camera: the view direction is parallel to the default up [0, 1, 0]; give "up")"},
      {"fov out of range",
       R"({"camera": {"from": [0, 0, 5], "to": [0, 0, 0], "fov": 180}})",
       {},
       "scene.json: /camera/fov: must be in (0, 180)"},
      {"unknown camera type",
       R"({"camera": {"type": "fisheye", "from": [0, 0, 5], "to": [0, 0, 0]}})",
       {},
       R"(scene.json: /camera/type: unknown camera type "fisheye" (expected one of: perspective, orthographic))"},
      {"spp 0",
       with_camera(R"("integrator": {"spp": 0})"),
       {},
       "scene.json: /integrator/spp: must be >= 1"},
      {"negative seed",
       with_camera(R"("integrator": {"seed": -1})"),
       {},
       "scene.json: /integrator/seed: must be >= 0"},
      {"unknown sampler",
       with_camera(R"("integrator": {"sampler": "sobol"})"),
       {},
       R"(scene.json: /integrator/sampler: unknown sampler "sobol" (expected one of: zsobol, independent))"},
      {"unknown light sampling",
       with_camera(R"("integrator": {"light_sampling": "two"})"),
       {},
       R"(scene.json: /integrator/light_sampling: unknown light_sampling "two" (expected one of: all, one))"},
      {"unknown tracking",
       with_camera(R"("integrator": {"tracking": "ratio"})"),
       {},
       R"(scene.json: /integrator/tracking: unknown tracking "ratio" (expected one of: delta, spectral-max, spectral-history, spectral-mis))"},
      {"decomposition not boolean",
       with_camera(R"("integrator": {"decomposition": "yes"})"),
       {},
       "scene.json: /integrator/decomposition: expected true or false, not a string"},
      {"octree too deep",
       with_camera(R"("integrator": {"octree": {"depth": 17}})"),
       {},
       "scene.json: /integrator/octree/depth: must be in [0, 16]"},
      {"zero light direction",
       with_camera(
           R"("lights": [{"type": "directional", "direction": [0, 0, 0], "irradiance": 1}])"),
       {},
       "scene.json: /lights/0/direction: must be a nonzero vector"},
      {"key of another light type",
       with_camera(
           R"("lights": [{"type": "point", "position": [0, 0, 0], "intensity": 1, "radius": 1}])"),
       {},
       R"(scene.json: /lights/0/radius: unknown key for light type "point")"},
      {"negative radiance",
       with_camera(R"("lights": [{"type": "environment", "radiance": [1, 1, -0.5]}])"),
       {},
       "scene.json: /lights/0/radiance/2: must be in [0, 1e+30]"},
      {"negative radius",
       with_shape(R"({"type": "sphere", "radius": -1})"),
       {},
       "scene.json: /shapes/ball/radius: must be in [1e-100, 1e+100]"},
      {"radius whose square is 0",
       with_shape(R"({"type": "sphere", "radius": 1e-320})"),
       {},
       "scene.json: /shapes/ball/radius: must be in [1e-100, 1e+100]"},
      {"zero ellipsoid radius",
       with_shape(R"({"type": "ellipsoid", "radii": [1, 2, 0]})"),
       {},
       "scene.json: /shapes/ball/radii/2: must be in [1e-100, 1e+100]"},
      {"unknown primitive type",
       with_shape(R"({"type": "sphre", "radius": 1})"),
       {},
       R"(scene.json: /shapes/ball/type: unknown shape type "sphre" (expected one of: quadric, sphere, ellipsoid, cylinder, cone, paraboloid, halfspace, slab, box, freeform, union, intersection, difference))"},
      {"cone angle",
       with_shape(R"({"type": "cone", "axis": [0, 1, 0], "half_angle": 90})"),
       {},
       "scene.json: /shapes/ball/half_angle: must be in (0, 90)"},
      {"quadric coefficient count",
       with_shape(R"({"type": "quadric", "coefficients": [1, 2, 3]})"),
       {},
       "scene.json: /shapes/ball/coefficients: expected an array of 10 numbers"},
      {"empty box",
       with_shape(R"({"type": "box", "min": [0, 0, 0], "max": [1, 0, 1]})"),
       {},
       "scene.json: /shapes/ball/max/1: must be greater than min (0)"},
      {"difference of one",
       with_shape(R"({"type": "difference", "shapes": [)" + ball + "]}"),
       {},
       "scene.json: /shapes/ball/shapes: expected at least 2 shapes"},
      {"perturbation without weight",
       with_shape(R"({"type": "freeform", "base": )" + ball + R"(, "perturbations": [{"shape": )" +
                  ball + "}]}"),
       {},
       "scene.json: /shapes/ball/perturbations/0/weight: required key is missing"},
      {"key of another shape type",
       with_shape(R"({"type": "sphere", "radius": 1, "axis": [0, 1, 0]})"),
       {},
       R"(scene.json: /shapes/ball/axis: unknown key for shape type "sphere")"},
      {"unknown shape name",
       with_camera(R"("shapes": {"blob": )" + ball +
                   R"(}, "objects": [{"shape": "blob"}, {"shape": "blobb"}])"),
       {},
       R"(scene.json: /objects/1/shape: unknown shape "blobb")"},
      {"shape of wrong type",
       with_camera(R"("objects": [{"shape": 3}])"),
       {},
       "scene.json: /objects/0/shape: expected a shape name or an inline shape object"},
      {"reference cycle",
       with_camera(R"("shapes": {"a": {"type": "freeform", "base": "b"},
                                 "b": {"type": "union", "shapes": ["a"]}})"),
       {},
       "scene.json: /shapes/a/base: cycle in shape references: a -> b -> a"},
      {"cycle behind a reference",
       with_camera(R"("shapes": {"a": {"type": "union", "shapes": ["b"]},
                                 "b": {"type": "union", "shapes": ["c"]},
                                 "c": {"type": "intersection", "shapes": [)" +
                   ball + R"(, "b"]}})"),
       {},
       "scene.json: /shapes/b/shapes/0: cycle in shape references: b -> c -> b"},
      {"self reference",
       with_camera(R"("shapes": {"u": {"type": "union", "shapes": ["u"]}})"),
       {},
       "scene.json: /shapes/u/shapes/0: cycle in shape references: u -> u"},
      {"zero scale",
       with_shape(R"({"type": "sphere", "radius": 1, "transform": [{"scale": 0}]})"),
       {},
       "scene.json: /shapes/ball/transform/0/scale: must be nonzero"},
      {"zero scale component",
       with_shape(R"({"type": "sphere", "radius": 1, "transform": [{"scale": [1, 0, 1]}]})"),
       {},
       "scene.json: /shapes/ball/transform/0/scale/1: must be nonzero"},
      {"degenerate transform",
       with_shape(R"({"type": "sphere", "radius": 1, "transform": [{"scale": [0.5, 1e-12, 1]}]})"),
       {},
       "scene.json: /shapes/ball/transform: degenerate transform (determinant 5e-13)"},
      {"zero rotation axis",
       with_shape(
           R"({"type": "sphere", "radius": 1, "transform": [{"rotate": {"axis": [0, 0, 0], "degrees": 5}}]})"),
       {},
       "scene.json: /shapes/ball/transform/0/rotate/axis: must be a nonzero vector"},
      {"two steps in one",
       with_shape(
           R"({"type": "sphere", "radius": 1, "transform": [{"scale": 2, "translate": [1, 0, 0]}]})"),
       {},
       R"(scene.json: /shapes/ball/transform/0: expected exactly one of "translate", "rotate", "scale")"},
      {"negative sigma",
       with_medium(R"({"sigma_s": [1, -2, 3]})"),
       {},
       "scene.json: /media/cloud/sigma_s/1: must be >= 0"},
      {"g out of range",
       with_medium(R"({"phase": {"type": "hg", "g": 1}})"),
       {},
       "scene.json: /media/cloud/phase/g: must be in (-1, 1)"},
      {"g of isotropic phase",
       with_medium(R"({"phase": {"g": 0.5}})"),
       {},
       R"(scene.json: /media/cloud/phase/g: unknown key for phase type "isotropic")"},
      {"vdb density without its file",
       with_medium(R"({"density": {"type": "vdb"}})"),
       {},
       R"(scene.json: /media/cloud/density/file: required key is missing)"},
      {"cloud key on constant density",
       with_medium(R"({"density": {"octaves": 3}})"),
       {},
       R"(scene.json: /media/cloud/density/octaves: unknown key for density type "constant")"},
      {"ior below 1",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"type": "dielectric", "ior": 0.9}})"),
       {},
       "scene.json: /objects/0/surface/ior: must be >= 1"},
      {"roughness above 1",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"type": "dielectric", "roughness": 1.5}})"),
       {},
       "scene.json: /objects/0/surface/roughness: must be in [0, 1]"},
      {"conductor with a negative roughness",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"type": "conductor", "eta": 0.2, "k": 3, "roughness": -0.1}})"),
       {},
       "scene.json: /objects/0/surface/roughness: must be in [0, 1]"},
      {"conductor eta of 0",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"type": "conductor", "eta": [0.2, 0, 1], "k": 3}})"),
       {},
       "scene.json: /objects/0/surface/eta/1: must be > 0"},
      {"conductor without k",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"type": "conductor", "eta": 0.2}})"),
       {},
       "scene.json: /objects/0/surface/k: required key is missing"},
      {"unknown metal",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"type": "conductor", "metal": "brass"}})"),
       {},
       R"(scene.json: /objects/0/surface/metal: unknown metal "brass" (expected one of: aluminium, copper, gold, silver))"},
      {"metal and eta both",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"type": "conductor", "metal": "gold", "eta": 0.2}})"),
       {},
       R"(scene.json: /objects/0/surface/eta: give either "metal" or "eta" and "k", not both)"},
      {"textured roughness of 0",
       with_object(
           R"({"shape": )" + ball +
           R"(, "surface": {"type": "dielectric", "roughness": {"texture": {"type": "noise"}, "from": 0, "to": 0.5}}})"),
       {},
       "scene.json: /objects/0/surface/roughness/from: a textured roughness must be > 0 (0 is the "
       "smooth boundary, which a texture cannot blend into)"},
      {"textured roughness above 1",
       with_object(
           R"({"shape": )" + ball +
           R"(, "surface": {"type": "conductor", "metal": "gold", "roughness": {"texture": {"type": "veins"}, "from": 0.1, "to": 2}}})"),
       {},
       "scene.json: /objects/0/surface/roughness/to: must be in [0, 1]"},
      {"texture on the ior",
       with_object(
           R"({"shape": )" + ball +
           R"(, "surface": {"type": "dielectric", "ior": {"texture": {"type": "noise"}, "from": 1.3, "to": 1.6}}})"),
       {},
       "scene.json: /objects/0/surface/ior: takes no texture (textures drive a diffuse albedo, a "
       "roughness, and a medium's sigma_a and sigma_s)"},
      {"texture on an emissive radiance",
       with_object(
           R"({"shape": )" + ball +
           R"(, "surface": {"type": "emissive", "radiance": {"texture": {"type": "noise"}, "from": 0, "to": 1}}})"),
       {},
       "scene.json: /objects/0/surface/radiance: takes no texture (textures drive a diffuse "
       "albedo, "
       "a roughness, and a medium's sigma_a and sigma_s)"},
      {"textured albedo without its to",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"albedo": {"texture": {"type": "turbulence"}, "from": 0.2}}})"),
       {},
       "scene.json: /objects/0/surface/albedo/to: required key is missing"},
      {"textured albedo above 1",
       with_object(
           R"({"shape": )" + ball +
           R"(, "surface": {"albedo": {"texture": {"type": "noise"}, "from": 0.2, "to": [1, 1.5, 1]}}})"),
       {},
       "scene.json: /objects/0/surface/albedo/to/1: must be in [0, 1]"},
      {"textured sigma with an unknown texture type",
       with_medium(R"({"sigma_a": {"texture": {"type": "marble"}, "from": 0, "to": 1}})"),
       {},
       R"(scene.json: /media/cloud/sigma_a/texture/type: unknown density type "marble" (expected one of: constant, field, cloud, vdb, noise, turbulence, veins))"},
      {"textured sigma with a negative end",
       with_medium(R"({"sigma_s": {"texture": {"type": "noise"}, "from": 1, "to": [1, -2, 3]}})"),
       {},
       "scene.json: /media/cloud/sigma_s/to/1: must be >= 0"},
      {"texture key of another pattern",
       with_medium(
           R"({"sigma_s": {"texture": {"type": "noise", "sharpness": 3}, "from": 1, "to": 2}})"),
       {},
       R"(scene.json: /media/cloud/sigma_s/texture/sharpness: unknown key for density type "noise")"},
      {"veins of sharpness below 1",
       with_medium(R"({"density": {"type": "veins", "sharpness": 0.5}})"),
       {},
       "scene.json: /media/cloud/density/sharpness: must be in [1, 1000]"},
      {"textured value with a stray key",
       with_medium(R"({"sigma_s": {"texture": {"type": "noise"}, "from": 1, "to": 2, "by": 3}})"),
       {},
       R"(scene.json: /media/cloud/sigma_s/by: unknown key for a textured value (expected "texture", "from" and "to"))"},
      {"roughness on a diffuse surface",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"roughness": 0.2}})"),
       {},
       R"(scene.json: /objects/0/surface/roughness: unknown key for surface type "diffuse")"},
      {"spectrum mode unknown",
       with_camera(R"("spectrum": {"mode": "hyper"})"),
       {},
       R"(scene.json: /spectrum/mode: unknown spectrum mode "hyper" (expected one of: rgb, spectral))"},
      {"too few wavelengths",
       with_camera(R"("spectrum": {"mode": "spectral", "wavelengths": 3})"),
       {},
       fmt::format("scene.json: /spectrum/wavelengths: must be one of {} (the counts this build "
                   "renders: CMake option NIMBUS_WAVELENGTH_COUNTS)",
                   fmt::join(built_wavelength_counts(), ", "))},
      {"sampled spectrum not increasing",
       with_medium(R"({"sigma_s": {"spectrum": [[400, 1], [700, 2], [650, 3]]}})"),
       {},
       "scene.json: /media/cloud/sigma_s/spectrum/2/0: wavelengths must increase (after 700 nm)"},
      {"sampled spectrum empty",
       with_medium(R"({"sigma_s": {"spectrum": []}})"),
       {},
       "scene.json: /media/cloud/sigma_s/spectrum: expected at least one [nm, value] pair"},
      {"sampled spectrum entry not a pair",
       with_medium(R"({"sigma_a": {"spectrum": [[400, 1, 2]]}})"),
       {},
       "scene.json: /media/cloud/sigma_a/spectrum/0: expected a pair [nm, value]"},
      {"sampled coefficient negative",
       with_medium(R"({"sigma_a": {"spectrum": [[400, 1], [500, -2]]}})"),
       {},
       "scene.json: /media/cloud/sigma_a/spectrum/1/1: must be >= 0"},
      {"sampled albedo above 1",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"albedo": {"spectrum": [[400, 0.5], [600, 1.2]]}}})"),
       {},
       "scene.json: /objects/0/surface/albedo/spectrum/1/1: must be in [0, 1]"},
      {"blackbody albedo",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"albedo": {"blackbody": 3000}}})"),
       {},
       R"(scene.json: /objects/0/surface/albedo/blackbody: unknown key (expected "spectrum"))"},
      {"blackbody too cold",
       with_camera(R"("lights": [{"type": "environment", "radiance": {"blackbody": 5}}])"),
       {},
       "scene.json: /lights/0/radiance/blackbody: must be in [100, 1000000]"},
      // Issue 29: emitted light past 1e30, a free form's weight past 1e15 and a cloud's
      // frequency past 1e100 made NaN samples or a speckled surface; they are refused.
      {"point light of 1e308",
       with_camera(R"("lights": [{"type": "point", "position": [0, 1, 0], "intensity": 1e308}])"),
       {},
       "scene.json: /lights/0/intensity: must be in [0, 1e+30]"},
      {"blackbody scaled by 1e300",
       with_camera(
           R"("lights": [{"type": "environment", "radiance": {"blackbody": 5000, "scale": 1e300}}])"),
       {},
       "scene.json: /lights/0/radiance/scale: must be in [0, 1e+30]"},
      {"emissive surface of 1e308",
       with_object(R"({"shape": )" + ball +
                   R"(, "surface": {"type": "emissive", "radiance": [1, 1e308, 1]}})"),
       {},
       "scene.json: /objects/0/surface/radiance/1: must be in [0, 1e+30]"},
      {"medium emission of 1e300",
       with_medium(R"({"sigma_a": 1, "emission": {"spectrum": [[400, 1e300]]}})"),
       {},
       "scene.json: /media/cloud/emission/spectrum/0/1: must be in [0, 1e+30]"},
      {"cloud frequency of 1e308",
       with_medium(R"({"sigma_s": 1, "density": {"type": "cloud", "frequency": 1e308}})"),
       {},
       "scene.json: /media/cloud/density/frequency: must be in [1e-100, 1e+100]"},
      {"free-form weight of 1e50",
       with_shape(R"({"type": "freeform", "base": )" + ball + R"(, "perturbations": [{"shape": )" +
                  ball + R"(, "weight": -1e50}]})"),
       {},
       "scene.json: /shapes/ball/perturbations/0/weight: must be in [-1e+15, 1e+15]"},
      {"spectrum and blackbody",
       with_camera(
           R"("lights": [{"type": "environment", "radiance": {"blackbody": 5000, "spectrum": [[500, 1]]}}])"),
       {},
       R"(scene.json: /lights/0/radiance/blackbody: give either "spectrum" or "blackbody", not both)"},
      {"colour object without a spectrum",
       with_medium(R"({"sigma_s": {}})"),
       {},
       R"(scene.json: /media/cloud/sigma_s: expected a number, [r, g, b] or {"spectrum": [[nm, value], ...]})"},
      {"albedo above 1",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"albedo": [0.5, 1.5, 0.5]}})"),
       {},
       "scene.json: /objects/0/surface/albedo/1: must be in [0, 1]"},
      {"unknown medium",
       with_object(R"({"shape": )" + ball + R"(, "medium": "smok"})"),
       {},
       R"(scene.json: /objects/0/medium: unknown medium "smok")"},
      {"invisible object",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"type": "none"}})"),
       {},
       R"(scene.json: /objects/0/surface/type: surface "none" needs a medium: the object would be invisible)"},
      {"medium behind opaque surface",
       with_object(R"({"shape": )" + ball +
                   R"(, "medium": "smoke", "surface": {"type": "diffuse"}})"),
       {},
       R"(scene.json: /objects/0/medium: only objects with surface "none" or "dielectric" can hold a medium)"},
      {"emissive without radiance",
       with_object(R"({"shape": )" + ball + R"(, "surface": {"type": "emissive"}})"),
       {},
       "scene.json: /objects/0/surface/radiance: required key is missing"},
      {"objects not an array",
       with_camera(R"("objects": {})"),
       {},
       "scene.json: /objects: expected an array, not an object"},
      {"--set value of wrong type",
       with_camera(""),
       {"integrator.spp=abc"},
       "--set integrator.spp=abc: /integrator/spp: expected an integer, not a string"},
      {"--set misspelt key",
       with_camera(""),
       {"camera.fvo=20"},
       R"(--set camera.fvo=20: /camera/fvo: unknown key (did you mean "fov"?))"},
      {"--set through a number",
       with_camera(R"("film": {"width": 10})"),
       {"film.width.x=3"},
       "--set film.width.x=3: film.width is not an object"},
      {"--set without =",
       with_camera(""),
       {"integrator.spp"},
       "--set integrator.spp: expected KEY=VALUE"},
      // Issue 16: a key that --set created is blamed on --set, not on the file.
      {"--set creates an unknown object",
       with_camera(""),
       {"newthing.x=1"},
       "--set newthing.x=1: /newthing: unknown key"},
      // Issue 16: a long value is not echoed whole.
      {"--set with a long value",
       with_camera(""),
       {"film.width=\"" + std::string(300, 'a') + "\""},
       "--set film.width=\"" + std::string(48, 'a') +
           "... (313 characters): /film/width: expected an integer, not a string"},
      {"--set past an array's end",
       with_camera(R"("lights": [])"),
       {"lights.0.radiance=1"},
       "--set lights.0.radiance=1: index 0 is out of range for lights (size 0)"},
      {"--set non-index into array",
       with_camera(R"("lights": [])"),
       {"lights.x=1"},
       R"(--set lights.x=1: lights is an array; "x" is not an index)"},
      {"--set empty name",
       with_camera(""),
       {"film..width=3"},
       R"(--set film..width=3: empty name in key "film..width")"},
  };
}

// An object whose shape is empty (no point has F > 0) cannot be seen: it is left out, and the
// scene says so in one line naming the object, which the command line prints as a warning.
TEST(SceneCompile, AnEmptyShapeIsLeftOutWithAWarningNamingTheObject) {
  const std::string shapes =
      R"("shapes": {"a": {"type": "sphere", "center": [0, 0, 0], "radius": 1},
                    "b": {"type": "sphere", "center": [5, 0, 0], "radius": 1},
                    "e": {"type": "intersection", "shapes": ["a", "b"]}}, )";
  const Scene seen = compile_scene(
      load_scene_text(with_camera(shapes + R"("objects": [{"shape": "a"}])"), "scene.json"));
  EXPECT_EQ(seen.objects.size(), 1u);
  EXPECT_TRUE(seen.warnings.empty());
  const Scene scene = compile_scene(load_scene_text(
      with_camera(shapes + R"("objects": [{"shape": "a"}, {"shape": "e"}])"), "scene.json"));
  EXPECT_EQ(scene.objects.size(), 1u);
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_EQ(scene.warnings[0],
            "scene.json: /objects/1/shape: shape \"e\" is empty (its function is positive "
            "nowhere); the object is not rendered");
  // Instances of an empty shape are all empty; ten empty objects are eight lines and a count.
  std::string many = R"("objects": [{"shape": "e", "instances": [[{"scale": 2}], [{"scale": 3}]]})";
  for (int i = 0; i < 10; ++i) many += R"(, {"shape": "e"})";
  const Scene crowd =
      compile_scene(load_scene_text(with_camera(shapes + many + "]"), "scene.json"));
  EXPECT_TRUE(crowd.objects.empty());
  ASSERT_EQ(crowd.warnings.size(), 9u);
  EXPECT_EQ(crowd.warnings[0],
            "scene.json: /objects/0/shape: shape \"e\" is empty (its function is positive "
            "nowhere); its 2 instances are not rendered");
  EXPECT_EQ(crowd.warnings[7].substr(0, 34), "scene.json: /objects/7/shape: shap");
  EXPECT_EQ(crowd.warnings[8],
            "scene.json: 3 more objects whose shapes are empty are not rendered");
}

TEST(SceneLoad, MalformedScenesGiveOneLineErrorsNamingThePath) {
  const std::vector<BadScene> cases = bad_scenes();
  EXPECT_GE(cases.size(), 25u);
  for (const BadScene& c : cases) {
    const std::string message = load_error(c.text, c.overrides);
    EXPECT_EQ(message, c.message) << c.what;
    EXPECT_EQ(message.find('\n'), std::string::npos) << c.what;
  }
}

// The fuzzer's seed corpus (fuzz/corpus, docs/testing.md) holds every bad scene above and every
// shipped scene, each in a file named after its text's FNV-1a hash. Run this test with
// NIMBUS_WRITE_FUZZ_CORPUS=1 to write the missing ones.
std::string corpus_name(const std::string& text) {
  uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return fmt::format("{:016x}.json", h);
}

TEST(SceneLoad, FuzzCorpusHoldsEveryBadAndShippedScene) {
  std::vector<std::string> texts;
  for (const BadScene& c : bad_scenes())
    if (c.overrides.empty()) texts.push_back(c.text);
  for (const char* dir : {"scenes", "scenes/bench"})
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(NIMBUS_SOURCE_DIR) + "/" + dir))
      if (entry.path().extension() == ".json") {
        std::ifstream in(entry.path(), std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        texts.push_back(text.str());
      }
  EXPECT_GE(texts.size(), 40u);
  const std::string corpus = std::string(NIMBUS_SOURCE_DIR) + "/fuzz/corpus/";
  const bool write = std::getenv("NIMBUS_WRITE_FUZZ_CORPUS") != nullptr;
  for (const std::string& text : texts) {
    const std::string path = corpus + corpus_name(text);
    std::ifstream in(path, std::ios::binary);
    std::stringstream held;
    held << in.rdbuf();
    if (write && held.str() != text) {
      std::ofstream(path, std::ios::binary) << text;
      continue;
    }
    EXPECT_EQ(held.str(), text) << path << " (NIMBUS_WRITE_FUZZ_CORPUS=1 writes it)";
  }
}

// Issue 13: optical thickness alone costs nothing (the walk is clipped to the exact surface), so a
// homogeneous gray medium of sigma_t = 10^8 compiles; the same density made chromatic would cost
// 10^8 null collisions per ray in its thinner channels and is refused, naming the object.
TEST(SceneLoad, DenseGrayMediaCompileAndDenseChromaticOnesAreRefused) {
  const std::string sphere =
      R"({"shape": {"type": "sphere", "radius": 1}, "surface": {"type": "none"},
                                 "medium": "smoke"})";
  auto scene = [&](const std::string& sigma_s) {
    return with_camera(R"("media": {"smoke": {"sigma_s": )" + sigma_s + R"(}}, "objects": [)" +
                       sphere + "]");
  };
  EXPECT_NO_THROW(compile_scene(load(scene("1e8"))));
  // Issue 29: gray and homogeneous but past about 1e17 per unit, the octree's outward rounding
  // (1e-12 of the density) is itself a null rate too costly; the refusal says why.
  try {
    compile_scene(load(scene("1e18")));
    ADD_FAILURE() << "a gray medium of 1e18 compiled";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("or a gray one past about 1e17 per unit of its size"),
              std::string::npos)
        << e.what();
  }
  try {
    compile_scene(load(scene("[1e8, 1e8, 1]")));
    ADD_FAILURE() << "a chromatic medium of 1e8 compiled";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(
                  "scene.json: /objects/0/medium: medium \"smoke\" may cost 3.46e+08 null", 0),
              0u)
        << e.what();
  }
  // Issue 29: a majorant scale of 10^7 on a thin field medium rendered as if hung; the guard now
  // sees the scale.
  const std::string field = with_camera(
      R"("media": {"m": {"sigma_s": 1, "density": {"type": "field"}}}, "objects": [{"shape": )"
      R"({"type": "sphere", "radius": 1}, "surface": {"type": "none"}, "medium": "m"}])");
  EXPECT_NO_THROW(compile_scene(load(field, {"integrator.majorant.scale=1e4"})));
  try {
    compile_scene(load(field, {"integrator.majorant.scale=1e7"}));
    ADD_FAILURE() << "a majorant scale of 1e7 compiled";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("scene.json: /objects/0/medium: medium \"m\" may cost ", 0), 0u) << m;
    EXPECT_NE(m.find("(integrator.majorant.scale 1e+07 multiplies the majorants)"),
              std::string::npos)
        << m;
  }
}

TEST(SceneLoad, ExampleLoads) {
  const SceneDesc s = load(documented_example());
  EXPECT_EQ(s.source, "scene.json");
  EXPECT_EQ(s.settings.width, 640);
  EXPECT_EQ(s.settings.height, 480);
  EXPECT_EQ(s.camera.type, CameraDesc::Type::Perspective);
  EXPECT_EQ(s.camera.from, (Vec3{0, 1, 6}));
  EXPECT_EQ(s.camera.fov, 35);
  EXPECT_EQ(s.settings.spp, 64);
  EXPECT_EQ(s.settings.sampler, RenderSettings::Sampler::ZSobol);
  EXPECT_EQ(s.settings.light_sampling, RenderSettings::LightSampling::One);
  EXPECT_EQ(s.settings.tracking.mode, TrackingSettings::Mode::SpectralMis);

  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_EQ(s.lights[0].type, Light::Type::Environment);
  EXPECT_EQ(s.lights[0].emission.rgb, Rgb({0.8, 0.9, 1.0}));
  EXPECT_EQ(s.lights[1].type, Light::Type::Directional);
  EXPECT_EQ(s.lights[1].direction, (Vec3{0, -1, 0}));
  EXPECT_EQ(s.lights[1].emission.rgb, Rgb(3));
  EXPECT_EQ(s.lights[2].type, Light::Type::Point);
  EXPECT_EQ(s.lights[2].position, (Vec3{1, 4, 2}));
  EXPECT_EQ(s.lights[3].type, Light::Type::Sphere);
  EXPECT_EQ(s.lights[3].radius, 0.5);

  // Media are ordered by name; objects refer to them by index.
  ASSERT_EQ(s.media.size(), 4u);
  EXPECT_EQ(s.media[0].name, "cloud");
  EXPECT_EQ(s.media[0].phase.type, PhaseDesc::Type::HenyeyGreenstein);
  EXPECT_EQ(s.media[0].phase.g, 0.85);
  const DensityPtr cloud_density = made_density(s.media[0]);
  const auto* cloud = dynamic_cast<const CloudDensity*>(cloud_density.get());
  ASSERT_NE(cloud, nullptr);
  EXPECT_EQ(cloud->params().seed, 7u);
  EXPECT_EQ(s.media[1].name, "fire");
  EXPECT_EQ(s.media[1].emission.rgb, Rgb({4, 1.5, 0.2}));
  EXPECT_EQ(s.media[1].phase.type, PhaseDesc::Type::Isotropic);
  EXPECT_EQ(s.media[2].name, "haze");
  EXPECT_EQ(s.media[2].sigma_a.rgb, Rgb(0.05));
  EXPECT_NE(dynamic_cast<const FieldDensity*>(made_density(s.media[2]).get()), nullptr);
  EXPECT_EQ(s.media[2].density_scale, 2.0);
  EXPECT_EQ(s.media[3].name, "marble");

  ASSERT_EQ(s.objects.size(), 4u);
  EXPECT_EQ(s.objects[0].shape_name, "blob");
  EXPECT_EQ(s.objects[0].json_path, "/objects/0");
  EXPECT_EQ(s.objects[0].surface.type, SurfaceDesc::Type::Diffuse);
  EXPECT_EQ(s.objects[0].surface.albedo.rgb, Rgb({0.7, 0.5, 0.3}));
  EXPECT_EQ(s.objects[0].medium, -1);
  EXPECT_EQ(s.objects[1].surface.albedo.rgb, Rgb(0.5));
  EXPECT_EQ(s.objects[2].medium, 3);
  EXPECT_EQ(s.objects[2].surface.type, SurfaceDesc::Type::Dielectric);
  EXPECT_EQ(s.objects[3].medium, 0);
  EXPECT_EQ(s.objects[3].surface.type, SurfaceDesc::Type::None);

  // The box is the intersection of three slabs.
  const auto* floor = std::get_if<CsgNode>(&s.objects[1].shape->node);
  ASSERT_NE(floor, nullptr);
  EXPECT_EQ(floor->op, CsgOp::Intersection);
  EXPECT_EQ(floor->children.size(), 3u);
}

TEST(SceneLoad, SpectralModeAndSpectralColours) {
  const SceneDesc s = load(with_camera(R"(
    "spectrum": {"mode": "spectral", "wavelengths": 4},
    "lights": [{"type": "environment", "radiance": {"blackbody": 6500, "scale": 2}},
               {"type": "point", "position": [0, 1, 0], "intensity": [1, 0.5, 0.25]}],
    "media": {"jade": {"sigma_s": {"spectrum": [[400, 1], [550, 4], [700, 2]]},
                       "sigma_a": 0.1}})"));
  EXPECT_EQ(s.settings.spectral.mode, SpectralSettings::Mode::Spectral);
  EXPECT_EQ(s.settings.spectral.wavelengths, 4);  // not the default, 8
  // A blackbody keeps its curve; rgb mode gets its projection, of luminance `scale`.
  ASSERT_TRUE(s.lights[0].emission.curve.has_value());
  EXPECT_EQ(s.lights[0].emission.curve->type, SpectralCurve::Type::Blackbody);
  EXPECT_NEAR(linear_srgb_to_xyz(s.lights[0].emission.rgb).y, 2.0, 1e-3);
  // RGB inputs get their curves when the scene is compiled.
  EXPECT_FALSE(s.lights[1].emission.curve.has_value());
  EXPECT_EQ(s.lights[1].emission.rgb, Rgb({1, 0.5, 0.25}));
  const SpectralParam& sigma_s = s.media[0].sigma_s;
  ASSERT_TRUE(sigma_s.curve.has_value());
  EXPECT_DOUBLE_EQ((*sigma_s.curve)(475), 2.5);
  EXPECT_DOUBLE_EQ((*sigma_s.curve)(300), 1.0);  // held beyond the ends
  // Its rgb-mode value is its projection: greenish, every component within the curve's range.
  EXPECT_GT(sigma_s.rgb[1], sigma_s.rgb[0]);
  EXPECT_GT(sigma_s.rgb[1], sigma_s.rgb[2]);
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(sigma_s.rgb[c] >= 0.5 && sigma_s.rgb[c] <= 4.5) << c;
  EXPECT_EQ(load(with_camera("")).settings.spectral.mode, SpectralSettings::Mode::Rgb);
}

TEST(SceneLoad, NamedShapesAreBuiltOnceAndShared) {
  const SceneDesc s = load(documented_example());
  EXPECT_EQ(s.objects[0].shape, s.objects[2].shape);
  const auto* blob = std::get_if<FreeFormNode>(&s.objects[0].shape->node);
  ASSERT_NE(blob, nullptr);
  EXPECT_EQ(blob->base, s.objects[3].shape);  // "ball"
  ASSERT_EQ(blob->perturbations.size(), 1u);
  EXPECT_EQ(blob->perturbations[0].weight, 2.5);
  const auto* bump = std::get_if<QuadricNode>(&blob->perturbations[0].shape->node);
  ASSERT_NE(bump, nullptr);
  EXPECT_EQ(bump->q.a, (std::array<double, 10>{-4, -4, -4, 0, 0, 0, 0, 0, 4, -0.75}));
}

TEST(SceneLoad, ShapeDefinitionMayBeAnAlias) {
  const SceneDesc s = load(with_camera(R"(
      "shapes": {"a": "b", "b": {"type": "sphere", "radius": 1}},
      "objects": [{"shape": "a"}, {"shape": "b"}])"));
  EXPECT_EQ(s.objects[0].shape, s.objects[1].shape);
  EXPECT_EQ(load_error(with_camera(R"("shapes": {"a": "b", "b": "a"})")),
            "scene.json: /shapes/a: cycle in shape references: a -> b -> a");
}

TEST(SceneLoad, DefaultsApplyWhereKeysAreOptional) {
  const SceneDesc s = load(with_camera(R"(
      "media": {"m": {}},
      "objects": [{"shape": {"type": "sphere", "radius": 1}},
                  {"shape": {"type": "sphere", "radius": 1}, "medium": "m"}])"));
  EXPECT_EQ(s.settings.width, 640);
  EXPECT_EQ(s.settings.height, 480);
  EXPECT_EQ(s.camera.type, CameraDesc::Type::Perspective);
  EXPECT_EQ(s.camera.up, (Vec3{0, 1, 0}));
  EXPECT_EQ(s.camera.fov, 40);
  EXPECT_EQ(s.settings.spp, 16);
  EXPECT_EQ(s.settings.seed, 0u);
  EXPECT_EQ(s.settings.max_depth, 1000);
  EXPECT_EQ(s.settings.tracking.absorption, TrackingSettings::Absorption::Weight);
  EXPECT_FALSE(s.settings.tracking.decomposition);
  EXPECT_EQ(s.settings.tracking.transmittance, TrackingSettings::Transmittance::ResidualRatio);
  EXPECT_EQ(s.settings.tracking.majorant_source, TrackingSettings::MajorantSource::Bound);
  EXPECT_EQ(s.settings.tracking.majorant_samples, 4096);
  EXPECT_EQ(s.settings.tracking.majorant_scale, 1.0);
  EXPECT_EQ(s.settings.tracking.octree_depth, 4);
  EXPECT_TRUE(s.lights.empty());
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_TRUE(s.media[0].sigma_s.rgb.is_black());
  EXPECT_NE(dynamic_cast<const ConstantDensity*>(made_density(s.media[0]).get()), nullptr);
  EXPECT_EQ(s.media[0].density_scale, 1.0);
  EXPECT_EQ(s.objects[0].shape_name, "inline");
  EXPECT_EQ(s.objects[0].surface.type, SurfaceDesc::Type::Diffuse);
  EXPECT_EQ(s.objects[0].surface.albedo.rgb, Rgb(0.5));
  EXPECT_EQ(s.objects[1].surface.type, SurfaceDesc::Type::None);
  EXPECT_EQ(s.objects[1].medium, 0);
}

TEST(SceneLoad, InlineShapesNestAndMayReferToNamedOnes) {
  const SceneDesc s = load(with_camera(R"(
      "shapes": {"ball": {"type": "sphere", "radius": 1}},
      "objects": [{"shape": {"type": "difference",
                             "shapes": ["ball", {"type": "halfspace", "normal": [0, 1, 0]}]}}])"));
  const auto* csg = std::get_if<CsgNode>(&s.objects[0].shape->node);
  ASSERT_NE(csg, nullptr);
  EXPECT_EQ(csg->op, CsgOp::Difference);
  ASSERT_EQ(csg->children.size(), 2u);
  const auto* ball = std::get_if<QuadricNode>(&csg->children[0]->node);
  ASSERT_NE(ball, nullptr);
  EXPECT_EQ(ball->q.a, sphere({}, 1).a);
  const auto* half = std::get_if<QuadricNode>(&csg->children[1]->node);
  ASSERT_NE(half, nullptr);
  EXPECT_EQ(half->q.a, halfspace({}, {0, 1, 0}).a);
}

// The quadric of a single-quadric shape, with its transform applied.
Quadric world_quadric(const ShapePtr& s) {
  return transformed(std::get<QuadricNode>(s->node).q, s->transform);
}

TEST(SceneLoad, TransformStepsApplyInListedOrder) {
  const SceneDesc s = load(with_camera(R"("objects": [
      {"shape": {"type": "sphere", "radius": 1,
                 "transform": [{"scale": 2}, {"translate": [1, 0, 0]}]}},
      {"shape": {"type": "sphere", "radius": 1,
                 "transform": [{"translate": [1, 0, 0]}, {"scale": 2}]}},
      {"shape": {"type": "ellipsoid", "radii": [2, 1, 1],
                 "transform": [{"rotate": {"axis": [0, 0, 1], "degrees": 90}},
                               {"translate": [0, 0, 5]}, {"scale": [1, 1, 0.5]}]}}])"));
  // Scaled by 2, then moved: radius 2 around (1, 0, 0). F' = F(M⁻¹x) keeps F's value 1 at the
  // centre.
  const Quadric a = world_quadric(s.objects[0].shape);
  EXPECT_NEAR(a.eval({1, 0, 0}), 1, 1e-12);
  EXPECT_NEAR(a.eval({3, 0, 0}), 0, 1e-12);
  EXPECT_NEAR(a.eval({1, -2, 0}), 0, 1e-12);
  // Moved, then scaled about the origin: radius 2 around (2, 0, 0).
  const Quadric b = world_quadric(s.objects[1].shape);
  EXPECT_NEAR(b.eval({2, 0, 0}), 1, 1e-12);
  EXPECT_NEAR(b.eval({4, 0, 0}), 0, 1e-12);
  EXPECT_NEAR(b.eval({0, 0, 0}), 0, 1e-12);
  // Long axis turned from x to y, centre moved to z = 5, then z halved: centre (0, 0, 2.5).
  const Quadric c = world_quadric(s.objects[2].shape);
  EXPECT_NEAR(c.eval({0, 0, 2.5}), 1, 1e-12);
  EXPECT_NEAR(c.eval({0, 2, 2.5}), 0, 1e-12);
  EXPECT_NEAR(c.eval({1, 0, 2.5}), 0, 1e-12);
  EXPECT_NEAR(c.eval({0, 0, 3}), 0, 1e-12);
}

TEST(SceneLoad, TransformOfABoxAppliesToTheWholeBox) {
  const SceneDesc s = load(with_camera(R"("objects": [
      {"shape": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1],
                 "transform": [{"translate": [10, 0, 0]}]}}])"));
  EXPECT_EQ(s.objects[0].shape->transform(0, 3), 10);
  for (const ShapePtr& slab : std::get<CsgNode>(s.objects[0].shape->node).children)
    EXPECT_EQ(slab->transform(0, 3), 0);
}

TEST(SceneLoad, OverridesReplaceAndCreateValues) {
  const SceneDesc s =
      load(documented_example(),
           {"integrator.spp=256", "camera.from=[1, 2, 3]", "camera.type=orthographic",
            "integrator.majorant.scale=1.5", "film.width=100", "film.width=200",
            "lights.0.radiance=[0.1, 0.2, 0.3]", R"(integrator.tracking="spectral-mis")",
            "integrator.octree={\"depth\": 3}", R"(integrator.sampler="independent")",
            R"(integrator.light_sampling="all")"});
  EXPECT_EQ(s.settings.spp, 256);
  EXPECT_EQ(s.settings.sampler, RenderSettings::Sampler::Independent);
  EXPECT_EQ(s.settings.light_sampling, RenderSettings::LightSampling::All);
  EXPECT_EQ(s.camera.from, (Vec3{1, 2, 3}));
  EXPECT_EQ(s.camera.type, CameraDesc::Type::Orthographic);
  EXPECT_EQ(s.settings.tracking.majorant_scale, 1.5);
  EXPECT_EQ(s.settings.width, 200);  // the last override wins
  EXPECT_EQ(s.lights[0].emission.rgb, Rgb({0.1, 0.2, 0.3}));
  EXPECT_EQ(s.settings.tracking.mode, TrackingSettings::Mode::SpectralMis);
  EXPECT_EQ(s.settings.tracking.octree_depth, 3);
}

// Issue 16: inline unions nested 5 000 deep and chains of 30 000 named aliases crashed the
// loader (stack overflow). Beyond kMaxShapeDepth levels they are one error at the place.
// Issue 29: a shape named "x\ny" split an error over two lines, "\u001b[31m" sent an escape
// sequence to the terminal, an overlong UTF-8 form was echoed raw, a 10 MB key made a 10 MB
// line. Every scene error is one printable line of bounded length.
TEST(SceneLoad, MessagesAreOnePrintableBoundedLine) {
  EXPECT_EQ(printable_line("a\nb\tc\x1b[31md\x7f"), "a\\nb\\tc\\x1b[31md\\x7f");
  EXPECT_EQ(printable_line("caf\xc3\xa9 \xe2\x88\x9e \xf0\x9f\x8c\xab"),
            "caf\xc3\xa9 \xe2\x88\x9e \xf0\x9f\x8c\xab");                 // UTF-8 stays
  EXPECT_EQ(printable_line("\xc0\x80"), "\\xc0\\x80");                    // overlong NUL
  EXPECT_EQ(printable_line("\xe0\x80\xaf"), "\\xe0\\x80\\xaf");           // overlong '/'
  EXPECT_EQ(printable_line("\xed\xa0\x80"), "\\xed\\xa0\\x80");           // a surrogate
  EXPECT_EQ(printable_line("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");  // past U+10FFFF
  EXPECT_EQ(printable_line("\xc2\x9b"
                           "1m"),
            "\\xc2\\x9b"
            "1m");                                      // C1 CSI
  EXPECT_EQ(printable_line("\xe2\x88"), "\\xe2\\x88");  // cut short
  const std::string big(10 << 20, 'k');
  const std::string cut = printable_line("key " + big + " end");
  EXPECT_LE(cut.size(), kMaxMessageBytes);
  EXPECT_NE(cut.find("(10485768 bytes in all)"), std::string::npos) << cut.substr(0, 80);
  EXPECT_EQ(cut.substr(cut.size() - 4), " end");

  for (const std::string name : {"x\\ny", "\\u001b[31mred", "\\u0085next"}) {
    const std::string message =
        load_error(with_camera(R"("shapes": {")" + name + R"(": {"type": "blobb"}})"));
    EXPECT_EQ(message.find_first_of("\n\x1b"), std::string::npos) << message;
    EXPECT_EQ(message.find("\xc2\x85"), std::string::npos) << message;
    EXPECT_NE(message.find("unknown"), std::string::npos) << message;
  }
  const std::string message = load_error(with_camera(R"("shapes": {")" + big + R"(": 1})"));
  EXPECT_LE(message.size(), kMaxMessageBytes);
}

// Issue 29: 200 000 nested arrays (400 KB) took 24 GB before the depth was checked, memory
// growing with the square of the depth. The depth is checked while parsing: a file or a --set
// value nested past kMaxJsonDepth is refused with one line, at once.
TEST(SceneLoad, DocumentsNestedTooDeeplyAreRefusedWhileParsing) {
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  try {
    load_scene_text(with_camera(R"("shapes": {"s": )" + deep + "}"), "scene.json");
    ADD_FAILURE() << "a document nested 200 000 deep was accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("scene.json: /shapes/s/0/0/0/", 0), 0u) << m.substr(0, 300);
    EXPECT_NE(m.find("/.../"), std::string::npos) << m.substr(0, 300);
    EXPECT_NE(m.find(": arrays and objects nest deeper than 1024 levels"), std::string::npos)
        << m.substr(0, 300);
    EXPECT_LT(m.size(), 400u);
  }
  try {
    load_scene_text(with_camera(""), "scene.json", {"shapes.s=" + deep});
    ADD_FAILURE() << "a --set value nested 200 000 deep was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("nest deeper than 1024 levels"), std::string::npos);
  }
}

// Issue 29: overflow was misdiagnosed. A camera 1e200 away was "parallel to the default up", a
// sphere centred there "unbounded", 400 scalings by 10 "determinant -nan". Coordinates and
// lengths beyond 1e100 are refused with their range; a transform that leaves a double's range
// says so.
TEST(SceneLoad, HugeCoordinatesAndTransformsAreRefusedWithTheirRange) {
  EXPECT_EQ(load_error(R"({"camera": {"from": [0, 0, 1e200], "to": [0, 0, 0]}})"),
            "scene.json: /camera/from/2: must be in [-1e+100, 1e+100]");
  EXPECT_EQ(load_error(with_object(
                R"({"shape": {"type": "sphere", "center": [1e200, 0, 0], "radius": 1}})")),
            "scene.json: /objects/0/shape/center/0: must be in [-1e+100, 1e+100]");
  std::string steps = "[";
  for (int i = 0; i < 400; ++i) steps += R"({"scale": 10}, )";
  for (int i = 0; i < 400; ++i) steps += std::string(R"({"scale": 0.1})") + (i < 399 ? ", " : "]");
  EXPECT_EQ(load_error(with_object(R"({"shape": {"type": "sphere", "radius": 1, "transform": )" +
                                   steps + "}}")),
            "scene.json: /objects/0/shape/transform: the steps compose to a transform beyond a "
            "double's range (their scales multiply)");
}

// Issue 29: numbers past a double had no JSON path ("number overflow parsing '1e400'") or became
// strings through --set ("not a string"), a seed past 2^64 - 1 was "a fraction", and duplicate
// keys in a --set value were accepted.
TEST(SceneLoad, NumbersOutOfRangeAndDuplicateKeysInSetAreNamed) {
  const std::string range = "beyond a double's range (finite, at most 1.8e308 in magnitude)";
  const auto text_error = [](const std::string& text) {
    try {
      load_scene_text(text, "scene.json");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(text_error(with_camera(R"("film": {"width": 1e400})")),
            "scene.json: /film/width: the number 1e400 is " + range);
  EXPECT_EQ(text_error(with_camera(
                R"("lights": [{"type": "point", "position": [0, -1e999, 0], "intensity": 1}])")),
            "scene.json: /lights/0/position/1: the number -1e999 is " + range);
  EXPECT_EQ(load_error(with_camera(""), {"camera.fov=1e999"}),
            "--set camera.fov=1e999: a number " + range);
  EXPECT_EQ(load_error(with_camera(""), {R"(camera={"from": [0, 0, 5], "from": [1, 1, 1]})"}),
            R"(--set camera={"from": [0, 0, 5], "from": [1, 1, 1]}: /from: duplicate key "from")");
  EXPECT_EQ(load_error(with_camera(""), {"integrator.seed=18446744073709551616"}),
            "--set integrator.seed=18446744073709551616: /integrator/seed: must be <= "
            "18446744073709551615");
  EXPECT_EQ(load(with_camera(""), {"integrator.seed=18446744073709551615"}).settings.seed,
            18446744073709551615ull);
}

TEST(SceneLoad, DeeplyNestedShapesAreAnErrorNotACrash) {
  std::string text = R"({"type": "sphere", "radius": 1})";
  // 300 levels: past kMaxShapeDepth, within kMaxJsonDepth (2 JSON levels a union).
  for (int i = 0; i < 300; ++i) text = R"({"type": "union", "shapes": [)" + text + "]}";
  const std::string nested = load_error(with_object(R"({"shape": )" + text + "}"));
  std::string at = "/objects/0/shape";
  for (int i = 0; i < kMaxShapeDepth; ++i) at += "/shapes/0";
  // Cut to kMaxMessageBytes around the middle of the pointer.
  EXPECT_EQ(nested, printable_line("scene.json: " + at + ": shapes nest more than " +
                                   std::to_string(kMaxShapeDepth) +
                                   " levels deep here (inline shapes, bases, perturbations, "
                                   "children and named references together)"));

  std::string shapes;
  for (int i = 0; i < 30000; ++i)
    shapes += "\"s" + std::to_string(i) + "\": \"s" + std::to_string(i + 1) + "\", ";
  shapes += R"("s30000": {"type": "sphere", "radius": 1})";
  const std::string chain = load_error(with_camera(R"("shapes": {)" + shapes + "}"));
  EXPECT_NE(chain.find("shapes nest more than"), std::string::npos) << chain.substr(0, 200);

  // Up to the limit, nesting is fine.
  std::string ok = R"({"type": "sphere", "radius": 1})";
  for (int i = 1; i < kMaxShapeDepth - 1; ++i) ok = R"({"type": "union", "shapes": [)" + ok + "]}";
  EXPECT_EQ(load_error(with_object(R"({"shape": )" + ok + "}")), "(no error)");
}

TEST(SceneLoad, OverrideCreatesMissingSections) {
  const SceneDesc s = load(with_camera(""), {"integrator.majorant.source=sample"});
  EXPECT_EQ(s.settings.tracking.majorant_source, TrackingSettings::MajorantSource::Sample);
}

TEST(SceneLoad, OverrideReturnsTheEscapedPointerOfWhatItOwns) {
  nlohmann::json j = nlohmann::json::object();
  // It created "shapes": everything below is the override's.
  EXPECT_EQ(apply_override(j, "shapes.a/b~c.radius=2"), "/shapes");
  EXPECT_EQ(j["shapes"]["a/b~c"]["radius"], 2);
  // Now only the value is new.
  EXPECT_EQ(apply_override(j, "shapes.a/b~c.radius=3"), "/shapes/a~1b~0c/radius");
  EXPECT_EQ(apply_override(j, "shapes.a/b~c.center=[0, 0, 0]"), "/shapes/a~1b~0c/center");
  EXPECT_EQ(apply_override(j, "note=two words"), "/note");
  EXPECT_EQ(j["note"], "two words");
}

// Writes text to a file named scene.json in a fresh directory.
class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("nimbus_scene_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& text) {
    const std::string path = (dir_ / "scene.json").string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
};

std::string file_error(const std::string& path) {
  try {
    load_scene_file(path);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST_F(SceneFileTest, FileLoadsWithComments) {
  const std::string path = write(R"({
    // Comments help explain scenes.
    "camera": {"from": [0, 0, 5], "to": [0, 0, 0]} /* required */
  })");
  const SceneDesc s = load_scene_file(path, {"film.height=10"});
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.settings.height, 10);
}

TEST_F(SceneFileTest, SyntaxErrorGivesLineAndColumn) {
  const std::string path = write("{\n  \"film\": {\n    width: 3}}");
  const std::string message = file_error(path);
  EXPECT_EQ(message.rfind(path + ": parse error at line 3, column 5: ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST_F(SceneFileTest, NumberOverflowIsAnError) {
  const std::string path = write(R"({"film": {"width": 1e400}})");
  EXPECT_EQ(file_error(path), path +
                                  ": /film/width: the number 1e400 is beyond a double's range "
                                  "(finite, at most 1.8e308 in magnitude)");
}

TEST_F(SceneFileTest, MissingFileIsAnError) {
  const std::string path = (dir_ / "none.json").string();
  EXPECT_EQ(file_error(path), path + ": cannot open file (No such file or directory)");
  EXPECT_EQ(file_error(dir_.string()), dir_.string() + ": cannot open file (is a directory)");
}

// Issue 16: a key given twice in one object was silently merged (one of them won).
TEST_F(SceneFileTest, DuplicateKeysAreAnErrorAtTheirPath) {
  std::string path = write(R"({"film": {"width": 8, "height": 4, "width": 9}})");
  EXPECT_EQ(file_error(path), path + R"(: /film/width: duplicate key "width")");
  path = write(R"({"lights": [{"type": "environment"}, {"type": "point", "type": "sphere"}]})");
  EXPECT_EQ(file_error(path), path + R"(: /lights/1/type: duplicate key "type")");
  path = write(R"({"shapes": {"a/b": {}, "c": [[1, {"k": 1, "k": 2}]]}})");
  EXPECT_EQ(file_error(path), path + R"(: /shapes/c/0/1/k: duplicate key "k")");
  // The same key in different objects is no duplicate.
  path = write(R"({"film": {"width": 8}, "camera": {"width": 2}})");
  EXPECT_EQ(file_error(path).find("duplicate"), std::string::npos) << file_error(path);
}

// Issue 16: a FIFO as the scene path hung with no word, and /dev/zero grew to 16.8 GB; a binary
// or oversized file is refused before it is parsed.
TEST_F(SceneFileTest, OnlyRegularUtf8FilesOfBoundedSizeAreRead) {
  const std::string fifo = (dir_ / "fifo.json").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(file_error(fifo), fifo + ": not a regular file (a FIFO)");
  EXPECT_EQ(file_error("/dev/zero"), "/dev/zero: not a regular file (a character device)");
  const std::string binary = write(std::string("{\"film\": \xff}"));
  EXPECT_EQ(file_error(binary), binary + ": not UTF-8 text (byte 9)");
  const std::string cut = write(std::string("{\"a\": \"\xc3"));
  EXPECT_EQ(file_error(cut), cut + ": not UTF-8 text (byte 7)");
  // Strictly UTF-8 (issue 29: an overlong form was accepted and echoed raw), and no NUL byte
  // (it read as "unexpected end of input"); text given in memory is checked alike.
  const std::string overlong = write(std::string("{\"a\": \"\xc0\xae\"}"));
  EXPECT_EQ(file_error(overlong), overlong + ": not UTF-8 text (byte 7)");
  const std::string surrogate = write(std::string("{\"a\": \"\xed\xa0\x80\"}"));
  EXPECT_EQ(file_error(surrogate), surrogate + ": not UTF-8 text (byte 7)");
  const std::string nul = write(std::string("{\"a\": 1}\0 ", 11));
  EXPECT_EQ(file_error(nul), nul + ": a NUL byte at byte 8 (a scene file is text)");
  EXPECT_THROW(
      {
        try {
          load_scene_text("{\"a\": \"\xc0\xae\"}", "in memory");
        } catch (const SceneError& e) {
          EXPECT_STREQ(e.what(), "in memory: not UTF-8 text (byte 7)");
          throw;
        }
      },
      SceneError);
  const std::string ok = write(std::string("{\"film\": {\"width\": 8}} // caf\xc3\xa9"));
  EXPECT_EQ(file_error(ok).find("UTF-8"), std::string::npos) << file_error(ok);
  const std::string big = (dir_ / "big.json").string();
  std::ofstream(big) << "{}";
  std::filesystem::resize_file(big, kMaxSceneFileBytes + 1);  // sparse: costs no disk
  EXPECT_EQ(file_error(big), fmt::format("{}: the file has {} bytes; a scene file may have at "
                                         "most {}",
                                         big, kMaxSceneFileBytes + 1, kMaxSceneFileBytes));
}

}  // namespace scene_load_test
}  // namespace nimbus
