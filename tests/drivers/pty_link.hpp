#pragma once
// A grbl character-counting link to lamina-sim's PTY, paced as its line: `baud` 8N1 (115200: 11520 bytes/s).
#include <memory>
#include <string>

#include "lamina/drivers/streamer.hpp"

namespace lamina::drivers::testing {

inline std::unique_ptr<Streamer> grbl_pty_link(const std::string& path, double baud = 115200) {
  StreamerSettings settings;
  settings.pace_bytes_per_s = baud / 10;
  return std::make_unique<Streamer>(
      [path](boost::asio::io_context& io) { return open_serial(io, path, SerialSettings{}); }, make_grbl_protocol(),
      settings);
}

}  // namespace lamina::drivers::testing
