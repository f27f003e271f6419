#include "nimbus/scene/load.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "nimbus/frep/primitives.h"
#include "nimbus/frep/tape.h"
#include "nimbus/media/octree.h"
#include "nimbus/render/scene.h"
#include "nimbus/render/setting_names.h"
#include "nimbus/render/settings.h"
#include "nimbus/render/wavelength_counts.h"
#include "nimbus/scene/colour_reader.h"
#include "nimbus/scene/density_types.h"
#include "nimbus/scene/emission_grid.h"
#include "nimbus/scene/instances_file.h"
#include "nimbus/scene/light_types.h"
#include "nimbus/spectral/metals.h"

namespace nimbus {
namespace {

// Below this |det| a transform squashes space so much that the transformed quadric's
// coefficients (which use its inverse) are meaningless.
constexpr double kMinDeterminant = 1e-12;

// In the order of SurfaceDesc::Type, so that an index is the enumerator.
const std::vector<std::string_view> kSurfaceTypes = {"none", "diffuse", "dielectric", "emissive",
                                                     "conductor"};

}  // namespace

SpectralParam read_colour(const JsonValue& v, SpectralRole role, const Range& range) {
  if (!v.json().is_object()) return SpectralParam(v.rgb(range));
  if (v.json().contains("texture")) v.fail(kTakesNoTexture);
  JsonObject o(v);
  const auto spectrum = o.optional("spectrum");
  const auto blackbody = role == SpectralRole::Illuminant ? o.optional("blackbody") : std::nullopt;
  const auto scale = blackbody ? o.optional("scale") : std::nullopt;
  o.finish(role == SpectralRole::Illuminant ? "(expected \"spectrum\" or \"blackbody\")"
                                            : "(expected \"spectrum\")");
  if (spectrum && blackbody) blackbody->fail("give either \"spectrum\" or \"blackbody\", not both");
  if (blackbody) {
    const double kelvin = blackbody->number(between(100, 1e6));
    const double s = scale ? scale->number(kEmission) : 1.0;
    return from_curve(blackbody_spectrum(kelvin, s), role);
  }
  if (!spectrum)
    v.fail(role == SpectralRole::Illuminant
               ? "expected a number, [r, g, b], {\"spectrum\": ...} or {\"blackbody\": ...}"
               : "expected a number, [r, g, b] or {\"spectrum\": [[nm, value], ...]}");
  const std::vector<JsonValue> entries = spectrum->array();
  if (entries.empty()) spectrum->fail("expected at least one [nm, value] pair");
  std::vector<std::pair<double, double>> points;
  for (const JsonValue& e : entries) {
    if (!e.json().is_array() || e.json().size() != 2) e.fail("expected a pair [nm, value]");
    const std::vector<JsonValue> pair = e.array();
    const double nm = pair[0].number(between(1, 100000));
    if (!points.empty() && !(nm > points.back().first))
      pair[0].fail(fmt::format("wavelengths must increase (after {} nm)", points.back().first));
    points.emplace_back(nm, pair[1].number(range));
  }
  return from_curve(piecewise_linear_spectrum(std::move(points)), role);
}

namespace {

std::string string_choice(const JsonValue& v, std::string_view noun,
                          const std::vector<std::string_view>& names) {
  return std::string(names[v.choice(noun, names)]);
}

// One of a setting's names (render/setting_names.h), as its value.
template <class E, size_t K>
E choice_of(const JsonValue& v, std::string_view noun,
            const std::array<std::pair<std::string_view, E>, K>& table) {
  std::vector<std::string_view> names;
  for (const auto& entry : table) names.push_back(entry.first);
  return table[v.choice(noun, names)].second;
}

}  // namespace

Mat4 read_transform(const JsonValue& v) {
  Mat4 m = Mat4::identity();
  for (const JsonValue& step_value : v.array()) {
    JsonObject step(step_value);
    const auto translate = step.optional("translate");
    const auto rotate = step.optional("rotate");
    const auto scale = step.optional("scale");
    step.finish();
    if (step_value.json().size() != 1)
      step.fail(R"(expected exactly one of "translate", "rotate", "scale")");
    Mat4 s;
    if (translate) {
      s = Mat4::translate(translate->vec3(kCoordinate));
    } else if (rotate) {
      JsonObject r(*rotate);
      const Vec3 axis = r.required("axis").direction();
      const double degrees = r.required("degrees").number();
      r.finish();
      s = Mat4::rotate(axis, degrees);
    } else if (scale->json().is_number()) {
      const double k = scale->number();
      if (k == 0) scale->fail("must be nonzero");
      s = Mat4::scale({k, k, k});
    } else {
      const Vec3 k = scale->vec3();
      for (int i = 0; i < 3; ++i)
        if (k[i] == 0) scale->array()[i].fail("must be nonzero");
      s = Mat4::scale(k);
    }
    m = s * m;  // steps apply in the listed order
  }
  // Scale factors multiply along the steps: 400 steps of 10 leave a double's range.
  if (!std::isfinite(determinant(m)))
    v.fail("the steps compose to a transform beyond a double's range (their scales multiply)");
  if (const std::string problem = transform_problem(m); !problem.empty()) v.fail(problem);
  return m;
}

std::string transform_problem(const Mat4& m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (!(std::abs(m(r, c)) <= kMaxCoordinate))
        return fmt::format("entry ({}, {}) is {}; entries must be within ±{:g}", r, c, m(r, c),
                           kMaxCoordinate);
  const double det = determinant(m);
  if (!std::isfinite(det)) return "a transform beyond a double's range (determinant overflows)";
  if (!(std::abs(det) > kMinDeterminant))
    return fmt::format("degenerate transform (determinant {})", det);
  return "";
}

namespace {

class Loader {
 public:
  explicit Loader(const JsonValue& document) : root_(document) {}

  SceneDesc load() {
    // Every top-level key is asked for before any is read, so that a misspelt section is
    // reported as such rather than as a missing one.
    const auto film = root_.optional("film");
    const auto camera = root_.optional("camera");
    const auto integrator = root_.optional("integrator");
    const auto spectrum = root_.optional("spectrum");
    const auto lights = root_.optional("lights");
    const auto shapes = root_.optional("shapes");
    const auto media = root_.optional("media");
    const auto objects = root_.optional("objects");
    root_.finish();

    SceneDesc scene;
    scene.source = root_.value().origin().source;
    if (film) read_settings(*film, "film.", scene.settings);
    scene.camera = read_camera(camera ? *camera : root_.required("camera"));
    if (integrator) read_settings(*integrator, "integrator.", scene.settings);
    if (spectrum) read_settings(*spectrum, "spectrum.", scene.settings);
    if (lights)
      for (const JsonValue& l : lights->array()) scene.lights.push_back(read_light(l));
    if (shapes) {
      // Every named shape is built, used or not, so that errors do not hide in unused ones.
      shapes_.emplace(*shapes);
      for (const auto& [name, value] : shapes_->entries()) named_shape(name, value);
    }
    if (media) {
      JsonObject table(*media);
      for (const auto& [name, value] : table.entries()) {
        media_index_[name] = static_cast<int>(scene.media.size());
        scene.media.push_back(read_medium(name, value));
      }
    }
    if (objects)
      for (const JsonValue& o : objects->array()) scene.objects.push_back(read_object(o));
    scene.inputs = std::move(inputs_);
    return scene;
  }

  // A document {"camera": CAMERA}: the camera, checked as a scene file's (load_camera_json).
  CameraDesc load_camera() {
    const JsonValue value = root_.required("camera");
    root_.finish();
    return read_camera(value);
  }

  // A document {"shape": SHAPE, "shapes": {NAME: SHAPE, ...}}: the shape, its names resolved in
  // the table (load_shape_json).
  ShapePtr load_shape() {
    const auto shapes = root_.optional("shapes");
    const JsonValue value = root_.required("shape");
    root_.finish();
    if (shapes) {
      shapes_.emplace(*shapes);
      for (const auto& [name, named] : shapes_->entries()) named_shape(name, named);
    }
    ShapePtr s = shape(value);
    if (count_quadrics(*s) > kMaxTapeQuadrics)
      value.fail(
          fmt::format("the shape holds more than {} quadrics (each use of a named shape counts)",
                      kMaxTapeQuadrics));
    return s;
  }

 private:
  static CameraDesc read_camera(const JsonValue& v) {
    JsonObject o(v);
    CameraDesc c;
    if (auto t = o.optional("type"))
      c.type = t->choice("camera type", {"perspective", "orthographic"}) == 0
                   ? CameraDesc::Type::Perspective
                   : CameraDesc::Type::Orthographic;
    c.from = o.required("from").vec3(kCoordinate);
    const JsonValue to = o.required("to");
    c.to = to.vec3(kCoordinate);
    const auto up = o.optional("up");
    if (up) c.up = up->direction();
    if (auto f = o.optional("fov")) c.fov = f->number(strictly_between(0, 180));
    if (auto w = o.optional("width")) c.width = w->number(above(0));
    o.finish();
    const Vec3 view = c.to - c.from;
    if (dot(view, view) == 0) to.fail(R"(must differ from "from")");
    // Parallel within about 1e-6 radians would give a camera frame made of round-off.
    if (length(cross(normalize(view), normalize(c.up))) < 1e-6) {
      if (up) up->fail("must not be parallel to the view direction");
      o.fail(R"(the view direction is parallel to the default up [0, 1, 0]; give "up")");
    }
    return c;
  }

  // The settings under `prefix` ("integrator.") in the section `v`, through their declarations
  // (render/settings.h), in the order declared; a subsection ("majorant") is an object.
  static void read_settings(const JsonValue& v, const std::string& prefix,
                            RenderSettings& settings) {
    JsonObject o(v);
    std::set<std::string, std::less<>> subsections;
    for (const Setting& s : render_settings()) {
      if (!s.key.starts_with(prefix)) continue;
      const std::string rest(s.key.substr(prefix.size()));
      if (const size_t dot = rest.find('.'); dot != std::string::npos) {
        const std::string sub = rest.substr(0, dot);
        if (subsections.insert(sub).second)
          if (auto x = o.optional(sub)) read_settings(*x, prefix + sub + ".", settings);
      } else if (auto x = o.optional(rest)) {
        read_setting(*x, s, settings);
      }
    }
    o.finish();
  }

  static void read_setting(const JsonValue& x, const Setting& s, RenderSettings& settings) {
    using Kind = SettingType::Kind;
    nlohmann::json value;
    switch (s.type.kind) {
      case Kind::Integer:
        value = x.integer(s.type.range);
        break;
      case Kind::Unsigned:
        value = x.unsigned_integer();
        break;
      case Kind::Number:
        value = x.number(s.type.range);
        break;
      case Kind::Boolean:
        value = x.boolean();
        break;
      case Kind::Choice:
        value = std::string(s.type.names[x.choice(s.type.noun, s.type.names)]);
        break;
      case Kind::ChoiceList:
        value = nlohmann::json::array();
        for (const JsonValue& e : x.array()) {
          const std::string name(s.type.names[e.choice(s.type.noun, s.type.names)]);
          if (std::find(value.begin(), value.end(), name) != value.end())
            e.fail(fmt::format("\"{}\" is listed twice", name));
          value.push_back(name);
        }
        break;
    }
    if (s.check)
      if (const std::string problem = s.check(value); !problem.empty()) x.fail(problem);
    s.set(settings, value);
  }

  static Light read_light(const JsonValue& v) {
    JsonObject o(v);
    const JsonValue type = o.required("type");
    std::vector<std::string_view> names;
    for (const LightType& t : light_types()) names.push_back(t.name);
    Light l;
    light_types()[type.choice("light type", names)].read(o, l);
    o.finish(fmt::format("for light type \"{}\"", type.string()));
    return l;
  }

  // A density's object, or a texture's: "type" (default "constant"), "scale" and the type's own
  // keys. `constant`: whether the type is "constant".
  static Deferred<DensityPtr> read_density(const JsonValue& v, double& scale, bool& constant) {
    JsonObject d(v);
    std::string type = "constant";
    if (auto t = d.optional("type")) type = string_choice(*t, "density type", density_type_names());
    if (auto s = d.optional("scale")) scale = s->number(at_least(0));
    Deferred<DensityPtr> made;
    for (const DensityType& t : density_types())
      if (t.name == type) made = t.read(d);
    constant = type == "constant";
    d.finish(fmt::format("for density type \"{}\"", type));
    return made;
  }

  static bool is_textured(const JsonValue& v) {
    return v.json().is_object() && v.json().contains("texture");
  }

  // {"texture": T, "from": a, "to": b}: T's pattern and scale; a and b are read by `value`.
  template <class T, class Read>
  static TextureDesc read_textured(const JsonValue& v, T& from, T& to, Read&& value) {
    JsonObject o(v);
    TextureDesc t;
    bool constant = false;
    t.make = read_density(o.required("texture"), t.scale, constant);
    from = value(o.required("from"));
    to = value(o.required("to"));
    o.finish(R"(for a textured value (expected "texture", "from" and "to"))");
    return t;
  }

  // A colour that a texture may drive.
  static TextureDesc read_textured_colour(const JsonValue& v, SpectralParam& from,
                                          SpectralParam& to, SpectralRole role,
                                          const Range& range) {
    auto colour = [&](const JsonValue& x) { return read_colour(x, role, range); };
    if (!is_textured(v)) {
      from = colour(v);
      return {};
    }
    return read_textured(v, from, to, colour);
  }

  // A roughness, GGX α in [0, 1], that a texture may drive; a textured one is > 0 at both ends.
  static TextureDesc read_roughness(const JsonValue& v, SurfaceDesc& s) {
    if (!is_textured(v)) {
      s.roughness = v.number(between(0, 1));
      return {};
    }
    return read_textured(v, s.roughness, s.roughness_to, [](const JsonValue& x) {
      const double a = x.number(between(0, 1));
      if (a == 0)
        x.fail(
            "a textured roughness must be > 0 (0 is the smooth boundary, which a texture cannot "
            "blend into)");
      return a;
    });
  }

  // The keys a rough dielectric and a conductor share: "roughness", "multiple_scattering".
  static void read_microfacet_keys(JsonObject& so, SurfaceDesc& s) {
    if (auto r = so.optional("roughness")) s.roughness_texture = read_roughness(*r, s);
    if (auto m = so.optional("multiple_scattering")) s.multiple_scattering = m->boolean();
  }

  static MediumDesc read_medium(const std::string& name, const JsonValue& v) {
    JsonObject o(v);
    MediumDesc m;
    m.name = name;
    if (auto x = o.optional("sigma_a"))
      m.sigma_a_texture =
          read_textured_colour(*x, m.sigma_a, m.sigma_a_to, SpectralRole::Unbounded, at_least(0));
    if (auto x = o.optional("sigma_s"))
      m.sigma_s_texture =
          read_textured_colour(*x, m.sigma_s, m.sigma_s_to, SpectralRole::Unbounded, at_least(0));
    if (auto x = o.optional("emission")) {
      if (is_emission_grid(*x))
        m.emission_grid = read_emission_grid(*x);
      else
        m.emission = read_colour(*x, SpectralRole::Illuminant, kEmission);
    }
    if (auto x = o.optional("emission_per_length")) {
      if (is_emission_grid(*x))
        m.j_grid = read_emission_grid(*x);
      else
        m.j = read_colour(*x, SpectralRole::Illuminant, kEmission);
    }
    if (auto x = o.optional("phase")) {
      JsonObject p(*x);
      std::string type = "isotropic";
      if (auto t = p.optional("type")) {
        type = string_choice(*t, "phase type", {"isotropic", "hg"});
        if (type == "hg") m.phase.type = PhaseDesc::Type::HenyeyGreenstein;
      }
      if (type == "hg")
        if (auto g = p.optional("g")) m.phase.g = g->number(strictly_between(-1, 1));
      p.finish(fmt::format("for phase type \"{}\"", type));
    }
    if (auto x = o.optional("density"))
      m.density = read_density(*x, m.density_scale, m.constant_density);
    o.finish();
    return m;
  }

  ObjectDesc read_object(const JsonValue& v) {
    JsonObject o(v);
    ObjectDesc obj;
    obj.json_path = v.pointer();
    const JsonValue shape_value = o.required("shape");
    obj.shape = shape(shape_value);
    obj.shape_name = shape_value.json().is_string() ? shape_value.string() : "inline";
    if (count_quadrics(*obj.shape) > kMaxTapeQuadrics)
      shape_value.fail(
          fmt::format("the shape holds more than {} quadrics (each use of a named shape counts)",
                      kMaxTapeQuadrics));
    if (auto instances = o.optional("instances")) obj.instances = read_instances(*instances);
    const auto medium = o.optional("medium");
    if (medium) {
      const auto it = media_index_.find(medium->string());
      if (it == media_index_.end())
        medium->fail(fmt::format("unknown medium \"{}\"", medium->string()));
      obj.medium = it->second;
    }
    // Without a surface, an object with a medium is an index-matched volume, any other one a
    // grey diffuse solid.
    obj.surface.type = medium ? SurfaceDesc::Type::None : SurfaceDesc::Type::Diffuse;
    std::optional<JsonValue> surface_type;
    if (auto s = o.optional("surface")) {
      JsonObject so(*s);
      if ((surface_type = so.optional("type")))
        obj.surface.type =
            static_cast<SurfaceDesc::Type>(surface_type->choice("surface type", kSurfaceTypes));
      switch (obj.surface.type) {
        case SurfaceDesc::Type::None:
          break;
        case SurfaceDesc::Type::Diffuse:
          if (auto a = so.optional("albedo"))
            obj.surface.albedo_texture = read_textured_colour(
                *a, obj.surface.albedo, obj.surface.albedo_to, SpectralRole::Albedo, between(0, 1));
          break;
        case SurfaceDesc::Type::Dielectric:
          if (auto i = so.optional("ior")) obj.surface.ior = i->number(at_least(1));
          read_microfacet_keys(so, obj.surface);
          break;
        case SurfaceDesc::Type::Conductor:
          if (auto m = so.optional("metal")) {
            const auto metal = metal_by_name(metal_names()[m->choice("metal", metal_names())]);
            for (const char* key : {"eta", "k"})
              if (auto v = so.optional(key))
                v->fail(R"(give either "metal" or "eta" and "k", not both)");
            obj.surface.eta = metal->eta;
            obj.surface.k = metal->k;
          } else {
            obj.surface.eta = read_colour(so.required("eta"), SpectralRole::Unbounded, above(0));
            obj.surface.k = read_colour(so.required("k"), SpectralRole::Unbounded, at_least(0));
          }
          read_microfacet_keys(so, obj.surface);
          break;
        case SurfaceDesc::Type::Emissive:
          obj.surface.radiance =
              read_colour(so.required("radiance"), SpectralRole::Illuminant, kEmission);
          break;
      }
      so.finish(fmt::format("for surface type \"{}\"",
                            kSurfaceTypes[static_cast<int>(obj.surface.type)]));
    }
    o.finish();
    if (obj.surface.type == SurfaceDesc::Type::None && !medium)
      surface_type->fail(R"(surface "none" needs a medium: the object would be invisible)");
    // A medium behind an opaque surface could never be reached by any ray.
    if (medium && obj.surface.type != SurfaceDesc::Type::None &&
        obj.surface.type != SurfaceDesc::Type::Dielectric)
      medium->fail(R"(only objects with surface "none" or "dielectric" can hold a medium)");
    return obj;
  }

  // An object's "instances": an array of transforms, or {"file": "x.npy"}, a side file of them
  // (scene/instances_file.h) relative to the scene file's folder. Each becomes a copy of the
  // object; every transform is checked as a shape's is.
  std::shared_ptr<const std::vector<Mat4>> read_instances(const JsonValue& v) {
    std::vector<Mat4> transforms;
    if (v.json().is_array()) {
      const std::vector<JsonValue> items = v.array();
      if (items.empty()) v.fail("must hold at least one transform");
      if (items.size() > kMaxInstances)
        v.fail(fmt::format("holds {} transforms; an object may have at most {}", items.size(),
                           kMaxInstances));
      transforms.reserve(items.size());
      for (const JsonValue& t : items) transforms.push_back(read_transform(t));
    } else if (v.json().is_object()) {
      JsonObject o(v);
      const JsonValue file = o.required("file");
      o.finish(R"(for instances from a file)");
      const std::string path = file.file();
      try {
        transforms = read_instances_file(path);
      } catch (const InstancesFileError& e) {
        file.fail(fmt::format("{}: {}", file.string(), e.what()));
      }
      for (std::size_t k = 0; k < transforms.size(); ++k)
        if (const std::string problem = transform_problem(transforms[k]); !problem.empty())
          file.fail(fmt::format("{}: instance {}: {}", file.string(), k, problem));
      inputs_.push_back(record_input_file(file.pointer(), path));
    } else {
      v.fail(R"(expected an array of transforms or {"file": "NAME.npy"})");
    }
    return std::make_shared<const std::vector<Mat4>>(std::move(transforms));
  }

  // A shape where one is expected: the name of a shape in "shapes", or an inline shape object.
  // Shapes nest through inline children, free-form bases and perturbations and named references
  // alike; beyond kMaxShapeDepth levels the loader and the compiler's recursion would exhaust the
  // stack (5 000 nested unions crashed it), so that is an error at the place it is exceeded.
  ShapePtr shape(const JsonValue& v) {
    struct Level {
      int& depth;
      explicit Level(int& d) : depth(++d) {}
      ~Level() { --depth; }
    } level(shape_depth_);
    if (shape_depth_ > kMaxShapeDepth)
      v.fail(
          fmt::format("shapes nest more than {} levels deep here (inline shapes, bases, "
                      "perturbations, children and named references together)",
                      kMaxShapeDepth));
    if (v.json().is_object()) return inline_shape(v);
    if (!v.json().is_string()) v.fail("expected a shape name or an inline shape object");
    const std::string name = v.string();
    if (!shapes_ || !shapes_->has(name)) v.fail(fmt::format("unknown shape \"{}\"", name));
    return named_shape(name, v);
  }

  // Builds a named shape once; `via` is the value that refers to it (or its own definition).
  ShapePtr named_shape(const std::string& name, const JsonValue& via) {
    if (const auto it = built_.find(name); it != built_.end()) return it->second;
    for (size_t i = 0; i < resolving_.size(); ++i) {
      if (resolving_[i].name != name) continue;
      std::string chain;
      for (size_t k = i; k < resolving_.size(); ++k) chain += resolving_[k].name + " -> ";
      // Reported at the reference that leaves the first shape of the cycle.
      const JsonValue& at = i + 1 < resolving_.size() ? resolving_[i + 1].via : via;
      at.fail("cycle in shape references: " + chain + name);
    }
    resolving_.push_back({name, via});
    // A definition may itself be just another shape's name: an alias.
    ShapePtr s = shape(*shapes_->optional(name));
    resolving_.pop_back();
    built_[name] = s;
    return s;
  }

  ShapePtr inline_shape(const JsonValue& v) {
    JsonObject o(v);
    const JsonValue type = o.required("type");
    const std::string kind = string_choice(
        type, "shape type",
        {"quadric", "sphere", "ellipsoid", "cylinder", "cone", "paraboloid", "halfspace", "slab",
         "box", "freeform", "union", "intersection", "difference"});
    const auto point = [&](const char* key) {
      const auto p = o.optional(key);
      return p ? p->vec3(kCoordinate) : Vec3{};
    };
    ShapePtr s;
    if (kind == "quadric") {
      const JsonValue c = o.required("coefficients");
      if (!c.json().is_array() || c.json().size() != 10) c.fail("expected an array of 10 numbers");
      Quadric q;
      bool all_zero = true;
      for (size_t i = 0; i < 10; ++i) {
        q.a[i] = c.array()[i].number();
        all_zero = all_zero && q.a[i] == 0;
      }
      if (all_zero) c.fail("must not all be zero");
      s = make_shape(QuadricNode{q});
    } else if (kind == "sphere") {
      const Vec3 center = point("center");
      s = make_shape(QuadricNode{sphere(center, o.required("radius").number(kLength))});
    } else if (kind == "ellipsoid") {
      const Vec3 center = point("center");
      s = make_shape(QuadricNode{ellipsoid(center, o.required("radii").vec3(kLength))});
    } else if (kind == "cylinder") {
      const Vec3 p = point("point");
      const Vec3 axis = o.required("axis").direction();
      s = make_shape(QuadricNode{cylinder(p, axis, o.required("radius").number(kLength))});
    } else if (kind == "cone") {
      const Vec3 apex = point("apex");
      const Vec3 axis = o.required("axis").direction();
      const double angle = o.required("half_angle").number(strictly_between(0, 90));
      s = make_shape(QuadricNode{cone(apex, axis, angle)});
    } else if (kind == "paraboloid") {
      const Vec3 vertex = point("vertex");
      const Vec3 axis = o.required("axis").direction();
      const double f = o.required("focal_length").number(kLength);
      s = make_shape(QuadricNode{paraboloid(vertex, axis, f)});
    } else if (kind == "halfspace") {
      const Vec3 p = point("point");
      s = make_shape(QuadricNode{halfspace(p, o.required("normal").direction())});
    } else if (kind == "slab") {
      const Vec3 center = point("center");
      const Vec3 normal = o.required("normal").direction();
      s = make_shape(QuadricNode{slab(center, normal, o.required("thickness").number(kLength))});
    } else if (kind == "box") {
      const Vec3 lo = o.required("min").vec3(kCoordinate);
      const JsonValue max_value = o.required("max");
      const Vec3 hi = max_value.vec3(kCoordinate);
      for (int i = 0; i < 3; ++i)
        if (!(hi[i] > lo[i]))
          max_value.array()[i].fail(fmt::format("must be greater than min ({})", lo[i]));
      s = box(lo, hi);
    } else if (kind == "freeform") {
      FreeFormNode node;
      node.base = shape(o.required("base"));
      if (auto ps = o.optional("perturbations")) {
        for (const JsonValue& pv : ps->array()) {
          JsonObject p(pv);
          Perturbation pert;
          pert.shape = shape(p.required("shape"));
          pert.weight =
              p.required("weight").number(between(-kMaxPerturbationWeight, kMaxPerturbationWeight));
          p.finish();
          node.perturbations.push_back(pert);
        }
      }
      s = make_shape(std::move(node));
    } else {
      CsgNode node;
      node.op = kind == "union"          ? CsgOp::Union
                : kind == "intersection" ? CsgOp::Intersection
                                         : CsgOp::Difference;
      const JsonValue children = o.required("shapes");
      const size_t min_children = node.op == CsgOp::Difference ? 2 : 1;
      const std::vector<JsonValue> list = children.array();
      if (list.size() < min_children)
        children.fail(
            fmt::format("expected at least {} shape{}", min_children, min_children > 1 ? "s" : ""));
      for (const JsonValue& c : list) node.children.push_back(shape(c));
      s = make_shape(std::move(node));
    }
    const auto transform = o.optional("transform");
    o.finish(fmt::format("for shape type \"{}\"", kind));
    return transform ? with_transform(s, read_transform(*transform)) : s;
  }

  struct Visit {
    std::string name;
    JsonValue via;
  };

  JsonObject root_;
  std::optional<JsonObject> shapes_;
  std::map<std::string, ShapePtr> built_;
  int shape_depth_ = 0;           // shapes being read, one inside the other
  std::vector<Visit> resolving_;  // named shapes being built, outermost first
  std::map<std::string, int> media_index_;
  std::vector<InputFile> inputs_;  // the instances files read
};

// load_scene_json, with the folder that relative file names in the document resolve against
// (a VDB density's "file"): the scene file's own, or "" (the current directory) for a document
// that is not a file.
SceneDesc load_json_in(nlohmann::json j, const std::string& source, const std::string& folder,
                       const std::vector<std::string>& overrides) {
  JsonOrigin origin{source, {}, folder};
  for (const std::string& o : overrides)
    origin.overrides.push_back({apply_override(j, o), set_flag(o)});
  SceneDesc scene = Loader(JsonValue(j, "", origin)).load();
  scene.document = std::move(j);
  return scene;
}

}  // namespace

ShapePtr load_shape_json(const nlohmann::json& shape, const nlohmann::json& shapes,
                         const std::string& source) {
  nlohmann::json document = {{"shape", shape}};
  if (!shapes.is_null()) document["shapes"] = shapes;
  const JsonOrigin origin{source, {}, ""};
  return Loader(JsonValue(document, "", origin)).load_shape();
}

CameraDesc load_camera_json(const nlohmann::json& camera, const std::string& source) {
  const nlohmann::json document = {{"camera", camera}};
  return Loader(JsonValue(document, "", JsonOrigin{source, {}, ""})).load_camera();
}

SceneDesc load_scene_json(nlohmann::json j, const std::string& source,
                          const std::vector<std::string>& overrides) {
  return load_json_in(std::move(j), source, "", overrides);
}

SceneDesc load_scene_text(const std::string& text, const std::string& source,
                          const std::vector<std::string>& overrides) {
  return load_json_in(parse_json_text(text, source), source, "", overrides);
}

SceneDesc load_scene_file(const std::string& path, const std::vector<std::string>& overrides) {
  return load_json_in(parse_json_file(path), path,
                      std::filesystem::path(path).parent_path().string(), overrides);
}

}  // namespace nimbus
