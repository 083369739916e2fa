#pragma once
// Internal: open a port libserialport lists (real UARTs, USB adapters) by its device name.
#include <expected>
#include <memory>
#include <string>

#include "lamina/drivers/transport.hpp"

namespace lamina::drivers::detail {

// `label` goes into describe() after the name, e.g. "(usb serial A10K3B)"; empty for none.
std::expected<std::unique_ptr<Transport>, LinkError> open_libserialport(boost::asio::io_context& io,
                                                                        const std::string& device,
                                                                        const SerialSettings& settings,
                                                                        const std::string& label);

}  // namespace lamina::drivers::detail
