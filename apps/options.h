#pragma once
// The checks of the commands' options that say their problem in words (CLI11's own range checks
// print the double bounds of the option's type): a failed one is a usage error, exit 2, before
// the scene is read.

#include <CLI/CLI.hpp>
#include <limits>
#include <string>
#include <vector>

// An integer option in [lo, hi]: "--spp must be >= 1, not 0".
CLI::Validator integer_in(long long lo, long long hi = std::numeric_limits<int>::max());
// A whole number in [0, 2^64 - 1], the range of the scene file's integrator.seed (issue 29: the
// command line stopped at 2^63 - 1).
CLI::Validator unsigned_64();
// export-vdb's voxel size, in the range that OpenVDB and a reader of the file accept
// (io/vdb_export.h).
CLI::Validator voxel_size();
// --display-server's HOST:PORT (io/display_server.h): an empty address, a missing port or an
// IPv6 address outside brackets is refused.
CLI::Validator display_address();
// --aov's list, "albedo,normal": names of AOVs (render/setting_names.h), none twice.
CLI::Validator aov_names();
// A number of seconds > 0.
CLI::Validator positive_seconds();
// A finite number > 0, shown in help as "NAME > 0".
CLI::Validator positive_number(const std::string& name);

// The items of "albedo,normal", empty ones included.
std::vector<std::string> comma_separated(const std::string& list);
