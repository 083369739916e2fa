#pragma once
// Errors returned by core stages. Codes are stable: tools and the daemon match on them,
// so never renumber; only append.
#include <cstdint>
#include <string>
#include <utility>

namespace lamina {

enum class ErrorCode : std::uint16_t {
  io_error = 1,          // file cannot be opened or read
  unknown_format = 2,    // not STL, OBJ or 3MF
  truncated_file = 3,    // file ends before its declared content
  parse_error = 4,       // malformed text (ASCII STL, OBJ) with line number
  empty_mesh = 5,        // no usable facet
  invalid_argument = 6,  // a parameter outside its domain
  unsupported = 7,       // a valid file using a feature we do not read
  limit_exceeded = 8,    // a file asking for more than a read limit allows (MeshReadOptions)
  stock_exhausted = 9,   // the rack's sheets (counts, sizes) cannot make the plan
};

// Stable lower-case name of a code, e.g. "truncated_file".
const char* error_code_name(ErrorCode code);

struct Error {
  ErrorCode code;
  std::string message;  // says what is wrong and where (file, line, byte offset, facet)
};

// A parameter outside its domain, said in `message`.
inline Error invalid_argument(std::string message) { return {ErrorCode::invalid_argument, std::move(message)}; }

}  // namespace lamina
