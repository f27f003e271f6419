#include "nimbus/job/fingerprint.h"

#include <fmt/format.h>

#include "nimbus/math/fnv.h"
#include "nimbus/render/settings.h"

namespace nimbus {
namespace {

template <class T>
uint64_t hash_value(const T& v, uint64_t h) {
  return hash_bytes(std::as_bytes(std::span(&v, 1)), h);
}

uint64_t hash_octree(const MajorantOctree& t, uint64_t h) {
  for (const Vec3& v : {t.box.lo, t.box.hi})
    for (int i = 0; i < 3; ++i) h = hash_value(v[i], h);
  for (const Vec3& v : t.half)
    for (int i = 0; i < 3; ++i) h = hash_value(v[i], h);
  for (const OctreeNode& n : t.nodes) h = hash_value(n.empty, hash_value(n.children, h));
  h = hash_value(t.bins, hash_value(t.majorant_scale, hash_value(t.depth, h)));
  return hash_bytes(std::as_bytes(std::span(t.bounds)), h);
}

std::string short_dump(const nlohmann::json& j) {
  std::string s = j.is_null() ? "absent" : j.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

std::string difference(const nlohmann::json& a, const nlohmann::json& b, const std::string& key) {
  if (a.is_object() && b.is_object()) {
    for (const auto& [k, v] : a.items()) {
      const std::string sub = key.empty() ? k : key + "." + k;
      if (std::string d = difference(v, b.contains(k) ? b[k] : nlohmann::json(), sub); !d.empty())
        return d;
    }
    for (const auto& [k, v] : b.items())
      if (!a.contains(k)) return difference(nlohmann::json(), v, key.empty() ? k : key + "." + k);
    return {};
  }
  if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (size_t i = 0; i < a.size(); ++i)
      if (std::string d = difference(a[i], b[i], key + "." + std::to_string(i)); !d.empty())
        return d;
    return {};
  }
  if (a == b) return {};
  return fmt::format("{}: {} in the checkpoint, {} now", key, short_dump(a), short_dump(b));
}

// The files of two fingerprints ({pointer: {"file", "bytes", "hash"}}), compared by pointer.
std::string file_difference(const nlohmann::json& saved, const nlohmann::json& now) {
  const auto path = [](const nlohmann::json& f) {
    return f.is_object() && f.contains("file") && f["file"].is_string()
               ? f["file"].get<std::string>()
               : std::string("?");
  };
  for (const auto& [pointer, f] : now.items()) {
    if (!saved.contains(pointer))
      return fmt::format("{}, named at {}, was not read by the checkpoint's render", path(f),
                         pointer);
    if (saved[pointer] != f)
      return fmt::format(
          "{}, named at {}, is not the file the checkpoint's render read (its "
          "size or content differs)",
          path(f), pointer);
  }
  for (const auto& [pointer, f] : saved.items())
    if (!now.contains(pointer))
      return fmt::format("the checkpoint's render read {}, named at {}; this one does not", path(f),
                         pointer);
  return {};
}

}  // namespace

nlohmann::json render_fingerprint(const SceneDesc& desc, const std::vector<InputFile>& inputs) {
  nlohmann::json fingerprint = nlohmann::json::object();
  fingerprint["nimbus"] = NIMBUS_VERSION;
  nlohmann::json& scene = fingerprint["scene"] = desc.document;  // the one copy
  // The settings as the render uses them, every one spelt out, rather than as the document
  // gives them: a setting given at its default is the default (issue 44: --seed 0 was refused
  // against a checkpoint whose scene left the seed out).
  if (scene.is_object()) {
    const nlohmann::json settings = settings_json(desc.settings);
    for (const auto& [section, values] : settings.items()) scene[section] = values;
    scene["integrator"].erase("spp");
  }
  // Each file under the JSON pointer that named it, as compiling recorded it when it read it.
  nlohmann::json& files = fingerprint["files"] = nlohmann::json::object();
  for (const InputFile& f : inputs)
    files[f.pointer] = {
        {"file", f.path}, {"bytes", f.bytes}, {"hash", fmt::format("{:016x}", f.hash)}};
  return fingerprint;
}

nlohmann::json render_fingerprint(const nlohmann::json& identity) {
  return {{"nimbus", NIMBUS_VERSION}, {"scene", identity}, {"files", nlohmann::json::object()}};
}

std::string fingerprint_difference(const nlohmann::json& saved, const nlohmann::json& now) {
  const auto without_files = [](nlohmann::json j) {
    if (j.is_object()) j.erase("files");
    return j;
  };
  if (std::string d = difference(without_files(saved), without_files(now), ""); !d.empty())
    return d;
  const auto files = [](const nlohmann::json& j) {
    return j.is_object() && j.contains("files") && j["files"].is_object()
               ? j["files"]
               : nlohmann::json::object();
  };
  return file_difference(files(saved), files(now));
}

uint64_t majorant_hash(const Scene& scene) {
  uint64_t h = hash_octree(scene.field_octree, kFnvOffset);
  for (const MajorantOctree& t : scene.solid_octrees.trees) h = hash_octree(t, h);
  return h;
}

}  // namespace nimbus
