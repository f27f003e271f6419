// The nimbus command line: `nimbus render SCENE ...`, `nimbus view SCENE`, `nimbus experiment
// NAME --out DIR`, `nimbus settings` and `nimbus export-vdb SCENE -o OUT.vdb --voxel-size H`,
// one file each (command.h). Here: parse, pick the command, run it, and turn what escapes it
// into one line and an exit code.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "cluster.h"
#include "command.h"
#include "nimbus/scene/json_reader.h"
#include "progress.h"
#include "stop_signals.h"

namespace {

int run_command(int argc, char** argv, const Cluster& cluster) {
  CLI::App app{"nimbus: renders functionally specified objects and participating media"};
  app.set_version_flag("--version", std::string("nimbus ") + NIMBUS_VERSION);
  app.require_subcommand(1);
  const std::vector<Command> commands = {render_command(app),     view_command(app),
                                         experiment_command(app), settings_command(app),
                                         export_vdb_command(app), export_mesh_command(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Under mpirun every rank parses the same command line: rank 0 alone says what is wrong.
    if (cluster.rank != 0) return e.get_exit_code() == 0 ? 0 : kExitBadInput;
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // One line (issue 29: CLI11 adds a second, "Run with --help for more information.").
    std::fprintf(stderr, "nimbus: %s\n", nimbus::printable_line(e.what()).c_str());
    return kExitBadInput;
  }
  // require_subcommand(1): exactly one was given.
  const Command& command = *std::find_if(commands.begin(), commands.end(),
                                         [](const Command& c) { return c.cli->parsed(); });
  try {
    if (cluster.size > 1 && !command.several_ranks) {
      if (cluster.rank == 0)
        std::fprintf(stderr, "nimbus: only render runs on several MPI ranks (docs/cli.md)\n");
      return kExitBadInput;
    }
    if (command.stoppable) catch_stop_signals();
    return command.run(cluster);
  } catch (const std::bad_alloc&) {
    // Past the estimate (render/memory_estimate.h), e.g. a --max-memory above what the machine
    // has (issue 29: "nimbus: std::bad_alloc").
    end_bar_line();
    std::fprintf(stderr,
                 "nimbus: out of memory: the machine could not give what the run needed "
                 "(does --max-memory allow more than it has?)\n");
    if (cluster.size > 1) cluster_abort(kExitFailure);
    return kExitFailure;
  } catch (const std::exception& e) {
    end_bar_line();  // an error from the render thread may come while its bar is drawn
    std::fprintf(stderr, "nimbus: %s\n", nimbus::printable_line(e.what()).c_str());
    // The other ranks may be waiting for this one: end them all.
    if (cluster.size > 1) cluster_abort(kExitFailure);
    return kExitFailure;
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Cluster cluster = cluster_start(&argc, &argv);
  const int code = run_command(argc, argv, cluster);
  cluster_end();
  return code;
}
