#pragma once
// The scene as the scene file states it, validated (scene/load.h) and nothing more: plain
// structs with the file's defaults. Loading reads the scene file and the instances files its
// objects name (their transforms are what the description says); what a grid file holds is read
// by compile_scene (scene/input_file.h), which builds the run-time Scene and trusts these values;
// docs/scene-format.md documents every field.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nimbus/frep/shape_desc.h"
#include "nimbus/math/vec3.h"
#include "nimbus/media/constant_density.h"
#include "nimbus/media/density.h"
#include "nimbus/media/temperature_emission.h"
#include "nimbus/render/scene.h"
#include "nimbus/scene/input_file.h"
#include "nimbus/spectral/spectral_param.h"

namespace nimbus {

struct CameraDesc {
  enum class Type { Perspective, Orthographic };
  Type type = Type::Perspective;
  Vec3 from, to, up{0, 1, 0};
  double fov = 40;   // vertical field of view in degrees (perspective)
  double width = 2;  // width of the view in world units (orthographic)
};

// Colour inputs are SpectralParam: RGB (a number or [r, g, b]) or a curve from the file
// ({"spectrum": [[nm, value], ...]}, or {"blackbody": K, "scale": s} where light is emitted).
// Lights are the run-time Light itself (render/light.h), read by scene/light_types.cpp.

struct PhaseDesc {
  enum class Type { Isotropic, HenyeyGreenstein };
  Type type = Type::Isotropic;
  double g = 0;
};

// A parameter that a solid texture drives (docs/scene-format.md, "Textures"):
// {"texture": T, "from": a, "to": b} is a + (b − a) · clamp(t(x), 0, 1). Unset: the parameter
// is the plain value beside it ("from" then holds it).
struct TextureDesc {
  // How compile_scene makes the pattern, a density type's (scene/density_types.h); null: none.
  Deferred<DensityPtr> make;
  double scale = 1;
  explicit operator bool() const { return bool(make); }
};

struct MediumDesc {
  std::string name;
  SpectralParam sigma_a, sigma_s, emission;
  // Textured coefficients: sigma_a and sigma_s are then their "from" values.
  TextureDesc sigma_a_texture, sigma_s_texture;
  SpectralParam sigma_a_to, sigma_s_to;
  // Set: the emission is a temperature grid's (media/temperature_emission.h), read from its file
  // when the scene is compiled.
  Deferred<std::shared_ptr<const TemperatureEmission>> emission_grid;
  // "emission_per_length": a colour, or a temperature grid as above.
  SpectralParam j;
  Deferred<std::shared_ptr<const TemperatureEmission>> j_grid;
  PhaseDesc phase;
  // How compile_scene makes the density (its type's reader, scene/density_types.h, checked the
  // keys; a "vdb" density's file is read then).
  Deferred<DensityPtr> density = [](std::vector<InputFile>&) { return make_constant_density(); };
  bool constant_density = true;  // the density is the "constant" type: its octree is one node
  double density_scale = 1;
};

struct SurfaceDesc {
  using Type = Surface::Type;
  Type type = Type::Diffuse;
  SpectralParam albedo{Rgb(0.5)};            // diffuse
  double ior = 1.5;                          // dielectric
  SpectralParam radiance;                    // emissive
  double roughness = 0;                      // dielectric, conductor
  bool multiple_scattering = true;           // dielectric, conductor
  SpectralParam eta{Rgb(1.0)}, k{Rgb(0.0)};  // conductor
  // Textured albedo and roughness: albedo and roughness are then their "from" values.
  TextureDesc albedo_texture, roughness_texture;
  SpectralParam albedo_to;
  double roughness_to = 0;
};

struct ObjectDesc {
  ShapePtr shape;
  std::string shape_name;  // the name in "shapes", or "inline"
  std::string json_path;   // e.g. "/objects/1", for messages from later stages
  SurfaceDesc surface;
  int medium = -1;  // index into SceneDesc::media, or -1
  // The "instances" key: copies of the object, each with its shape placed by one transform
  // (after the shape's own); null: the object once, as its shape stands.
  std::shared_ptr<const std::vector<Mat4>> instances;
  // The objects this one stands for.
  std::size_t copies() const { return instances ? instances->size() : 1; }
};

struct SceneDesc {
  std::string source;  // the file name (or other source) used in messages
  // The "film", "integrator" and "spectrum" sections: the render's settings themselves, read
  // through their declarations (render/settings.h).
  RenderSettings settings;
  CameraDesc camera;
  std::vector<Light> lights;
  std::vector<MediumDesc> media;
  std::vector<ObjectDesc> objects;
  // The files read while loading (instances files), for the render's fingerprint.
  std::vector<InputFile> inputs;
  // The document as loaded, after the overrides (null for a description built in code): with the
  // files that compiling it reads, what the render is of (job/fingerprint.h), without a second
  // parse.
  nlohmann::json document;
};

}  // namespace nimbus
