#include "nimbus/job/fingerprint.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>

#include "nimbus/scene/json_reader.h"
#include "nimbus/scene/load.h"

namespace nimbus {

uint64_t hash_bytes(std::span<const std::byte> bytes, uint64_t h) {
  for (std::byte b : bytes) h = (h ^ uint64_t(b)) * 0x100000001b3ull;
  return h;
}

namespace {

template <class T>
uint64_t hash_value(const T& v, uint64_t h) {
  return hash_bytes(std::as_bytes(std::span(&v, 1)), h);
}

uint64_t hash_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path.string() + ": cannot open file");
  uint64_t h = 0xcbf29ce484222325ull;
  std::vector<char> buffer(1 << 16);
  while (in.read(buffer.data(), std::streamsize(buffer.size())) || in.gcount() > 0)
    h = hash_bytes(std::as_bytes(std::span(buffer.data(), size_t(in.gcount()))), h);
  return h;
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

}  // namespace

nlohmann::json render_fingerprint(const std::string& scene_path,
                                  const std::vector<std::string>& overrides,
                                  const std::vector<InputFile>& inputs) {
  std::ifstream in(scene_path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  nlohmann::json scene = nlohmann::json::parse(text, nullptr, true, true);
  for (const std::string& o : overrides) apply_override(scene, o);
  if (scene.contains("integrator") && scene["integrator"].is_object())
    scene["integrator"].erase("spp");
  // Each file under the JSON pointer that named it, as the loader recorded it.
  nlohmann::json files = nlohmann::json::object();
  for (const InputFile& f : inputs) files[f.pointer] = fmt::format("{:016x}", hash_file(f.path));
  return {{"nimbus", NIMBUS_VERSION}, {"scene", scene}, {"files", files}};
}

std::string fingerprint_difference(const nlohmann::json& saved, const nlohmann::json& now) {
  return difference(saved, now, "");
}

uint64_t majorant_hash(const Scene& scene) {
  uint64_t h = hash_octree(scene.field_octree, 0xcbf29ce484222325ull);
  for (const MajorantOctree& t : scene.solid_octrees) h = hash_octree(t, h);
  return h;
}

}  // namespace nimbus
