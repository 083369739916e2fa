#include "libserialport_util.hpp"

namespace lamina::drivers::detail {

std::string sp_error_text(sp_return result) {
  switch (result) {
    case SP_OK: return "ok";
    case SP_ERR_ARG: return "invalid argument";
    case SP_ERR_MEM: return "out of memory";
    case SP_ERR_SUPP: return "not supported by this system or device";
    case SP_ERR_FAIL: break;
  }
  char* message = sp_last_error_message();
  std::string text = message ? message : "system error";
  sp_free_error_message(message);
  return text;
}

}  // namespace lamina::drivers::detail
