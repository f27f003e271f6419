// `nimbus export-mesh SCENE -o OUT.{ply,obj,stl,glb} --error E`: the scene's objects as a triangle
// mesh to an error bound (mesh/polygonize.h, io/mesh_file.h).

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "command.h"
#include "nimbus/io/mesh_file.h"
#include "nimbus/io/output.h"
#include "nimbus/mesh/polygonize.h"
#include "nimbus/render/memory_estimate.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "options.h"

namespace {

struct MeshArgs {
  std::string scene;
  std::string output;
  double error = 0;
  int object = -1;  // -1: every object
  bool all = false;
  int threads = 0;                        // 0: all cores
  std::optional<std::string> max_memory;  // none: the system's available memory
  std::vector<std::string> sets;
  bool quiet = false;
};

int run_export_mesh(const MeshArgs& args) {
  using namespace nimbus;
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t budget = 0;
  try {
    try {
      budget = args.max_memory ? parse_memory_size(*args.max_memory) : available_memory();
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(fmt::format("--max-memory: {}", e.what()));
    }
    check_writable_path(args.output);
    if (!mesh_format(args.output))
      throw std::runtime_error(args.output +
                               ": unknown mesh format (use .ply, .obj, .stl or .glb)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  Scene scene;
  try {
    SceneDesc desc = load_scene_file(args.scene, args.sets);
    if (args.object >= int(desc.objects.size()))
      throw std::invalid_argument(
          fmt::format("--object {}: the scene has {} objects", args.object, desc.objects.size()));
    // Meshing needs the objects' functions, not the renderer's majorants.
    desc.settings.tracking.octree_depth = 0;
    desc.settings.tracking.majorant_source = TrackingSettings::MajorantSource::Bound;
    std::vector<InputFile> read;
    scene = compile_scene(desc, {}, &read);
    check_outputs_distinct({{"-o", args.output}}, scene_inputs(args.scene, read));
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  // Every copy of the chosen objects, placed (their tapes are in the scene's space). The mesh is
  // the same for any number of threads.
  std::optional<tbb::global_control> threads;
  if (args.threads > 0)
    threads.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(args.threads));
  TriangleMesh mesh;
  PolygonizeOptions options;
  options.error = args.error;
  double vertex_error = 0, face_error = 0;
  int meshed = 0;
  for (const SceneObject& obj : scene.objects) {
    if (args.object >= 0 && obj.source != args.object) continue;
    // The memory budget is the whole run's: each object gets what the meshes before it left.
    const std::uint64_t used = mesh.positions.size() * 2 * sizeof(Vec3) +
                               mesh.triangles.size() * sizeof(mesh.triangles[0]);
    options.max_cells =
        std::max<std::uint64_t>(1, (budget - std::min(budget, used)) / kPolygonizeBytesPerCell);
    PolygonizeReport report;
    try {
      append(mesh, polygonize(obj.tape, options, &report));
    } catch (const PolygonizeError& e) {
      std::fprintf(stderr, "nimbus: %s: /objects/%d: %s\n", args.scene.c_str(), obj.source,
                   e.what());
      return kExitBadInput;
    }
    vertex_error = std::max(vertex_error, report.vertex_error);
    face_error = std::max(face_error, report.face_error);
    ++meshed;
  }
  if (meshed == 0) {
    std::fprintf(stderr, "nimbus: %s: no object to mesh (every shape is empty)\n",
                 args.scene.c_str());
    return kExitBadInput;
  }
  try {
    write_mesh(args.output, mesh);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitFailure;
  }
  if (!args.quiet)
    std::fprintf(
        stderr,
        "nimbus: %d object(s), %zu triangles, %zu vertices; largest vertex error %.3g, face "
        "error %.3g (bound %g) in %.3f s -> %s\n",
        meshed, mesh.triangles.size(), mesh.positions.size(), vertex_error, face_error, args.error,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
        args.output.c_str());
  return 0;
}

}  // namespace

Command export_mesh_command(CLI::App& app) {
  const auto args = std::make_shared<MeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export-mesh",
      "Write the scene's objects as a triangle mesh to an error bound (docs/cli.md)");
  cmd->add_option("scene", args->scene, "Scene file (JSON)")->required();
  cmd->add_option("-o,--output", args->output,
                  "Output file (.ply, .obj, .stl or .glb: glTF 2.0 binary)")
      ->required();
  cmd->add_option("--error", args->error,
                  "Error bound E > 0 in scene units: every vertex within E of the surface, every "
                  "face's sample points within E")
      ->required()
      ->check(positive_number("E"));
  auto* object = cmd->add_option("--object", args->object,
                                 "Index into the scene's objects (its instances included)")
                     ->check(integer_in(0));
  cmd->add_flag("--all", args->all, "Every object (the default)")->excludes(object);
  cmd->add_option("--max-memory", args->max_memory,
                  "Refuse error bounds whose meshing is estimated to need more memory than this "
                  "(e.g. 8G, 512M; default: the system's available memory)");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(integer_in(1));
  cmd->add_option("--set", args->sets, "Override a scene key, as for render; repeatable");
  cmd->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  return {cmd, [args](const Cluster&) { return run_export_mesh(*args); }};
}
