#include "lamina/core/error.hpp"

namespace lamina {

const char* error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::io_error: return "io_error";
    case ErrorCode::unknown_format: return "unknown_format";
    case ErrorCode::truncated_file: return "truncated_file";
    case ErrorCode::parse_error: return "parse_error";
    case ErrorCode::empty_mesh: return "empty_mesh";
    case ErrorCode::invalid_argument: return "invalid_argument";
    case ErrorCode::unsupported: return "unsupported";
    case ErrorCode::limit_exceeded: return "limit_exceeded";
    case ErrorCode::stock_exhausted: return "stock_exhausted";
  }
  return "unknown";
}

}  // namespace lamina
