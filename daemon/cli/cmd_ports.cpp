// lamina ports: the serial ports libserialport sees, with their USB identity (open a cell's
// controller by its USB serial number so a renumbered /dev/ttyUSB* does not break it).
#include <fmt/format.h>

#include "commands.hpp"
#include "lamina/drivers/transport.hpp"

namespace lamina::cli {

void add_ports_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("ports", "list serial ports (name, USB VID:PID, serial number, description)");
  cmd->callback([&exit_code] {
    const auto ports = drivers::list_serial_ports();
    if (!ports) {
      fmt::print(stderr, "lamina ports: {}\n", ports.error().message);
      exit_code = 1;
      return;
    }
    if (ports->empty()) {
      fmt::print("no serial ports found (a PTY such as lamina-sim's link is not listed: open it by path)\n");
      return;
    }
    fmt::print("{:<20} {:<10} {:<20} {}\n", "port", "usb", "serial", "description");
    for (const auto& p : *ports) {
      const std::string usb = p.usb_vid && p.usb_pid ? fmt::format("{:04x}:{:04x}", *p.usb_vid, *p.usb_pid) : "-";
      fmt::print("{:<20} {:<10} {:<20} {}\n", p.name, usb, p.usb_serial.empty() ? "-" : p.usb_serial, p.description);
    }
  });
}

}  // namespace lamina::cli
