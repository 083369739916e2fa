#include "http/session_table.hpp"

#include <algorithm>

#include "http/passwords.hpp"

namespace lamina::daemon::http {

std::string SessionTable::open(std::string user, Role role, double now_s) {
  drop_expired(now_s);
  if (by_digest_.size() >= max_sessions_) {  // the one nearest its end makes room
    const auto oldest = std::min_element(by_digest_.begin(), by_digest_.end(), [](const auto& a, const auto& b) {
      return a.second.expires_s < b.second.expires_s;
    });
    by_digest_.erase(oldest);
  }
  std::string token = random_token();
  by_digest_[token_digest(token)] = LoginSession{std::move(user), role, now_s + lifetime_s_};
  return token;
}

std::optional<LoginSession> SessionTable::find(std::string_view token, double now_s) {
  if (token.empty()) return std::nullopt;
  const auto it = by_digest_.find(token_digest(token));
  if (it == by_digest_.end()) return std::nullopt;
  if (it->second.expires_s <= now_s) {
    by_digest_.erase(it);
    return std::nullopt;
  }
  return it->second;
}

void SessionTable::close(std::string_view token) { by_digest_.erase(token_digest(token)); }

void SessionTable::drop_expired(double now_s) {
  std::erase_if(by_digest_, [now_s](const auto& entry) { return entry.second.expires_s <= now_s; });
}

}  // namespace lamina::daemon::http
