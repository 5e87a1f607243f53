// What `rayaudit audit` does after its table when asked to gate or report
// to CI: the failure lines (case ids, replay command, hints), the
// comparison with --baseline, and the --junit file. Shared by the plain
// audit, --grade and `audit diff`, so all three say the same in the same
// words, in a terminal and in a CI system's JUnit view.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "baseline.h"

namespace ra::baseline {

struct GateOptions {
  std::string baseline_name;  // how the baseline is named in messages (its path)
  std::string junit;          // write JUnit XML here (empty: none)
  std::string suite = "rayaudit audit";
  bool failure_lines = true;  // print each failing family's ids and replay command
};

struct GateResult {
  bool rose = false;    // a figure rose against the baseline: the caller exits 1
  std::string printed;  // what was printed (also in the JUnit bodies)
};

// Reads a baseline or diff input: ra::InputError "FILE:LINE: ..." on bad JSON.
nlohmann::json read_audit_json(const std::string& path);

// Compares `audit` with `baseline` when given (Mismatch becomes ra::InputError
// naming baseline_name), prints to stdout, writes the JUnit file (through
// write_text_atomically, so an OutputBatch that declared it commits it).
GateResult gate(const nlohmann::json& audit, const std::optional<nlohmann::json>& baseline, const GateOptions& o);

}  // namespace ra::baseline
