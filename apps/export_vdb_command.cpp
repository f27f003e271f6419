// `nimbus export-vdb SCENE -o OUT.vdb --voxel-size H`: one object's medium as an OpenVDB fog
// volume (io/vdb_export.h).

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "command.h"
#include "nimbus/io/output.h"
#include "nimbus/io/vdb_export.h"
#include "nimbus/scene/compile.h"
#include "nimbus/scene/load.h"
#include "options.h"
#include "progress.h"
#include "stop_signals.h"

namespace {

struct ExportArgs {
  std::string scene;
  std::string output;
  double voxel_size = 0;
  int object = -1;  // -1: the first object that holds a medium
  std::vector<std::string> sets;
  bool quiet = false;
};

// `nimbus export-vdb`: one object's medium as an OpenVDB fog volume (io/vdb_export.h). Bad input
// (the scene, the object, the voxel size, the output path) is exit 2 with one line and nothing
// written; a signal stops the build as it stops a render.
int run_export_vdb(const ExportArgs& args) {
  using namespace nimbus;
  try {
    check_writable_path(args.output);
    std::string ext = std::filesystem::path(args.output).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (ext != ".vdb") throw std::runtime_error(args.output + ": unknown volume format (use .vdb)");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  Scene scene;
  int object = -1;
  try {
    SceneDesc desc = load_scene_file(args.scene, args.sets);
    object = vdb_export_object(desc, args.object);
    // The export needs the objects' functions and media, not the renderer's majorants.
    desc.settings.tracking.octree_depth = 0;
    desc.settings.tracking.majorant_source = TrackingSettings::MajorantSource::Bound;
    std::vector<InputFile> read;
    scene = compile_scene(desc, {}, &read);
    object = vdb_export_compiled(scene, object);
    try {
      check_outputs_distinct({{"-o", args.output}}, scene_inputs(args.scene, read));
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "nimbus: %s\n", e.what());
      return kExitBadInput;
    }
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  const bool show_progress = !args.quiet && isatty(fileno(stderr));
  const auto start = std::chrono::steady_clock::now();
  BuildMonitor monitor;
  monitor.cancel = [] { return stop_signal() != 0; };
  // The fraction 1 comes once the grid is built, before it is written: from then on a signal
  // removes the temporary file and ends the process (catch_stop_signals).
  monitor.progress = [&](double f) {
    if (f >= 1) set_writing(true);
    if (show_progress)
      print_progress(
          "export", f,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  };
  VdbExportResult result;
  try {
    result = export_vdb(scene, object, args.voxel_size, args.output, monitor);
  } catch (const std::invalid_argument& e) {
    end_bar_line();
    std::fprintf(stderr, "nimbus: %s\n", e.what());
    return kExitBadInput;
  }
  set_writing(false);
  end_bar_line();
  if (result.cancelled) {
    const int sig = stop_signal();
    std::fprintf(stderr, "nimbus: stopped by %s while building the grid; nothing written\n",
                 signal_name(sig));
    return 128 + sig;
  }
  if (!args.quiet)
    std::fprintf(stderr,
                 "nimbus: object %d: %llu active voxels of size %g, largest density %.4g, in %.2f "
                 "s -> %s\n",
                 object, static_cast<unsigned long long>(result.active_voxels), args.voxel_size,
                 result.max_density,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                 args.output.c_str());
  return 0;
}

}  // namespace

Command export_vdb_command(CLI::App& app) {
  const auto args = std::make_shared<ExportArgs>();
  CLI::App* export_vdb = app.add_subcommand(
      "export-vdb", "Write an object's medium as an OpenVDB fog volume (docs/cli.md)");
  export_vdb->add_option("scene", args->scene, "Scene file (JSON)")->required();
  export_vdb->add_option("-o,--output", args->output, "Output file (.vdb)")->required();
  export_vdb
      ->add_option("--voxel-size", args->voxel_size,
                   fmt::format("Voxel size H in world units, in [{:g}, {:g}]",
                               nimbus::kVdbExportMinVoxelSize, nimbus::kVdbExportMaxVoxelSize))
      ->required()
      ->check(voxel_size());
  export_vdb
      ->add_option("--object", args->object,
                   "Index into the scene's objects (default: the first with a medium)")
      ->check(integer_in(0));
  export_vdb->add_option("--set", args->sets, "Override a scene key, as for render; repeatable");
  export_vdb->add_flag("-q,--quiet", args->quiet, "Print nothing but errors");
  return {export_vdb, [args](const Cluster&) { return run_export_vdb(*args); },
          /*stoppable=*/true};
}
