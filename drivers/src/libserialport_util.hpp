#pragma once
// Internal: small owners and error text for libserialport (its header stays in drivers/src).
#include <libserialport.h>

#include <memory>
#include <string>

namespace lamina::drivers::detail {

// The library's own words for the last failure: the OS message for SP_ERR_FAIL, a fixed text
// otherwise (sp_last_error_message is only meaningful after SP_ERR_FAIL).
std::string sp_error_text(sp_return result);

struct SpPortDeleter {
  void operator()(sp_port* port) const { sp_free_port(port); }
};
struct SpPortListDeleter {
  void operator()(sp_port** ports) const { sp_free_port_list(ports); }
};
struct SpConfigDeleter {
  void operator()(sp_port_config* config) const { sp_free_config(config); }
};
using SpPortPtr = std::unique_ptr<sp_port, SpPortDeleter>;
using SpPortListPtr = std::unique_ptr<sp_port*, SpPortListDeleter>;
using SpConfigPtr = std::unique_ptr<sp_port_config, SpConfigDeleter>;

// libserialport returns NULL for a string it does not know; we want "".
inline std::string sp_string(const char* text) { return text ? std::string(text) : std::string(); }

}  // namespace lamina::drivers::detail
