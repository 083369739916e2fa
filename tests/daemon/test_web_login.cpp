// The web console's login and its WebSocket (issue 19), over real sockets: laminad's HTTP server
// and RPC server on one io thread, as in laminad, with a handler that says who is calling. The
// roles' effect on the real methods is LaminadWeb's (test_laminad_web.cpp).
#include <gtest/gtest.h>

#include <future>
#include <optional>
#include <set>
#include <thread>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "http_test_client.hpp"
#include "web_test_console.hpp"
#include "ws_test_client.hpp"

namespace lamina::daemon::http {
namespace {

using testing::body_of;
using testing::status_of;
using testing::WsClient;

using testing_console::Console;
using testing_console::users;

using testing::session_cookie;

TEST(WebLogin, TheRightPasswordOpensASessionInAStrictHttpOnlyCookie) {
  Console console;
  const std::string r = console.login("ana", "ana's password");
  ASSERT_EQ(status_of(r), 200) << r;
  EXPECT_NE(r.find("HttpOnly; SameSite=Strict"), std::string::npos) << r;
  const auto reply = nlohmann::json::parse(body_of(r));
  EXPECT_EQ(reply["user"], "ana");
  EXPECT_EQ(reply["role"], "operator");
  const std::string cookie = session_cookie(r);
  ASSERT_TRUE(cookie.starts_with("lamina_session=")) << r;
  const std::string session = console.get("/api/session", cookie);
  ASSERT_EQ(status_of(session), 200) << session;
  EXPECT_EQ(nlohmann::json::parse(body_of(session))["user"], "ana");
  EXPECT_EQ(status_of(console.get("/api/session", "")), 401);
}

TEST(WebLogin, AWrongPasswordAndAnUnknownNameGetTheSameAnswer) {
  Console console;
  const std::string wrong = console.login("ana", "guess");
  const std::string unknown = console.login("nobody", "guess");
  EXPECT_EQ(status_of(wrong), 401) << wrong;
  EXPECT_EQ(status_of(unknown), 401) << unknown;
  EXPECT_EQ(body_of(wrong), body_of(unknown));
  EXPECT_EQ(wrong.find("Set-Cookie"), std::string::npos);
  EXPECT_EQ(status_of(console.post("/api/login", "{\"user\": 1}")), 400);
}

TEST(WebLogin, AfterFiveWrongGuessesEvenTheRightPasswordIsToldToWait) {
  Console console;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(status_of(console.login("ana", "guess " + std::to_string(i))), 401) << i;
  const std::string r = console.login("ana", "ana's password");
  EXPECT_EQ(status_of(r), 429) << r;
  EXPECT_NE(r.find("Retry-After: 60"), std::string::npos) << r;
  EXPECT_NE(body_of(r).find("too many failed logins"), std::string::npos) << r;
}

TEST(WebLogin, ALoginPostedByAnotherSitesPageIsRefused) {
  Console console;
  const std::string r = console.post("/api/login", R"({"user":"ana","password":"ana's password"})",
                                     "Origin: http://evil.example\r\n");
  EXPECT_EQ(status_of(r), 403) << r;
  EXPECT_EQ(r.find("Set-Cookie"), std::string::npos);
}

TEST(WebLogin, ARequestForAnotherHostIsRefused) {
  Console console;
  const std::string r = testing::http_exchange(
      console.port(), "GET /api/session HTTP/1.1\r\nHost: rebound.evil.example\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(status_of(r), 400) << r;
}

TEST(WebLogin, ArtefactsNeedALoginOnceUsersExist) {
  Console console;
  const std::string r = console.get("/api/jobs/j-1764892800123-a3f9/report.json", "");
  EXPECT_EQ(status_of(r), 401) << r;
  const std::string cookie = session_cookie(console.login("vic", "vic's password"));
  EXPECT_EQ(status_of(console.get("/api/jobs/j-1764892800123-a3f9/report.json", cookie)), 404) << "past the login";
}

TEST(WebSocketRpc, NeedsASessionAndThisConsolesOrigin) {
  Console console;
  WsClient anonymous(console.port(), "", console.origin());
  EXPECT_FALSE(anonymous.open());
  EXPECT_EQ(anonymous.status(), 401U);
  const std::string cookie = session_cookie(console.login("ana", "ana's password"));
  WsClient foreign(console.port(), cookie, "http://evil.example");
  EXPECT_FALSE(foreign.open());
  EXPECT_EQ(foreign.status(), 403U);
  WsClient stale(console.port(), "lamina_session=" + std::string(64, 'a'), console.origin());
  EXPECT_EQ(stale.status(), 401U);

  WsClient ws(console.port(), cookie, console.origin());
  ASSERT_TRUE(ws.open()) << ws.status() << " " << ws.refusal();
  const auto reply = ws.call("server.info");
  ASSERT_TRUE(reply.contains("result")) << reply.dump();
  EXPECT_EQ(reply["result"]["user"], "ana");
  EXPECT_EQ(reply["result"]["role"], "operator");
  EXPECT_EQ(reply["result"]["via"], "WebSocket");
}

TEST(WebSocketRpc, LogoutEndsTheSessionForNewConnections) {
  Console console;
  const std::string cookie = session_cookie(console.login("vic", "vic's password"));
  const std::string out = console.post("/api/logout", "", "Cookie: " + cookie + "\r\n");
  EXPECT_EQ(status_of(out), 200) << out;
  EXPECT_NE(out.find("Max-Age=0"), std::string::npos) << out;
  EXPECT_EQ(status_of(console.get("/api/session", cookie)), 401);
  EXPECT_EQ(WsClient(console.port(), cookie, console.origin()).status(), 401U);
}

TEST(WebSocketRpc, ABrowserGetsTheNotificationsItSubscribedTo) {
  Console console;
  const std::string cookie = session_cookie(console.login("vic", "vic's password"));
  WsClient ws(console.port(), cookie, console.origin());
  ASSERT_TRUE(ws.open());
  ASSERT_TRUE(ws.call("server.subscribe").contains("result"));
  console.rpc->broadcast("notify_machine_status", {{"state", "Run"}});
  const auto text = ws.receive();
  ASSERT_TRUE(text);
  const auto note = nlohmann::json::parse(*text);
  EXPECT_EQ(note["method"], "notify_machine_status");
  EXPECT_EQ(note["params"]["state"], "Run");
}

// A console that stops reading while the daemon stops: its write is still pending when the
// io_context goes. The connection and its WebSocket must be freed with it (the pending write's
// handler was kept in the transport, which the connection owns: the sanitizer pass found the
// cycle as a leak).
TEST(WebSocketRpc, AConsoleThatStopsReadingIsFreedWhenTheDaemonStops) {
  std::optional<Console> console(std::in_place);
  const std::string cookie = session_cookie(console->login("vic", "vic's password"));
  WsClient ws(console->port(), cookie, console->origin());
  ASSERT_TRUE(ws.open());
  ASSERT_TRUE(ws.call("server.subscribe").contains("result"));
  // 4 MiB the client never reads: far past what the sockets buffer, short of the 8 MiB limit.
  const std::string chunk(128 * 1024, 'x');
  for (int i = 0; i < 32; ++i) console->rpc->broadcast("notify_log", {{"text", chunk}});
  std::promise<void> queued;  // the broadcasts were posted before this, on the one io thread
  boost::asio::post(console->io, [&queued] { queued.set_value(); });
  ASSERT_EQ(queued.get_future().wait_for(std::chrono::seconds(30)), std::future_status::ready);
  EXPECT_EQ(console->rpc->client_count(), 1U) << "dropped instead of left writing";
  console.reset();  // LeakSanitizer (the sanitizer pass) reports what this leaves behind
}

// The console's first two calls: one for the worker, one inline that overtakes it. Neither reply
// may be lost, and the worker's reply must not undo the subscription (it did: the console then
// never heard of its job again).
TEST(WebSocketRpc, AnInlineSubscribeThatOvertakesAWorkersRequestStays) {
  Console console;
  const std::string cookie = session_cookie(console.login("vic", "vic's password"));
  WsClient ws(console.port(), cookie, console.origin());
  ASSERT_TRUE(ws.open());
  ws.send(R"({"jsonrpc":"2.0","id":1,"method":"slow"})");
  ws.send(R"({"jsonrpc":"2.0","id":2,"method":"server.subscribe"})");
  std::set<int> replies;
  for (int i = 0; i < 2; ++i) {
    const auto text = ws.receive();
    ASSERT_TRUE(text) << "reply " << i + 1 << " of 2 never came; got " << replies.size();
    replies.insert(nlohmann::json::parse(*text)["id"].get<int>());
  }
  EXPECT_EQ(replies, (std::set<int>{1, 2}));
  console.rpc->broadcast("notify_machine_status", {{"state", "Idle"}});
  const auto note = ws.receive();
  ASSERT_TRUE(note) << "subscribed, but no notification came";
  EXPECT_EQ(nlohmann::json::parse(*note)["method"], "notify_machine_status");
}

TEST(WebSocketRpc, AMessageOverTheRequestLimitIsRefusedAsOnEveryTransport) {
  Console console(2048);
  const std::string cookie = session_cookie(console.login("vic", "vic's password"));
  WsClient ws(console.port(), cookie, console.origin());
  ASSERT_TRUE(ws.open());
  // A pretty-printed request spans lines: one message is still one request.
  const auto ok = ws.call("server.info", nlohmann::json{{"a", 1}});
  ASSERT_TRUE(ok.contains("result"));
  ws.send("{\n \"jsonrpc\": \"2.0\",\n \"id\": 7,\n \"method\": \"server.info\"\n}");
  const auto multi = ws.receive();
  ASSERT_TRUE(multi);
  EXPECT_EQ(nlohmann::json::parse(*multi)["id"], 7);
  // One byte over: the connection's own answer. Further over, Beast refuses it unread (1009).
  const std::string head = R"({"jsonrpc":"2.0","id":8,"method":"x","params":{"pad":")", tail = "\"}}";
  ws.send(head + std::string(2049 - head.size() - tail.size(), 'p') + tail);
  const auto refused = ws.receive();
  ASSERT_TRUE(refused);
  EXPECT_NE(refused->find("request too large (2049 bytes, limit 2048)"), std::string::npos) << *refused;
  EXPECT_FALSE(ws.receive()) << "closed after the refusal";

  WsClient huge(console.port(), cookie, console.origin());
  ASSERT_TRUE(huge.open());
  (void)huge.send(std::string(1 << 20, ' '));  // may fail part way: the server hangs up early
  EXPECT_FALSE(huge.receive()) << "closed without reading a MiB";
}

}  // namespace
}  // namespace lamina::daemon::http
