// JSON input files (scenes, POV tolerances, the golden manifest) parsed with
// errors as one "FILE:LINE: what" line, and duplicate keys refused.
#pragma once
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace ra {

// The line of each value of a parsed document, by JSON pointer ("/goldens/0/
// settings/spp"): an object member's is its key's line, an array element's
// the line where it starts. For messages about values that parse but are
// wrong, which should name their line like a syntax error does.
struct JsonLines : std::map<std::string, long> {
  // The line of `pointer`, or of its nearest recorded parent; 0 if none.
  long at(const std::string& pointer) const;
};

// Parses `text` (the contents of `file`). Throws InputError "FILE:LINE: ..."
// for invalid JSON (nlohmann's "[json.exception.parse_error.101] ..." prefix
// removed), a number that overflows a double (at the number itself, not at
// its first appearance elsewhere) and a key given twice in one object (which
// nlohmann would silently resolve to the last).
nlohmann::json parse_json_text(const std::string& text, const std::string& file, JsonLines* lines = nullptr);

// Reads and parses a file (check_input_file first).
nlohmann::json read_json_file(const std::string& file, JsonLines* lines = nullptr);

// "FILE: /a/b: expected a number" style text for a nlohmann type or range
// error met while reading an already parsed document, without the
// "[json.exception.type_error.302]" prefix.
std::string json_error_text(const std::exception& e);

// Google Benchmark writes NaN and Infinity (e.g. the cv of a constant
// counter), which JSON lacks: outside strings they become null, keeping
// lines (so errors still name the right one).
std::string gbench_non_finite_to_null(const std::string& text);

}  // namespace ra
