// JSON input files (scenes, POV tolerances, the golden manifest) parsed with
// errors as one "FILE:LINE: what" line, and duplicate keys refused.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace ra {

// Parses `text` (the contents of `file`). Throws InputError "FILE:LINE: ..."
// for invalid JSON (nlohmann's "[json.exception.parse_error.101] ..." prefix
// removed), a number that overflows a double (at the number itself, not at
// its first appearance elsewhere) and a key given twice in one object (which
// nlohmann would silently resolve to the last).
nlohmann::json parse_json_text(const std::string& text, const std::string& file);

// Reads and parses a file (check_input_file first).
nlohmann::json read_json_file(const std::string& file);

// "FILE: /a/b: expected a number" style text for a nlohmann type or range
// error met while reading an already parsed document, without the
// "[json.exception.type_error.302]" prefix.
std::string json_error_text(const std::exception& e);

}  // namespace ra
