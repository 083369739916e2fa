// POST /api/uploads (issue 19): a model from the console's form streamed to disk, its bytes as
// they are, into the daemon's Uploads (the id then goes with job.submit). Who may, how large, and
// what is left when a sender stops halfway.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <fstream>
#include <random>

#include "http_test_client.hpp"
#include "web_test_console.hpp"

namespace lamina::daemon::http {
namespace {

using testing::body_of;
using testing::status_of;
using testing_console::Console;

std::string upload_request(const Console& console, const std::string& name, const std::string& body,
                           const std::string& cookie, const std::string& origin) {
  return "POST /api/uploads?name=" + name + " HTTP/1.1\r\nHost: localhost:" + std::to_string(console.port()) +
         "\r\nContent-Type: application/octet-stream\r\nContent-Length: " + std::to_string(body.size()) + "\r\n" +
         (cookie.empty() ? "" : "Cookie: " + cookie + "\r\n") + (origin.empty() ? "" : "Origin: " + origin + "\r\n") +
         "Connection: close\r\n\r\n" + body;
}

std::string upload(const Console& console, const std::string& user, const std::string& body,
                   const std::string& name = "part.stl") {
  const std::string cookie = user.empty() ? "" : testing::http_login(console.port(), user, user + "'s password");
  return testing::http_exchange(console.port(), upload_request(console, name, body, cookie, console.origin()));
}

// Every byte value, CR LF and NUL included, as a binary STL has them.
std::string binary_bytes(std::size_t n) {
  std::mt19937 rng(19);
  std::string bytes(n, '\0');
  for (auto& b : bytes) b = static_cast<char>(rng() & 0xFF);
  return bytes;
}

TEST(WebUpload, AnEngineersModelReachesTheDiskByteForByte) {
  Console console;
  const std::string model = binary_bytes(1'500'000);  // several of the server's 256 KiB pieces
  const std::string r = upload(console, "eve", model);
  ASSERT_EQ(status_of(r), 200) << r.substr(0, 400);
  const auto reply = nlohmann::json::parse(body_of(r));
  EXPECT_EQ(reply["size"], model.size());
  auto path = console.uploads.take(reply["upload"].get<std::string>());  // as job.submit does
  ASSERT_TRUE(path.has_value()) << path.error().message;
  std::ifstream in(*path, std::ios::binary);
  const std::string on_disk((std::istreambuf_iterator<char>(in)), {});
  EXPECT_TRUE(on_disk == model) << "the file differs from what was sent (" << on_disk.size() << " bytes)";
}

TEST(WebUpload, OnlyAnEngineerMayAndARefusalSaysWhy) {
  Console console;
  const std::string viewer = upload(console, "vic", "solid x\nendsolid x\n");
  EXPECT_EQ(status_of(viewer), 403) << viewer;
  EXPECT_NE(body_of(viewer).find("uploading a model is for an engineer; vic is a viewer"), std::string::npos) << viewer;
  const std::string op = upload(console, "ana", "solid x\nendsolid x\n");
  EXPECT_EQ(status_of(op), 403) << op;
  EXPECT_NE(body_of(op).find("ana is an operator"), std::string::npos) << op;
  EXPECT_EQ(status_of(upload(console, "", "solid x\n")), 401);
  const std::string cookie = testing::http_login(console.port(), "eve", "eve's password");
  const std::string foreign = testing::http_exchange(
      console.port(), upload_request(console, "part.stl", "solid x\n", cookie, "http://evil.example"));
  EXPECT_EQ(status_of(foreign), 403) << foreign;
  EXPECT_EQ(console.uploads.open_count(), 0U) << "a refused upload left a file behind";
}

TEST(WebUpload, ATooLargeUnnamedOrUnmeasuredBodyIsRefusedBeforeItIsRead) {
  Console console;
  const std::string cookie = testing::http_login(console.port(), "eve", "eve's password");
  // Announced past the limit, nothing sent after the head: the answer comes all the same.
  const std::string big = testing::http_exchange(
      console.port(), "POST /api/uploads?name=big.stl HTTP/1.1\r\nHost: localhost:" + std::to_string(console.port()) +
                          "\r\nCookie: " + cookie + "\r\nContent-Length: " + std::to_string(Console::kMaxUploadBytes + 1) +
                          "\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(status_of(big), 413) << big;
  const std::string chunked = testing::http_exchange(
      console.port(), "POST /api/uploads?name=part.stl HTTP/1.1\r\nHost: localhost:" + std::to_string(console.port()) +
                          "\r\nCookie: " + cookie + "\r\nTransfer-Encoding: chunked\r\nConnection: close\r\n\r\n5\r\nsolid\r\n0\r\n\r\n");
  EXPECT_EQ(status_of(chunked), 411) << chunked;
  EXPECT_EQ(status_of(upload(console, "eve", "solid x\n", "..%2Fx.stl")), 400);
  EXPECT_EQ(status_of(upload(console, "eve", "solid x\n", "notes.txt")), 400);  // not a model's extension
  EXPECT_EQ(console.uploads.open_count(), 0U);
  // The upload's larger limit is its own: a login's body is still 4 KiB at most.
  const std::string long_login = console.post("/api/login", std::string(5000, ' '));
  EXPECT_EQ(status_of(long_login), 413) << long_login;
}

TEST(WebUpload, ASenderThatStopsHalfwayLeavesNoUploadBehind) {
  Console console;
  const std::string cookie = testing::http_login(console.port(), "eve", "eve's password");
  const std::string model = binary_bytes(600'000);
  const std::string request = upload_request(console, "part.stl", model, cookie, console.origin());
  const int fd = testing::connect_loopback(console.port());
  const std::size_t half = request.size() - model.size() / 2;
  ASSERT_EQ(::write(fd, request.data(), half), static_cast<ssize_t>(half));
  // The upload is open while its bytes come…
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (console.uploads.open_count() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(console.uploads.open_count(), 1U);
  ::close(fd);  // …and dropped, file and slot, when the sender goes
  while (console.uploads.open_count() != 0 && std::chrono::steady_clock::now() < deadline + std::chrono::seconds(10))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(console.uploads.open_count(), 0U);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& f : std::filesystem::directory_iterator(console.upload_dir.path() / "uploads")) ++files;
  EXPECT_EQ(files, 0U) << "the half model is still on disk";
}

}  // namespace
}  // namespace lamina::daemon::http
