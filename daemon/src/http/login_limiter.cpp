#include "http/login_limiter.hpp"

#include <algorithm>

namespace lamina::daemon::http {
namespace {

std::string address_key(std::string_view address) { return "a:" + std::string(address); }
std::string user_key(std::string_view user) { return "u:" + std::string(user); }

}  // namespace

std::optional<double> LoginLimiter::wait_for(const std::string& key, double now_s) const {
  const auto it = counts_.find(key);
  if (it == counts_.end() || it->second.locked_until_s <= now_s) return std::nullopt;
  return it->second.locked_until_s - now_s;
}

std::optional<double> LoginLimiter::refused_for(std::string_view address, std::string_view user, double now_s) const {
  const auto a = wait_for(address_key(address), now_s);
  const auto u = wait_for(user_key(user), now_s);
  if (!a) return u;
  if (!u) return a;
  return std::max(*a, *u);
}

void LoginLimiter::count_failure(const std::string& key, double now_s) {
  if (!counts_.contains(key) && counts_.size() >= limits_.max_keys) {
    const auto stalest = std::min_element(counts_.begin(), counts_.end(), [](const auto& x, const auto& y) {
      return std::max(x.second.window_start_s, x.second.locked_until_s) <
             std::max(y.second.window_start_s, y.second.locked_until_s);
    });
    counts_.erase(stalest);
  }
  Count& c = counts_[key];
  if (now_s - c.window_start_s >= limits_.window_s) c = Count{0, now_s, c.locked_until_s};
  if (++c.failures >= limits_.max_failures) {
    c.locked_until_s = now_s + limits_.lockout_s;
    c.failures = 0;
    c.window_start_s = c.locked_until_s;
  }
}

void LoginLimiter::failed(std::string_view address, std::string_view user, double now_s) {
  count_failure(address_key(address), now_s);
  count_failure(user_key(user), now_s);
}

// The address is cleared, the name is not: someone guessing a name from elsewhere keeps their
// count when its owner logs in.
void LoginLimiter::succeeded(std::string_view address) { counts_.erase(address_key(address)); }

}  // namespace lamina::daemon::http
