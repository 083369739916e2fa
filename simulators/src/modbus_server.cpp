#include "modbus_server.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/ioctl.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <optional>
#include <thread>
#include <vector>

#include <fmt/format.h>

namespace lamina::sim {
namespace mm = modbus_map;
namespace {
using Clock = std::chrono::steady_clock;

// A frame is handed to libmodbus only once all of it has arrived (the MBAP header says how
// long it is), so a partial frame never blocks the one server thread; a client that leaves a
// frame unfinished this long is dropped.
constexpr double kFrameTimeoutS = 0.5;
// libmodbus's own byte timeout, a second line of defence: only reached when a frame's function
// needs more bytes than its header announced (a malformed frame).
constexpr std::uint32_t kByteTimeoutUs = 50'000;
constexpr int kMbapLength = 7;
constexpr int kMaxClients = 32;

struct Segment {
  int begin, end;  // [begin, end)
};
// The documented addresses per area (docs/modbus-map.md); anything else is "illegal data address".
const std::vector<Segment> kCoilSegments{{0, mm::kCoilCount}, {mm::kCoilSimEstop, mm::kCoilSimEnd}};
const std::vector<Segment> kInputSegments{{0, mm::kInputCount}};
const std::vector<Segment> kInRegSegments{{0, mm::kInCount}};
const std::vector<Segment> kHoldSegments{{0, mm::kHoldAbrasiveSetpoint + 1}, {mm::kHoldMailboxSeq, mm::kHoldCount}};

bool inside(const std::vector<Segment>& segments, int address, int count) {
  for (const auto& s : segments)
    if (address >= s.begin && address + count <= s.end) return true;
  return false;
}

int word_at(const std::uint8_t* p) { return (p[0] << 8) | p[1]; }

// False when the request names an address outside the map. Quantities out of the protocol's
// range are left to modbus_reply, which answers them with "illegal data value" as the standard says.
bool addresses_documented(const std::uint8_t* req, int length, int header) {
  if (length < header + 5) return true;  // too short to carry an address: modbus_reply decides
  const int function = req[header];
  const int address = word_at(req + header + 1);
  const int count = word_at(req + header + 3);
  auto check = [&](const std::vector<Segment>& segments, int n, int max_n) {
    return n < 1 || n > max_n || inside(segments, address, n);
  };
  switch (function) {
    case MODBUS_FC_READ_COILS: return check(kCoilSegments, count, MODBUS_MAX_READ_BITS);
    case MODBUS_FC_READ_DISCRETE_INPUTS: return check(kInputSegments, count, MODBUS_MAX_READ_BITS);
    case MODBUS_FC_READ_HOLDING_REGISTERS: return check(kHoldSegments, count, MODBUS_MAX_READ_REGISTERS);
    case MODBUS_FC_READ_INPUT_REGISTERS: return check(kInRegSegments, count, MODBUS_MAX_READ_REGISTERS);
    case MODBUS_FC_WRITE_SINGLE_COIL: return inside(kCoilSegments, address, 1);
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
    case MODBUS_FC_MASK_WRITE_REGISTER: return inside(kHoldSegments, address, 1);
    case MODBUS_FC_WRITE_MULTIPLE_COILS: return check(kCoilSegments, count, MODBUS_MAX_WRITE_BITS);
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS: return check(kHoldSegments, count, MODBUS_MAX_WRITE_REGISTERS);
    case MODBUS_FC_WRITE_AND_READ_REGISTERS: {
      if (length < header + 9) return true;
      const int write_address = word_at(req + header + 5);
      const int write_count = word_at(req + header + 7);
      const bool read_ok = check(kHoldSegments, count, MODBUS_MAX_WR_READ_REGISTERS);
      const bool write_ok = write_count < 1 || write_count > MODBUS_MAX_WR_WRITE_REGISTERS ||
                            inside(kHoldSegments, write_address, write_count);
      return read_ok && write_ok;
    }
    default: return true;  // unknown functions: modbus_reply answers "illegal function"
  }
}

bool is_write(int function) {
  switch (function) {
    case MODBUS_FC_WRITE_SINGLE_COIL:
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
    case MODBUS_FC_WRITE_MULTIPLE_COILS:
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
    case MODBUS_FC_MASK_WRITE_REGISTER:
    case MODBUS_FC_WRITE_AND_READ_REGISTERS: return true;
    default: return false;
  }
}

void set_cloexec(int fd) { ::fcntl(fd, F_SETFD, ::fcntl(fd, F_GETFD) | FD_CLOEXEC); }

std::string loopback_or_throw(const std::string& host) {
  const std::string ip = host == "localhost" ? "127.0.0.1" : host;
  in_addr addr{};
  if (::inet_pton(AF_INET, ip.c_str(), &addr) != 1 || (ntohl(addr.s_addr) >> 24) != 127)
    throw std::runtime_error(
        fmt::format("the Modbus server listens on loopback only (127.x.x.x); {} is not a loopback address", host));
  return ip;
}

}  // namespace

struct ModbusServer::Impl {
  struct Client {
    int fd = -1;
    modbus_t* ctx = nullptr;
    std::optional<Clock::time_point> partial_since;  // a frame has begun but not fully arrived
  };

  Plc& plc;
  std::mutex& mutex;
  std::function<double()> now_s;
  modbus_t* listen_ctx = nullptr;
  int listen_fd = -1;
  int port = 0;
  modbus_mapping_t* mapping = nullptr;
  int wake[2] = {-1, -1};  // self-pipe: the destructor writes a byte, select wakes at once
  std::atomic<bool> stopping{false};
  std::atomic<bool> network_up{true};
  std::atomic<bool> network_applied{true};  // what the server thread has acted on
  std::atomic<std::size_t> served{0};
  std::vector<Client> clients;
  std::thread thread;

  Impl(Plc& p, std::mutex& m, std::function<double()> clock) : plc(p), mutex(m), now_s(std::move(clock)) {}

  void start(const std::string& host, int requested_port) {
    const std::string ip = loopback_or_throw(host);
    const std::string where = fmt::format("{}:{}", host, requested_port);
    listen_ctx = modbus_new_tcp(ip.c_str(), requested_port);
    if (!listen_ctx) throw std::runtime_error(fmt::format("cannot create a Modbus context for {}", where));
    listen_fd = modbus_tcp_listen(listen_ctx, 16);
    if (listen_fd < 0)
      throw std::runtime_error(fmt::format("cannot listen for Modbus on {}: {}", where, std::strerror(errno)));
    set_cloexec(listen_fd);
    // Non-blocking so a client that resets between select() and accept() cannot block the thread.
    ::fcntl(listen_fd, F_SETFL, ::fcntl(listen_fd, F_GETFL) | O_NONBLOCK);
    sockaddr_in bound{};
    socklen_t bound_len = sizeof bound;
    if (::getsockname(listen_fd, reinterpret_cast<sockaddr*>(&bound), &bound_len) != 0)
      throw std::runtime_error(fmt::format("cannot read the Modbus port of {}: {}", where, std::strerror(errno)));
    port = ntohs(bound.sin_port);

    const PlcRegisters& r = plc.registers();
    mapping = modbus_mapping_new(static_cast<int>(r.coils.size()), static_cast<int>(r.inputs.size()),
                                 static_cast<int>(r.holding.size()), static_cast<int>(r.input_registers.size()));
    if (!mapping) throw std::runtime_error("cannot allocate the Modbus register mapping");
    if (::pipe2(wake, O_CLOEXEC | O_NONBLOCK) != 0)
      throw std::runtime_error(fmt::format("cannot create the Modbus server's wake pipe: {}", std::strerror(errno)));
    thread = std::thread([this] { run(); });
  }

  ~Impl() {
    stopping = true;
    if (wake[1] >= 0) wake_up();
    if (thread.joinable()) thread.join();
    for (auto& c : clients) drop(c);
    if (listen_fd >= 0) ::close(listen_fd);
    if (listen_ctx) modbus_free(listen_ctx);  // its socket is listen_fd, closed above
    if (mapping) modbus_mapping_free(mapping);
    for (int fd : wake)
      if (fd >= 0) ::close(fd);
  }

  void run() {
    while (!stopping) {
      if (!network_up) {
        cut_off();
        continue;
      }
      if (!network_applied) close_unread_backlog();  // sent while it was down: lost with the link
      network_applied = true;
      fd_set readable;
      FD_ZERO(&readable);
      FD_SET(listen_fd, &readable);
      FD_SET(wake[0], &readable);
      int max_fd = std::max(listen_fd, wake[0]);
      bool any_partial = false;
      for (const auto& c : clients) {
        // A client with half a frame stays readable: polled below instead, or select would spin.
        if (c.partial_since) {
          any_partial = true;
          continue;
        }
        FD_SET(c.fd, &readable);
        max_fd = std::max(max_fd, c.fd);
      }
      // The stop flag is seen within 50 ms even without the pipe; partial frames polled every 5 ms.
      timeval timeout{0, any_partial ? 5'000 : 50'000};
      const int n = ::select(max_fd + 1, &readable, nullptr, nullptr, &timeout);
      if (n < 0) {
        FD_ZERO(&readable);  // EINTR: contents undefined
      }
      if (FD_ISSET(wake[0], &readable)) {
        drain_wake();
        continue;  // stopping, or the network went down: the loop's head decides
      }
      for (auto& c : clients)
        if ((c.partial_since || FD_ISSET(c.fd, &readable)) && !serve(c)) drop(c);
      std::erase_if(clients, [](const Client& c) { return c.fd < 0; });
      if (FD_ISSET(listen_fd, &readable)) accept_one();
    }
  }

  // The PLC off the network (a cable pulled, a switch down): its logic runs on, the heartbeat
  // watchdog included, but no request reaches it. Connections it had are gone; a new one waits
  // unaccepted (the host sees timeouts, as behind a dead link) and is closed unread when the
  // network is back: what a host sent into the dead link is lost, never served late.
  void cut_off() {
    for (auto& c : clients) drop(c);
    clients.clear();
    network_applied = false;
    fd_set readable;
    FD_ZERO(&readable);
    FD_SET(wake[0], &readable);
    timeval timeout{0, 50'000};
    if (::select(wake[0] + 1, &readable, nullptr, nullptr, &timeout) > 0 && FD_ISSET(wake[0], &readable)) drain_wake();
  }

  void close_unread_backlog() {  // the listening socket is non-blocking
    for (int fd; (fd = ::accept(listen_fd, nullptr, nullptr)) >= 0;) ::close(fd);
  }

  void drain_wake() {
    char bytes[16];
    while (::read(wake[0], bytes, sizeof bytes) > 0) {
    }
  }

  void wake_up() {
    const char byte = 1;
    [[maybe_unused]] auto n = ::write(wake[1], &byte, 1);
  }

  // Returns once the server thread has acted on the change (a request after it sees it).
  void set_network(bool up) {
    network_up = up;
    wake_up();
    for (int i = 0; i < 1000 && network_applied != up; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

  void accept_one() {
    // modbus_tcp_accept stores the new socket in the context it is given, so it gets a
    // context of the client's own; the listening context keeps the listening socket.
    Client c;
    c.ctx = modbus_new_tcp("127.0.0.1", port);
    if (!c.ctx) return;
    int s = listen_fd;
    c.fd = modbus_tcp_accept(c.ctx, &s);
    if (c.fd < 0 || c.fd >= FD_SETSIZE || static_cast<int>(clients.size()) >= kMaxClients) {
      drop(c);
      return;
    }
    set_cloexec(c.fd);
    modbus_set_indication_timeout(c.ctx, 0, kByteTimeoutUs);
    modbus_set_byte_timeout(c.ctx, 0, kByteTimeoutUs);
    clients.push_back(c);
  }

  static void drop(Client& c) {
    if (c.ctx) {
      if (c.fd >= 0) modbus_close(c.ctx);  // closes c.fd
      modbus_free(c.ctx);
    } else if (c.fd >= 0) {
      ::close(c.fd);
    }
    c.fd = -1;
    c.ctx = nullptr;
  }

  enum class Frame { complete, partial, bad };

  // Whether a whole Modbus TCP frame is waiting on the socket, judged from its MBAP header
  // (transaction id, protocol id 0, length of what follows).
  static Frame frame_waiting(int fd) {
    int available = 0;
    if (::ioctl(fd, FIONREAD, &available) != 0) return Frame::bad;
    if (available == 0) return Frame::complete;  // readable with nothing: EOF, modbus_receive sees it
    if (available < kMbapLength) return Frame::partial;
    std::uint8_t mbap[kMbapLength];
    if (::recv(fd, mbap, sizeof mbap, MSG_PEEK | MSG_DONTWAIT) != kMbapLength) return Frame::partial;
    const int follows = word_at(mbap + 4);  // unit id + PDU
    if (word_at(mbap + 2) != 0 || follows < 2 || 6 + follows > MODBUS_TCP_MAX_ADU_LENGTH) return Frame::bad;
    return available >= 6 + follows ? Frame::complete : Frame::partial;
  }

  // One request from a client that has bytes waiting. False: close it (gone, garbage, too slow).
  bool serve(Client& c) {
    switch (frame_waiting(c.fd)) {
      case Frame::bad: return false;
      case Frame::partial:
        if (!c.partial_since) c.partial_since = Clock::now();
        return std::chrono::duration<double>(Clock::now() - *c.partial_since).count() < kFrameTimeoutS;
      case Frame::complete: c.partial_since.reset(); break;
    }
    std::uint8_t req[MODBUS_TCP_MAX_ADU_LENGTH];
    const int length = modbus_receive(c.ctx, req);
    if (length < 0) return false;
    if (length == 0) return true;  // addressed to another unit: nothing to answer
    const int header = modbus_get_header_length(c.ctx);
    std::lock_guard lock(mutex);
    ++served;
    if (!addresses_documented(req, length, header))
      return modbus_reply_exception(c.ctx, req, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS) >= 0;

    PlcRegisters& r = plc.registers();
    std::memcpy(mapping->tab_bits, r.coils.data(), r.coils.size());
    std::memcpy(mapping->tab_input_bits, r.inputs.data(), r.inputs.size());
    std::memcpy(mapping->tab_input_registers, r.input_registers.data(), r.input_registers.size() * 2);
    std::memcpy(mapping->tab_registers, r.holding.data(), r.holding.size() * 2);
    const int rc = modbus_reply(c.ctx, req, length, mapping);
    if (is_write(req[header])) {
      // Applied even if sending the answer failed: the write reached the PLC either way.
      std::memcpy(r.coils.data(), mapping->tab_bits, r.coils.size());
      std::memcpy(r.holding.data(), mapping->tab_registers, r.holding.size() * 2);
      plc.after_client_write(now_s());
    }
    return rc >= 0;
  }
};

ModbusServer::ModbusServer(std::string host, int port, Plc& plc, std::mutex& mutex, std::function<double()> now_s)
    : impl_(std::make_unique<Impl>(plc, mutex, std::move(now_s))) {
  impl_->start(host, port);
}

ModbusServer::~ModbusServer() = default;

int ModbusServer::port() const { return impl_->port; }
std::size_t ModbusServer::requests_served() const { return impl_->served; }
void ModbusServer::set_network_up(bool up) { impl_->set_network(up); }
bool ModbusServer::network_up() const { return impl_->network_up; }

}  // namespace lamina::sim
