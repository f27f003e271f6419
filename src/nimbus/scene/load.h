#pragma once
// Loading a scene file (docs/scene-format.md) into a SceneDesc, its JSON read through
// scene/json_text.h (file checks, parsing with limits, --set). All validation happens here:
// every error is a SceneError whose message is one line, "SOURCE: /json/pointer: problem", where
// SOURCE is the file name, or the "--set KEY=VALUE" flag that put the offending value in place.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nimbus/math/mat4.h"
#include "nimbus/scene/json_reader.h"
#include "nimbus/scene/json_text.h"
#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// How deeply shapes may nest in a scene file (docs/scene-format.md).
inline constexpr int kMaxShapeDepth = 256;

static_assert(kMaxJsonDepth >= 4 * kMaxShapeDepth,
              "the JSON depth limit (scene/json_text.h) must leave room for the deepest shapes");

// Points, directions and lengths (a position, a radius, a translation) lie within ±1e100: their
// squares and products, which the quadrics and the camera compute, stay within a double
// (issue 29: a camera 1e200 away was "parallel to up", a sphere there "unbounded").
inline constexpr double kMaxCoordinate = 1e100;
inline const Range kCoordinate = between(-kMaxCoordinate, kMaxCoordinate);
// Lengths are at least 1e-100, whose square is a normal double (issue 26: a sphere of radius
// 1e-320 squared it to 0 and was an object of no size, rendered as nothing without a word).
inline constexpr double kMinLength = 1e-100;
inline const Range kLength = between(kMinLength, kMaxCoordinate);

// Emitted light (a light's radiance, irradiance or intensity, a surface's or a medium's radiance,
// a blackbody's or a temperature grid's scale) lies within [0, 1e30]: a film sums light of any
// scale exactly (film.h, film_exponent), but an EXR holds 32-bit floats (at most 3.4e38), which
// light of 1e30 leaves 10^8 of room for falloff and weights (issue 29: a point light of 1e308
// made NaN samples, a blackbody scaled by 1e300 a black image).
inline constexpr double kMaxEmission = 1e30;
inline const Range kEmission = between(0, kMaxEmission);

// A free form's perturbation weights lie within ±1e15: the flat free forms' polynomial
// (frep/intersect.cpp) keeps its roots to 1e-6 there and lost them from about 1e30 (issue 29:
// weights of 1e50 speckled the surface, 1.7e308 made holes and NaN).
inline constexpr double kMaxPerturbationWeight = 1e15;

// Reads, parses and validates a scene file; every problem is one SceneError line naming the
// file and, inside it, the JSON path.
SceneDesc load_scene_file(const std::string& path, const std::vector<std::string>& overrides = {});

// As load_scene_file for a scene file's text already in memory (the fuzzer's entry point);
// `source` names it in messages.
SceneDesc load_scene_text(const std::string& text, const std::string& source,
                          const std::vector<std::string>& overrides = {});

// As load_scene_file for a document already parsed; `source` names it in messages.
SceneDesc load_scene_json(nlohmann::json j, const std::string& source,
                          const std::vector<std::string>& overrides = {});

// One shape of the scene format on its own (Python's nimbus.Shape): `shape` a shape value, named
// shapes it refers to in `shapes` (a table as the scene file's, or null), checked as in a scene
// file; messages read "SOURCE: /shape/...: problem" or "SOURCE: /shapes/NAME/...: problem".
ShapePtr load_shape_json(const nlohmann::json& shape, const nlohmann::json& shapes,
                         const std::string& source);

// A "camera" value on its own (nimbus view's camera moves), checked as in a scene file; messages
// read "SOURCE: /camera/...: problem".
CameraDesc load_camera_json(const nlohmann::json& camera, const std::string& source);

// A "transform" value (docs/scene-format.md): steps applied in the listed order; a degenerate one
// fails. Shapes and the "vdb" density read it.
Mat4 read_transform(const JsonValue& v);

// What is wrong with a transform placing a shape, or "": an entry beyond ±kMaxCoordinate (or not
// finite), or a determinant that overflows or is degenerate (|det| <= 1e-12).
std::string transform_problem(const Mat4& m);

}  // namespace nimbus
