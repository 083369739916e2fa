// Transports against the lamina-sim process: a PTY through termios (as libserialport 0.1.1
// refuses PTYs), TCP, and the failures a cell meets — no such port, refused or silent hosts, an
// unplugged cable, and a close() while a read is pending.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <iostream>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "lamina/drivers/transport.hpp"
#include "sim_process.hpp"
#include "transport_test_support.hpp"

namespace {

using namespace lamina::drivers;
using lamina::sim::testing::control;
using lamina::sim::testing::control_status;
using lamina::sim::testing::seconds_since;
using lamina::sim::testing::SimProcess;
using lamina::sim::testing::TempDir;
using lamina::drivers::testing::closed_tcp_port;
using lamina::drivers::testing::Reader;
using lamina::drivers::testing::SilentListener;
using lamina::drivers::testing::write_all;

struct PtySim {
  TempDir dir;
  std::string link = dir.file("cnc");
  SimProcess sim;
  explicit PtySim(std::vector<std::string> extra = {})
      : sim([&] {
          // grblHAL on native USB stays quiet when the port opens (lamina-sim's default): these
          // tests ask for the banner with a soft reset (greet). A board that greets every open
          // would race open_serial's flush of stale input, which runs just after the open — the
          // Streamer copes with a lost banner; a test reading the raw line must not depend on it.
          std::vector<std::string> args{"--link", link, "--control", "127.0.0.1:0"};
          args.insert(args.end(), extra.begin(), extra.end());
          return args;
        }()) {}
};

// A soft reset (^X, a real-time byte) makes the controller print its banner: read up to the end
// of that line, so what follows on the line is an answer to the test.
::testing::AssertionResult greet(boost::asio::io_context& io, Transport& t, Reader& r) {
  if (auto failed = write_all(io, t, "\x18")) return ::testing::AssertionFailure() << "write: " << failed.message();
  if (!r.wait_for("for help]\r\n", 3.0))
    return ::testing::AssertionFailure() << "no banner after ^X; got: " << r.text() << " error: " << r.error().message();
  return ::testing::AssertionSuccess();
}

TEST(Transports, ListSerialPortsReturnsWithoutError) {
  const auto ports = list_serial_ports();
  ASSERT_TRUE(ports) << ports.error().message;
  for (const auto& p : *ports) {
    EXPECT_FALSE(p.name.empty());
    EXPECT_FALSE(p.transport.empty()) << p.name;
  }
}

TEST(Transports, PtyLinkReadsTheBannerAndAnswersBuildInfoOverARawLine) {
  PtySim s;
  boost::asio::io_context io;
  auto t = open_serial(io, s.link, SerialSettings{});
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_EQ((*t)->describe(), "pty " + s.link + " (termios) 115200 8N1");
  Reader r(io, **t);
  ASSERT_TRUE(greet(io, **t, r));
  ASSERT_FALSE(write_all(io, **t, "$I\n"));
  ASSERT_TRUE(r.wait_for("[OPT:", 3.0)) << "got: " << r.text();
  EXPECT_TRUE(r.wait_for("ok", 2.0));
  // A line that echoed would hand the banner back to the controller: it must see our 3 bytes only.
  const auto status = control_status(s.sim.control_port());
  EXPECT_EQ(status["bytes_received"], 3) << status.dump();
  EXPECT_EQ(status["errors_sent"], 0) << status.dump();
}

TEST(Transports, TcpLinkReadsTheBannerAndAnswersBuildInfo) {
  SimProcess sim({"--tcp", "127.0.0.1:0", "--on-open", "banner"});
  boost::asio::io_context io;
  auto t = open_tcp(io, "127.0.0.1", sim.tcp_port(), 2.0);
  ASSERT_TRUE(t) << t.error().message;
  EXPECT_EQ((*t)->describe(), "tcp 127.0.0.1:" + std::to_string(sim.tcp_port()));
  Reader r(io, **t);
  ASSERT_TRUE(r.wait_for("Grbl", 3.0)) << "got: " << r.text() << " error: " << r.error().message();
  ASSERT_FALSE(write_all(io, **t, "$I\n"));
  EXPECT_TRUE(r.wait_for("[OPT:", 3.0)) << "got: " << r.text();
}

TEST(Transports, AMissingDeviceIsPortNotFoundNamingIt) {
  boost::asio::io_context io;
  auto check = [](const std::expected<std::unique_ptr<Transport>, LinkError>& result) {
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().code, LinkErrorCode::port_not_found);
    EXPECT_NE(result.error().message.find("/nonexistent"), std::string::npos) << result.error().message;
  };
  check(open_serial(io, "/nonexistent", {}));
  check(open_termios(io, "/nonexistent", {}));
}

TEST(Transports, ANodeThatIsNotATerminalIsOpenFailed) {
  boost::asio::io_context io;
  auto result = open_serial(io, "/dev/null", {});
  ASSERT_FALSE(result) << (*result)->describe();
  EXPECT_EQ(result.error().code, LinkErrorCode::open_failed) << result.error().message;
  EXPECT_NE(result.error().message.find("/dev/null"), std::string::npos) << result.error().message;
}

TEST(Transports, AnUnknownUsbSerialNumberIsPortNotFoundListingThePorts) {
  boost::asio::io_context io;
  auto result = open_serial(io, "LAMINA0NOSUCHSERIAL", {});
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, LinkErrorCode::port_not_found);
  const std::string& m = result.error().message;
  EXPECT_NE(m.find("LAMINA0NOSUCHSERIAL"), std::string::npos) << m;
  EXPECT_NE(m.find("ports: "), std::string::npos) << m;
  const auto ports = list_serial_ports();
  ASSERT_TRUE(ports);
  for (const auto& p : *ports) EXPECT_NE(m.find(p.name), std::string::npos) << m;
}

TEST(Transports, SettingsTheLineCannotRunAreRefusedNamingTheSetting) {
  PtySim s;
  boost::asio::io_context io;
  SerialSettings odd_baud;
  odd_baud.baud = 100000;  // 13% from 115200: no UART would talk to it
  auto refused = open_serial(io, s.link, odd_baud);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, LinkErrorCode::configure_failed);
  EXPECT_NE(refused.error().message.find("baud 100000"), std::string::npos) << refused.error().message;

  SerialSettings close_baud;
  close_baud.baud = 115000;  // within tolerance: runs at the standard rate and says so
  auto rounded = open_serial(io, s.link, close_baud);
  ASSERT_TRUE(rounded) << rounded.error().message;
  EXPECT_NE((*rounded)->describe().find(" 115200 8N1"), std::string::npos) << (*rounded)->describe();

  SerialSettings nine_bits;
  nine_bits.data_bits = 9;
  auto bad = open_serial(io, s.link, nine_bits);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, LinkErrorCode::bad_request);
  EXPECT_NE(bad.error().message.find("data bits"), std::string::npos) << bad.error().message;
}

TEST(Transports, TcpToAClosedPortIsOpenFailedNamingHostAndPort) {
  const int port = closed_tcp_port();
  boost::asio::io_context io;
  auto result = open_tcp(io, "127.0.0.1", port, 1.0);
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, LinkErrorCode::open_failed);
  EXPECT_NE(result.error().message.find("127.0.0.1:" + std::to_string(port)), std::string::npos)
      << result.error().message;
}

TEST(Transports, TcpToASilentPeerTimesOutWithinItsTimeout) {
  SilentListener silent;
  boost::asio::io_context io;
  const auto t0 = std::chrono::steady_clock::now();
  auto result = open_tcp(io, "127.0.0.1", silent.port(), 0.3);
  const double elapsed_s = seconds_since(t0);
  ASSERT_FALSE(result) << (*result)->describe();
  EXPECT_EQ(result.error().code, LinkErrorCode::timeout) << result.error().message;
  EXPECT_NE(result.error().message.find("127.0.0.1:" + std::to_string(silent.port())), std::string::npos)
      << result.error().message;
  EXPECT_GE(elapsed_s, 0.25);
  EXPECT_LT(elapsed_s, 1.0);
}

TEST(Transports, UnpluggingThePtyCompletesThePendingReadWithAnError) {
  PtySim s;
  boost::asio::io_context io;
  auto t = open_serial(io, s.link, {});
  ASSERT_TRUE(t) << t.error().message;
  Reader r(io, **t);
  ASSERT_TRUE(greet(io, **t, r));
  r.start();
  ASSERT_EQ(control(s.sim.control_port(), "unplug").find("error"), std::string::npos);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(r.wait_for_error(2.0)) << "the read hung after the unplug";
  EXPECT_LT(seconds_since(t0), 2.0);
  EXPECT_NE(r.error(), std::errc::operation_canceled) << r.error().message();
  EXPECT_EQ(to_link_error(r.error(), (*t)->describe()).code, LinkErrorCode::io_error);
  std::cout << "  read ended with: " << r.error().message() << "\n";
}

TEST(Transports, UnpluggingTheTcpLinkCompletesThePendingReadWithAnError) {
  // Unplugged once the link is open (an unplug timed from the simulator's start could come
  // before the connect on a loaded machine).
  SimProcess sim({"--tcp", "127.0.0.1:0", "--control", "127.0.0.1:0"});
  boost::asio::io_context io;
  auto t = open_tcp(io, "127.0.0.1", sim.tcp_port(), 2.0);
  ASSERT_TRUE(t) << t.error().message;
  Reader r(io, **t);
  r.start();
  ASSERT_EQ(control(sim.control_port(), "unplug").find("error"), std::string::npos);
  EXPECT_TRUE(r.wait_for_error(3.0)) << "the read hung after the unplug; got: " << r.text();
  EXPECT_NE(r.error(), std::errc::operation_canceled) << r.error().message();
  EXPECT_EQ(to_link_error(r.error(), (*t)->describe()).code, LinkErrorCode::io_error);
  std::cout << "  read ended with: " << r.error().message() << "\n";
}

TEST(Transports, CloseAbortsAPendingReadAndCanBeRepeated) {
  PtySim s;
  boost::asio::io_context io;
  auto t = open_serial(io, s.link, {});
  ASSERT_TRUE(t) << t.error().message;
  Reader r(io, **t);
  ASSERT_TRUE(greet(io, **t, r));
  r.start();
  ASSERT_TRUE(r.pending());
  (*t)->close();
  (*t)->close();
  EXPECT_TRUE(r.wait_for_error(1.0)) << "close() left the read pending";
  EXPECT_EQ(r.error(), std::errc::operation_canceled) << r.error().message();
  EXPECT_EQ(to_link_error(r.error(), (*t)->describe()).code, LinkErrorCode::cancelled);
  // An operation started after close() fails at once instead of hanging.
  Reader after(io, **t);
  EXPECT_TRUE(after.wait_for_error(1.0));
  EXPECT_TRUE(after.text().empty());
}

}  // namespace
