#pragma once
// Who is logged in to the web console (sans-IO: time is an argument). A session is a random
// token in the browser's cookie; the table keeps only the token's digest, so neither a memory
// dump nor the timing of a lookup gives a live token away. Sessions end at a fixed lifetime
// (a shift, by default), at logout, and the oldest goes when the table is full.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "lamina/daemon/rpc_server.hpp"

namespace lamina::daemon::http {

struct LoginSession {
  std::string user;
  Role role = Role::viewer;
  double expires_s = 0;  // on the clock the caller passes
};

class SessionTable {
 public:
  SessionTable(double lifetime_s, std::size_t max_sessions) : lifetime_s_(lifetime_s), max_sessions_(max_sessions) {}

  // A new session; the token goes to the browser and nowhere else.
  std::string open(std::string user, Role role, double now_s);
  std::optional<LoginSession> find(std::string_view token, double now_s);  // drops it if expired
  void close(std::string_view token);
  std::size_t size() const { return by_digest_.size(); }
  double lifetime_s() const { return lifetime_s_; }

 private:
  void drop_expired(double now_s);

  double lifetime_s_;
  std::size_t max_sessions_;
  std::map<std::string, LoginSession> by_digest_;
};

}  // namespace lamina::daemon::http
