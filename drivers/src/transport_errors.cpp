// to_link_error(): one reading of a handler's error code for every transport, so the streamer
// does not need to know Asio's categories (EOF lives in asio's "misc" category).
#include <fmt/core.h>

#include "lamina/drivers/transport.hpp"

namespace lamina::drivers {

LinkError to_link_error(std::error_code ec, const std::string& where) {
  if (ec == std::errc::operation_canceled)
    return LinkError{LinkErrorCode::cancelled, fmt::format("{}: closed", where)};
  return LinkError{LinkErrorCode::io_error, fmt::format("{}: link lost: {}", where, ec.message())};
}

}  // namespace lamina::drivers
