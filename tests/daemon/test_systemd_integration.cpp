// systemd integration as the service manager sees it: notify datagrams on a socket the test
// binds in place of systemd's, the watchdog and socket-activation variables as systemd sets
// them, and the unit files judged by systemd-analyze itself.
#include "lamina/daemon/systemd_integration.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
namespace sd = lamina::daemon::systemd;

const fs::path kSource = LAMINA_SOURCE_DIR;

fs::path make_temp_dir() {
  std::string pattern = (fs::temp_directory_path() / "lamina-sd-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

sockaddr_un unix_address(const fs::path& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof(addr.sun_path) - 1);
  return addr;
}

int bound_unix_socket(const fs::path& path, int type) {
  const int fd = socket(AF_UNIX, type | SOCK_CLOEXEC, 0);
  const sockaddr_un addr = unix_address(path);
  if (fd < 0 || bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0)
    throw std::runtime_error("cannot bind " + path.string());
  return fd;
}

// Stands in for systemd's notify socket.
class Notify : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = make_temp_dir();
    fd_ = bound_unix_socket(dir_ / "notify", SOCK_DGRAM);
    const timeval timeout{2, 0};  // a missing datagram fails the test instead of hanging it
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    setenv("NOTIFY_SOCKET", (dir_ / "notify").c_str(), 1);
  }
  void TearDown() override {
    unsetenv("NOTIFY_SOCKET");
    close(fd_);
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string receive() {
    char buffer[4096];
    const ssize_t n = recv(fd_, buffer, sizeof(buffer), 0);
    return n < 0 ? std::string("<nothing received>") : std::string(buffer, static_cast<std::size_t>(n));
  }

  fs::path dir_;
  int fd_ = -1;
};

TEST_F(Notify, ReadySendsReadyAndStatus) {
  ASSERT_TRUE(sd::notify_ready("x"));
  const std::string m = receive();
  EXPECT_NE(m.find("READY=1"), std::string::npos) << m;
  EXPECT_NE(m.find("STATUS=x"), std::string::npos) << m;
}

TEST_F(Notify, ReadyWithoutStatusSendsNoStatus) {
  ASSERT_TRUE(sd::notify_ready());
  const std::string m = receive();
  EXPECT_EQ(m, "READY=1");
}

TEST_F(Notify, WatchdogStoppingAndStatus) {
  ASSERT_TRUE(sd::notify_watchdog());
  EXPECT_EQ(receive(), "WATCHDOG=1");
  ASSERT_TRUE(sd::notify_stopping("cutting stopped"));
  const std::string stopping = receive();
  EXPECT_NE(stopping.find("STOPPING=1"), std::string::npos) << stopping;
  EXPECT_NE(stopping.find("STATUS=cutting stopped"), std::string::npos) << stopping;
  ASSERT_TRUE(sd::notify_status("3 jobs queued"));
  EXPECT_EQ(receive(), "STATUS=3 jobs queued");
}

TEST_F(Notify, AStatusStaysOnOneLine) {
  // A newline would let the status text smuggle in another assignment (READY=1, MAINPID=…).
  ASSERT_TRUE(sd::notify_status("plan failed\nREADY=1"));
  EXPECT_EQ(receive(), "STATUS=plan failed READY=1");
}

TEST_F(Notify, NothingIsSentWithoutNotifySocket) {
  unsetenv("NOTIFY_SOCKET");
  EXPECT_FALSE(sd::notify_ready("x"));
  EXPECT_FALSE(sd::notify_status("x"));
  EXPECT_FALSE(sd::notify_stopping());
  EXPECT_FALSE(sd::notify_watchdog());
}

TEST_F(Notify, ASocketNobodyListensOnIsAFailure) {
  setenv("NOTIFY_SOCKET", (dir_ / "gone").c_str(), 1);
  EXPECT_FALSE(sd::notify_watchdog());
}

TEST(Watchdog, PeriodComesFromWatchdogUsecForThisProcess) {
  setenv("WATCHDOG_USEC", "5000000", 1);
  setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
  const auto period = sd::watchdog_period();
  ASSERT_TRUE(period.has_value());
  EXPECT_EQ(*period, std::chrono::seconds(5));
  EXPECT_TRUE(sd::watchdog_period().has_value()) << "asked twice (after a reload), still known";

  setenv("WATCHDOG_PID", std::to_string(getpid() + 1).c_str(), 1);  // meant for another process
  EXPECT_FALSE(sd::watchdog_period().has_value());
  unsetenv("WATCHDOG_PID");
  setenv("WATCHDOG_USEC", "soon", 1);
  EXPECT_FALSE(sd::watchdog_period().has_value());
  unsetenv("WATCHDOG_USEC");
  EXPECT_FALSE(sd::watchdog_period().has_value());
}

// Socket activation: systemd passes the listening socket as fd 3 (SD_LISTEN_FDS_START).
class Activation : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = make_temp_dir();
    saved_fd3_ = fcntl(3, F_GETFD) == -1 ? -1 : dup(3);  // fd 3 may be the runner's: give it back
  }
  void TearDown() override {
    unsetenv("LISTEN_FDS");
    unsetenv("LISTEN_PID");
    if (saved_fd3_ >= 0) {
      dup2(saved_fd3_, 3);
      close(saved_fd3_);
    } else {
      close(3);
    }
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void place_at_fd3(int fd) {
    if (fd == 3) return;  // fd 3 was free, so the socket got it
    ASSERT_EQ(dup2(fd, 3), 3);
    close(fd);
  }
  fs::path dir_;
  int saved_fd3_ = -1;
};

TEST_F(Activation, TheListeningSocketIsFd3) {
  const int fd = bound_unix_socket(dir_ / "lamina.sock", SOCK_STREAM);
  ASSERT_EQ(listen(fd, 8), 0);
  place_at_fd3(fd);
  setenv("LISTEN_FDS", "1", 1);
  setenv("LISTEN_PID", std::to_string(getpid()).c_str(), 1);
  EXPECT_EQ(sd::listen_fds(), std::vector<int>{3});
  EXPECT_TRUE(sd::is_unix_stream_listener(3));
  // Unset afterwards, so that `lamina plan` and other children never take fd 3 as theirs.
  EXPECT_EQ(std::getenv("LISTEN_FDS"), nullptr);
  EXPECT_EQ(std::getenv("LISTEN_PID"), nullptr);
  EXPECT_TRUE(sd::listen_fds().empty());
}

TEST_F(Activation, FdsMeantForAnotherProcessAreNotTaken) {
  setenv("LISTEN_FDS", "1", 1);
  setenv("LISTEN_PID", std::to_string(getpid() + 1).c_str(), 1);
  EXPECT_TRUE(sd::listen_fds().empty());
  unsetenv("LISTEN_PID");
  unsetenv("LISTEN_FDS");
  EXPECT_TRUE(sd::listen_fds().empty());
}

TEST_F(Activation, OnlyAListeningUnixStreamSocketCounts) {
  const int listener = bound_unix_socket(dir_ / "a.sock", SOCK_STREAM);
  ASSERT_EQ(listen(listener, 1), 0);
  EXPECT_TRUE(sd::is_unix_stream_listener(listener));
  const int unbound = socket(AF_UNIX, SOCK_STREAM, 0);
  EXPECT_FALSE(sd::is_unix_stream_listener(unbound)) << "not listening";
  const int datagram = bound_unix_socket(dir_ / "d.sock", SOCK_DGRAM);
  EXPECT_FALSE(sd::is_unix_stream_listener(datagram));
  const int tcp = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in loopback{};
  loopback.sin_family = AF_INET;
  loopback.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(tcp, reinterpret_cast<const sockaddr*>(&loopback), sizeof(loopback)), 0);
  ASSERT_EQ(listen(tcp, 1), 0);
  EXPECT_FALSE(sd::is_unix_stream_listener(tcp)) << "TCP";
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  EXPECT_FALSE(sd::is_unix_stream_listener(pipe_fds[0]));
  for (const int fd : {listener, unbound, datagram, tcp, pipe_fds[0], pipe_fds[1]}) close(fd);
  EXPECT_FALSE(sd::is_unix_stream_listener(listener)) << "closed";
}

// ---- The unit files, judged by systemd-analyze.

struct CommandResult {
  int status = -1;
  std::string output;  // stdout and stderr
};

CommandResult run(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  while (const std::size_t n = fread(buffer, 1, sizeof(buffer), pipe)) r.output.append(buffer, n);
  const int status = pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

bool have(const std::string& tool) { return run("command -v " + tool).status == 0; }

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// verify insists that ExecStart's binary exists: the copies run /bin/true with laminad's arguments.
class Units : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have("systemd-analyze")) GTEST_SKIP() << "systemd-analyze is not installed";
    dir_ = make_temp_dir();
    std::string service = read_text(kSource / "systemd/laminad.service");
    const std::string exec = "ExecStart=/usr/sbin/laminad ";
    const auto at = service.find("\n" + exec);
    ASSERT_NE(at, std::string::npos) << "laminad.service starts /usr/sbin/laminad";
    service.replace(at + 1, exec.size(), "ExecStart=/bin/true ");
    std::ofstream(dir_ / "laminad.service") << service;
    fs::copy_file(kSource / "systemd/laminad.socket", dir_ / "laminad.socket");
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  CommandResult verify() {
    return run("systemd-analyze verify '" + (dir_ / "laminad.service").string() + "' '" +
               (dir_ / "laminad.socket").string() + "'");
  }
  fs::path dir_;
};

// verify exits 0 on unknown keys and only prints them: any line about our units is a failure.
bool mentions_our_units(const std::string& output) { return output.find("lamina") != std::string::npos; }

TEST_F(Units, VerifyFindsNothingToSay) {
  const CommandResult r = verify();
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_FALSE(mentions_our_units(r.output)) << r.output;
}

TEST_F(Units, VerifyWouldReportAMistake) {
  // The check above is only worth something if a mistake shows: a misspelt key does.
  std::ofstream(dir_ / "laminad.service", std::ios::app) << "\n[Service]\nProtectSystm=strict\n";
  const CommandResult r = verify();
  EXPECT_TRUE(mentions_our_units(r.output)) << r.output;
  EXPECT_NE(r.output.find("ProtectSystm"), std::string::npos) << r.output;
}

// "→ Overall exposure level for laminad.service: 1.5 OK 🙂" → "1.5" (empty when not found).
std::string exposure_in(const std::string& output) {
  const std::string label = "Overall exposure level for ";
  const auto at = output.find(label);
  if (at == std::string::npos) return {};
  const auto colon = output.find(": ", at + label.size());
  if (colon == std::string::npos) return {};
  const auto begin = colon + 2;
  const auto end = output.find_first_not_of("0123456789.", begin);
  return output.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

TEST_F(Units, ExposureIsAtMostTwo) {
  const CommandResult r = run("systemd-analyze security --offline=true '" + (dir_ / "laminad.service").string() + "'");
  const std::string exposure = exposure_in(r.output);
  ASSERT_FALSE(exposure.empty()) << r.output;
  RecordProperty("exposure", exposure);
  EXPECT_LE(std::stod(exposure), 2.0) << r.output;
}

TEST(Sysusers, CreatesLaminaInDialout) {
  if (!have("systemd-sysusers")) GTEST_SKIP() << "systemd-sysusers is not installed";
  const fs::path root = make_temp_dir();
  fs::create_directories(root / "etc");
  std::ofstream(root / "etc/passwd") << "root:x:0:0:root:/root:/bin/sh\n";
  std::ofstream(root / "etc/group") << "root:x:0:\ndialout:x:20:\n";
  const CommandResult r = run("systemd-sysusers --root='" + root.string() + "' '" + (kSource / "systemd/lamina.sysusers").string() + "'");
  EXPECT_EQ(r.status, 0) << r.output;
  const std::string passwd = read_text(root / "etc/passwd");
  EXPECT_NE(passwd.find(":Lamina cell daemon:/var/lib/lamina:"), std::string::npos) << passwd;
  EXPECT_NE(passwd.find("\nlamina:x:"), std::string::npos) << passwd;
  EXPECT_NE(read_text(root / "etc/group").find("dialout:x:20:lamina"), std::string::npos) << read_text(root / "etc/group");

  // tmpfiles chowns to lamina, which needs root; the user resolves from the root made above.
  if (geteuid() == 0 && have("systemd-tmpfiles")) {
    const CommandResult t = run("systemd-tmpfiles --create --root='" + root.string() + "' '" +
                      (kSource / "systemd/lamina.tmpfiles").string() + "'");
    EXPECT_EQ(t.status, 0) << t.output;
    struct stat st {};
    ASSERT_EQ(stat((root / "var/lib/lamina").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, 0750u);
    EXPECT_TRUE(fs::is_directory(root / "etc/lamina"));
  }
  std::error_code ec;
  fs::remove_all(root, ec);
}

}  // namespace
