// make_link (issue 18): the one place a link is built, for `lamina stream` and laminad alike;
// what differs between protocols is a trait of the protocol's row.
#include <gtest/gtest.h>

#include "lamina/drivers/link_factory.hpp"

namespace lamina::drivers {
namespace {

TEST(LinkFactory, EveryProtocolIsRegisteredOnceWithItsTraits) {
  EXPECT_EQ(link_protocol_names_text(), "grbl, send-response, xonxoff, modbus");
  for (const LinkProtocol& p : link_protocols()) {
    EXPECT_EQ(find_link_protocol(p.name), &p);
    EXPECT_FALSE(p.summary.empty()) << p.name;
    EXPECT_EQ(p.make == nullptr, p.traits.mailbox) << p.name << ": a line protocol makes its LineProtocol";
    EXPECT_EQ(cut_settings_for(p).wait_for_idle, p.traits.reports_status) << p.name;
  }
  EXPECT_FALSE(find_link_protocol("xonxoff")->traits.reports_status) << "a drip feed reports no status";
  EXPECT_TRUE(find_link_protocol("modbus")->traits.mailbox);
}

TEST(LinkFactory, SettingsThatNameNoLinkAreRefusedSayingWhich) {
  LinkSettings s;
  s.protocol = "marlin";
  auto bad = make_link(s);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error(), "protocol 'marlin' is unknown (known: grbl, send-response, xonxoff, modbus)");

  s.protocol = "grbl";
  EXPECT_EQ(make_link(s).error(), "give a serial port or a TCP address (one of them)");
  s.port = "/dev/ttyUSB0", s.tcp = "10.0.0.2:23";
  EXPECT_EQ(make_link(s).error(), "give a serial port or a TCP address (one of them)");
  s.port.clear(), s.tcp = "10.0.0.2";
  EXPECT_EQ(make_link(s).error(), "tcp '10.0.0.2': expected HOST:PORT (\"[::1]:PORT\" for IPv6)");
}

// Building opens nothing (the link connects when a cut starts): these run without a machine.
TEST(LinkFactory, ALinkSaysWhatItIs) {
  LinkSettings s;
  s.protocol = "xonxoff", s.port = "/dev/ttyS0", s.baud = 9600;
  auto serial = make_link(s);
  ASSERT_TRUE(serial) << serial.error();
  EXPECT_EQ(serial->description, "xonxoff on /dev/ttyS0 at 9600 baud");
  EXPECT_DOUBLE_EQ(serial->line_bytes_per_s, 960.0);
  EXPECT_EQ(serial->protocol, find_link_protocol("xonxoff"));

  s = {};
  s.tcp = "[::1]:2323";
  auto tcp = make_link(s);
  ASSERT_TRUE(tcp) << tcp.error();
  EXPECT_EQ(tcp->description, "grbl on tcp [::1]:2323");
  EXPECT_DOUBLE_EQ(tcp->line_bytes_per_s, 0.0);

  s = {};
  s.protocol = "modbus", s.plc.host = "::1", s.plc.port = 1502;
  auto mailbox = make_link(s);
  ASSERT_TRUE(mailbox) << mailbox.error();
  EXPECT_EQ(mailbox->description, "Modbus mailbox on [::1]:1502");
  EXPECT_TRUE(mailbox->link->can_reset());
}

}  // namespace
}  // namespace lamina::drivers
