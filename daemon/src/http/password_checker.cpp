#include "http/password_checker.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <sodium.h>

#include "http/passwords.hpp"

namespace lamina::daemon::http {

struct PasswordChecker::Impl {
  explicit Impl(std::size_t max) : max_pending(max), guard(work.get_executor()) {}
  std::size_t max_pending;
  std::atomic<std::size_t> pending{0};
  boost::asio::io_context work;
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> guard;
  std::thread thread;
};

PasswordChecker::PasswordChecker(std::size_t max_pending) : impl_(std::make_shared<Impl>(max_pending)) {
  impl_->thread = std::thread([impl = impl_.get()] {
    // Linux nice values are per thread: a guessing browser gets the CPU the cut leaves over.
    ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 10);
    impl->work.run();
  });
}

PasswordChecker::~PasswordChecker() {
  impl_->guard.reset();
  impl_->work.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

bool PasswordChecker::check(std::string hash, std::string password, boost::asio::any_io_executor reply_on,
                            std::function<void(bool)> done) {
  if (impl_->pending.fetch_add(1) >= impl_->max_pending) {
    --impl_->pending;
    return false;
  }
  boost::asio::post(impl_->work, [impl = impl_, hash = std::move(hash), password = std::move(password),
                                  reply_on = std::move(reply_on), done = std::move(done)]() mutable {
    const bool matches = verify_password(hash, password);
    sodium_memzero(password.data(), password.size());
    --impl->pending;
    boost::asio::post(reply_on, [done = std::move(done), matches] { done(matches); });
  });
  return true;
}

}  // namespace lamina::daemon::http
