// HOST:PORT as the daemon's config and `lamina stream --modbus/--tcp` take it.
#include <gtest/gtest.h>

#include "lamina/drivers/modbus_endpoint.hpp"

namespace lamina::drivers {
namespace {

TEST(HostPort, NamesIpv4AndBracketedIpv6AreSplit) {
  using HP = std::pair<std::string, int>;
  EXPECT_EQ(parse_host_port("127.0.0.1:502"), (HP{"127.0.0.1", 502}));
  EXPECT_EQ(parse_host_port("plc-cell1:1502"), (HP{"plc-cell1", 1502}));
  EXPECT_EQ(parse_host_port("[::1]:502"), (HP{"::1", 502}));
  EXPECT_EQ(parse_host_port("[fd00::7]:65535"), (HP{"fd00::7", 65535}));
  EXPECT_EQ(parse_host_port("h:1"), (HP{"h", 1}));
}

TEST(HostPort, MalformedTextIsRefused) {
  for (const char* bad : {"plc", "plc:", ":502", "plc:0", "plc:65536", "plc:5o2", "plc:-1", "plc:123456", "::1:502",
                          "[::1]", "[]:502", "my plc:502", "plc/1:502", "[::1:502"}) {
    EXPECT_FALSE(parse_host_port(bad).has_value()) << bad;
  }
}

}  // namespace
}  // namespace lamina::drivers
