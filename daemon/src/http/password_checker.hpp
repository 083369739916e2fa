#pragma once
// Runs the login's Argon2id checks (~0.1 s of CPU and 64 MiB each) on a thread of their own at
// a lowered priority, so that neither the io thread nor the cut waits for a login. At most
// max_pending checks wait; beyond that a login is told the server is busy.
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/any_io_executor.hpp>

namespace lamina::daemon::http {

class PasswordChecker {
 public:
  explicit PasswordChecker(std::size_t max_pending = 8);
  ~PasswordChecker();  // waits for the check running now; the waiting ones are dropped
  PasswordChecker(const PasswordChecker&) = delete;
  PasswordChecker& operator=(const PasswordChecker&) = delete;

  // False (and `done` is never called) when max_pending checks wait already. Otherwise `done`
  // runs on `reply_on` with the verdict.
  bool check(std::string hash, std::string password, boost::asio::any_io_executor reply_on,
             std::function<void(bool matches)> done);

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace lamina::daemon::http
