// list_serial_ports(): libserialport's enumeration, with the USB identity that lets a cell name
// its adapter by serial number instead of by a /dev/ttyUSB* that renumbers on replug.
#include <fmt/core.h>

#include "libserialport_util.hpp"
#include "lamina/drivers/transport.hpp"

namespace lamina::drivers {

namespace {

const char* transport_text(sp_transport transport) {
  switch (transport) {
    case SP_TRANSPORT_NATIVE: return "native";
    case SP_TRANSPORT_USB: return "usb";
    case SP_TRANSPORT_BLUETOOTH: return "bluetooth";
  }
  return "unknown";
}

PortInfo describe_port(const sp_port* port) {
  PortInfo info;
  info.name = detail::sp_string(sp_get_port_name(port));
  info.description = detail::sp_string(sp_get_port_description(port));
  const sp_transport transport = sp_get_port_transport(port);
  info.transport = transport_text(transport);
  if (transport == SP_TRANSPORT_USB) {
    int vid = 0, pid = 0;
    // Missing ids are not an error of the listing: some adapters do not report them.
    if (sp_get_port_usb_vid_pid(port, &vid, &pid) == SP_OK) {
      info.usb_vid = vid;
      info.usb_pid = pid;
    }
    info.usb_serial = detail::sp_string(sp_get_port_usb_serial(port));
    info.manufacturer = detail::sp_string(sp_get_port_usb_manufacturer(port));
    info.product = detail::sp_string(sp_get_port_usb_product(port));
  }
  return info;
}

}  // namespace

std::expected<std::vector<PortInfo>, LinkError> list_serial_ports() {
  sp_port** raw = nullptr;
  const sp_return result = sp_list_ports(&raw);
  detail::SpPortListPtr ports(raw);
  if (result != SP_OK) {
    // SP_ERR_SUPP: this platform cannot enumerate, so no port can be found by its identity.
    const LinkErrorCode code = result == SP_ERR_SUPP ? LinkErrorCode::port_not_found : LinkErrorCode::io_error;
    return std::unexpected(LinkError{code, fmt::format("cannot list serial ports: {}", detail::sp_error_text(result))});
  }
  std::vector<PortInfo> out;
  for (sp_port** p = ports.get(); p && *p; ++p) out.push_back(describe_port(*p));
  return out;
}

}  // namespace lamina::drivers
