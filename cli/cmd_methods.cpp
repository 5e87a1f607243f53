// `rayaudit methods [--json]`: the registry as a table or a JSON array.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "command.h"
#include "registry.h"

namespace {

void setup(CLI::App& app) {
  auto* cmd = app.add_subcommand("methods", "List the registered intersection methods");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print a JSON array instead of a table");
  cmd->callback([json] {
    if (*json) {
      nlohmann::json arr = nlohmann::json::array();
      for (const auto& m : ra::methods()) {
        arr.push_back({{"name", m.name},
                       {"kind", std::string(ra::kind_name(m.kind))},
                       {"source", m.source},
                       {"description", m.description},
                       {"precompute_bytes_float", m.precompute_bytes_float},
                       {"precompute_bytes_double", m.precompute_bytes_double},
                       {"wrong_on_purpose", m.wrong_on_purpose}});
      }
      std::cout << arr.dump(2) << "\n";
      return;
    }
    std::printf("%-18s %-8s %-9s %-46s %s\n", "NAME", "KIND", "PRE f/d", "SOURCE", "DESCRIPTION");
    for (const auto& m : ra::methods()) {
      char pre[32];
      std::snprintf(pre, sizeof pre, "%zu/%zu", m.precompute_bytes_float, m.precompute_bytes_double);
      std::printf("%-18s %-8s %-9s %-46s %s\n", m.name.c_str(), std::string(ra::kind_name(m.kind)).c_str(),
                  pre, m.source.c_str(), m.description.c_str());
    }
  });
}

ra::cli::Registrar reg(20, setup);

}  // namespace
