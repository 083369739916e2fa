// N web consoles on laminad, as a browser runs them: each logs in (POST /api/login), opens the
// WebSocket with its cookie and the console's Origin, subscribes and reads every notification
// for a while. Prints, as JSON, how many machine-status updates each console got per second
// (the console's ≥ 5 a second) and the errors. Used by bench/console_latency.sh beside
// daemon_rpc_load, to see whether consoles raise the RPC latency of the other clients.
// With HOLDS > 0 the first console is also the operator's: it presses Hold (machine.hold) and,
// 0.3 s later, Resume, HOLDS times, 3 s apart, and prints when each hold left it (steady_clock,
// CLOCK_MONOTONIC, as lamina-sim stamps the '!' that reaches the controller) and its reply time.
// Usage: console_load PORT USER PASSWORD [CONSOLES=5] [SECONDS=10] [HOLDS=0]
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

namespace beast = boost::beast;
namespace bhttp = beast::http;
using tcp = boost::asio::ip::tcp;

namespace {

std::string login(int port, const std::string& user, const std::string& password) {
  boost::asio::io_context io;
  beast::tcp_stream stream(io);
  stream.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  bhttp::request<bhttp::string_body> req(bhttp::verb::post, "/api/login", 11);
  req.set(bhttp::field::host, fmt::format("127.0.0.1:{}", port));
  req.set(bhttp::field::content_type, "application/json");
  req.body() = nlohmann::json{{"user", user}, {"password", password}}.dump();
  req.prepare_payload();
  bhttp::write(stream, req);
  beast::flat_buffer buffer;
  bhttp::response<bhttp::string_body> res;
  bhttp::read(stream, buffer, res);
  const std::string cookie(res[bhttp::field::set_cookie]);
  return cookie.substr(0, cookie.find(';'));
}

double mono_now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

struct Presses {
  std::vector<double> hold_sent_mono_s;
  std::vector<double> hold_reply_ms;
};

using WebSocket = beast::websocket::stream<beast::tcp_stream>;

// Sends a call and reads until its reply; the notifications read meanwhile are counted.
void call(WebSocket& ws, int id, const char* method, long& updates) {
  ws.write(boost::asio::buffer(fmt::format(R"({{"jsonrpc":"2.0","id":{},"method":"{}"}})", id, method)));
  for (;;) {
    beast::flat_buffer buffer;
    ws.read(buffer);
    const std::string text = beast::buffers_to_string(buffer.data());
    if (text.find(fmt::format(R"("id":{},)", id)) != std::string::npos) return;
    updates += text.find("notify_machine_status") != std::string::npos;
  }
}

// Reads until the deadline; the number of machine-status updates. `presses`: the operator's.
long console(int port, const std::string& cookie, double seconds, int holds, Presses* presses) {
  boost::asio::io_context io;
  WebSocket ws(io);
  beast::get_lowest_layer(ws).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  const std::string host = fmt::format("127.0.0.1:{}", port);
  ws.set_option(beast::websocket::stream_base::decorator([&](beast::websocket::request_type& r) {
    r.set(bhttp::field::cookie, cookie);
    r.set(bhttp::field::origin, "http://" + host);
  }));
  ws.handshake(host, "/ws");
  long updates = 0;
  call(ws, 1, "server.subscribe", updates);
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration<double>(seconds);
  int id = 2;
  for (int pressed = 0; presses && pressed < holds; ++pressed) {
    while (std::chrono::steady_clock::now() < start + std::chrono::seconds(1 + 3 * pressed)) call(ws, id++, "machine.status", updates);
    const double sent = mono_now_s();
    call(ws, id++, "machine.hold", updates);
    presses->hold_sent_mono_s.push_back(sent);
    presses->hold_reply_ms.push_back((mono_now_s() - sent) * 1000);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    call(ws, id++, "machine.resume", updates);
  }
  while (std::chrono::steady_clock::now() < end) {
    beast::flat_buffer buffer;
    ws.read(buffer);
    updates += beast::buffers_to_string(buffer.data()).find("notify_machine_status") != std::string::npos;
  }
  ws.close(beast::websocket::close_code::normal);
  return updates;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: console_load PORT USER PASSWORD [CONSOLES] [SECONDS]\n");
    return 2;
  }
  const int port = std::stoi(argv[1]);
  const int consoles = argc > 4 ? std::stoi(argv[4]) : 5;
  const double seconds = argc > 5 ? std::stod(argv[5]) : 10;
  const int holds = argc > 6 ? std::stoi(argv[6]) : 0;
  std::atomic<long> updates{0};
  std::atomic<int> errors{0};
  Presses presses;
  std::vector<std::thread> threads;
  for (int i = 0; i < consoles; ++i)
    threads.emplace_back([&, i] {
      try {
        updates += console(port, login(port, argv[2], argv[3]), seconds, holds, i == 0 ? &presses : nullptr);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "console: %s\n", e.what());
        ++errors;
      }
    });
  for (auto& t : threads) t.join();
  fmt::print("{{\"consoles\": {}, \"status_updates_per_s_each\": {:.2f}, \"errors\": {}, \"hold_sent_mono_s\": [{:.6f}], "
             "\"hold_reply_ms\": [{:.2f}]}}\n",
             consoles, consoles ? static_cast<double>(updates) / consoles / seconds : 0.0, errors.load(),
             fmt::join(presses.hold_sent_mono_s, ", "), fmt::join(presses.hold_reply_ms, ", "));
  return errors == 0 ? 0 : 1;
}
