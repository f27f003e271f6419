#include "options.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "nimbus/io/display_server.h"
#include "nimbus/io/vdb_export.h"
#include "nimbus/render/setting_names.h"

CLI::Validator integer_in(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& value) -> std::string {
        long long x = 0;
        size_t used = 0;
        try {
          x = std::stoll(value, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != value.size())
          return fmt::format("must be a whole number, not \"{}\"", value);
        if (x < lo) return fmt::format("must be >= {}, not {}", lo, x);
        if (x > hi) return fmt::format("must be <= {}, not {}", hi, x);
        return {};
      },
      fmt::format("INT >= {}", lo));
}

CLI::Validator unsigned_64() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        const bool digits = !value.empty() && value.size() <= 20 &&
                            value.find_first_not_of("0123456789") == std::string::npos;
        if (!digits) return fmt::format("must be a whole number, not \"{}\"", value);
        try {
          std::stoull(value);
        } catch (const std::out_of_range&) {
          return fmt::format("must be <= {}, not {}", std::numeric_limits<uint64_t>::max(), value);
        }
        return {};
      },
      "UINT64");
}

CLI::Validator voxel_size() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        // strtod, not stod: a number past a double's range (1e999, 1e-400) is out of range
        // rather than "not a number".
        char* end = nullptr;
        const double x = std::strtod(value.c_str(), &end);
        if (value.empty() || end != value.c_str() + value.size())
          return fmt::format("must be a number, not \"{}\"", value);
        if (nimbus::vdb_voxel_size_problem(x).empty()) return {};
        return fmt::format("must be in [{:g}, {:g}], not {}", nimbus::kVdbExportMinVoxelSize,
                           nimbus::kVdbExportMaxVoxelSize, value);
      },
      "H");
}

CLI::Validator display_address() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        try {
          nimbus::parse_display_address(value);
        } catch (const std::invalid_argument& e) {
          return e.what();
        }
        return {};
      },
      "HOST:PORT");
}

CLI::Validator aov_names() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        std::vector<std::string> known, seen;
        for (const auto& entry : nimbus::kAovNames) known.emplace_back(entry.first);
        for (const std::string& name : comma_separated(value)) {
          if (std::find(known.begin(), known.end(), name) == known.end())
            return fmt::format("unknown AOV \"{}\" (one of: {})", name, fmt::join(known, ", "));
          if (std::find(seen.begin(), seen.end(), name) != seen.end())
            return fmt::format("names \"{}\" twice", name);
          seen.push_back(name);
        }
        return {};
      },
      "albedo,normal,depth,variance");
}

CLI::Validator positive_seconds() {
  return positive_number("SECONDS");
}

CLI::Validator positive_number(const std::string& name) {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        double x = 0;
        size_t used = 0;
        try {
          x = std::stod(value, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != value.size())
          return fmt::format("must be a number, not \"{}\"", value);
        if (!(x > 0) || !std::isfinite(x)) return fmt::format("must be > 0, not {}", value);
        return {};
      },
      name + " > 0");
}

std::vector<std::string> comma_separated(const std::string& list) {
  std::vector<std::string> items;
  for (size_t start = 0, comma = 0; comma != std::string::npos; start = comma + 1) {
    comma = list.find(',', start);
    items.push_back(list.substr(start, comma - start));
  }
  return items;
}
