// Input path checks shared by every reader (a directory given as a
// scene read "no such file", a FIFO as texture or CSV blocked forever).
#include "input_file.h"

#include <system_error>

#include "../errors.h"
#include "file_identity.h"

namespace ra {

std::string input_file_problem(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) return "no such file";
  if (ec) return "cannot read: " + ec.message();
  switch (st.type()) {
    case fs::file_type::regular:
      return "";
    case fs::file_type::directory:
      return "is a directory, not a file";
    case fs::file_type::fifo:
      return "is a FIFO, not a file";
    case fs::file_type::socket:
      return "is a socket, not a file";
    case fs::file_type::block:
    case fs::file_type::character:
      return "is a device, not a file";
    default:
      return "is not a regular file";
  }
}

void check_input_file(const std::filesystem::path& path) {
  const std::string why = input_file_problem(path);
  if (!why.empty()) throw InputError(located(path.string(), 0, why));
  note_input(path);  // an output naming this file is refused
}

}  // namespace ra
