#pragma once
// The commands of the nimbus command line, one file each (render_command.cpp, ...): each adds
// its subcommand, options and help text to the CLI11 app, and says how to run it once parsed.
// main.cpp dispatches to the one given.

#include <CLI/CLI.hpp>
#include <functional>

#include "cluster.h"

// The exit codes besides 0 and 128 + a signal's number.
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

struct Command {
  CLI::App* cli = nullptr;                 // the subcommand, parsed() once given
  std::function<int(const Cluster&)> run;  // the command's exit code
  bool stoppable = false;      // catches SIGINT, SIGTERM and SIGHUP (stop_signals.h) first
  bool several_ranks = false;  // may run on several MPI ranks
};

// In the order `nimbus --help` lists them.
Command render_command(CLI::App& app);
Command view_command(CLI::App& app);
Command experiment_command(CLI::App& app);
Command settings_command(CLI::App& app);
Command export_vdb_command(CLI::App& app);
Command export_mesh_command(CLI::App& app);
