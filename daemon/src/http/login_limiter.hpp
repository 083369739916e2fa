#pragma once
// Bounds password guessing at the web console's login (sans-IO: time is an argument). Failures
// are counted per client address and per user name, so neither one browser trying many names
// nor many addresses trying one name gets more than max_failures guesses per window; past that
// the key is locked out for lockout_s. Memory is bounded: at most max_keys keys are tracked, the
// stalest forgotten first.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace lamina::daemon::http {

struct LoginLimits {
  int max_failures = 5;
  double window_s = 60;
  double lockout_s = 60;
  std::size_t max_keys = 4096;
};

class LoginLimiter {
 public:
  explicit LoginLimiter(LoginLimits limits = {}) : limits_(limits) {}

  // Seconds until this address may try this user again, if it may not now.
  std::optional<double> refused_for(std::string_view address, std::string_view user, double now_s) const;
  void failed(std::string_view address, std::string_view user, double now_s);
  void succeeded(std::string_view address);

 private:
  struct Count {
    int failures = 0;
    double window_start_s = 0;
    double locked_until_s = 0;
  };
  void count_failure(const std::string& key, double now_s);
  std::optional<double> wait_for(const std::string& key, double now_s) const;

  LoginLimits limits_;
  std::map<std::string, Count> counts_;
};

}  // namespace lamina::daemon::http
