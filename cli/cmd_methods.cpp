// `rayaudit methods [--json]`: the registry as a table or a JSON array.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "command.h"
#include "peers/peers.h"
#include "registry.h"
#include "tracers/tracers.h"

namespace {

// Pads to `width` display columns: counts UTF-8 code points, not bytes, so
// that sources such as "seeds/000 §2.1" keep the table aligned.
std::string pad(const std::string& s, std::size_t width) {
  std::size_t cols = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++cols;
  return s + std::string(cols < width ? width - cols : 1, ' ');
}

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
      std::printf("%-18s %-8s %-9s %s%s\n", m.name.c_str(), std::string(ra::kind_name(m.kind)).c_str(), pre,
                  pad(m.source, 47).c_str(), m.description.c_str());
    }
    // Not registry methods (the JSON lists only those), but names the audit
    // takes too: peers in --methods, whole tracers in --tracers.
    std::printf("\nPEERS (audit --methods NAME; graded on the same cases)\n");
    for (const auto& p : ra::peers::peers())
      std::printf("%-18s %-8s %s%s\n", p.name.c_str(), ra::audit::precision_name(p.precision), p.info.what.c_str(),
                  p.missing.empty() ? "" : (" [not in this build: " + p.missing + "]").c_str());
    std::printf("\nTRACERS (audit --tracers NAMES; whole tracers on closed meshes)\n%s\n",
                ra::tracers::known_names().c_str());
  });
}

ra::cli::Registrar reg(20, setup);

}  // namespace
