#pragma once
// Hands values from a thread that must never wait (the link's io thread) to a callback that may
// be slow (a progress record written to SQLite with a full sync: seconds on a busy disk), on a
// thread of its own. Only the newest value counts: one posted while the callback runs replaces
// any older one still waiting. The fault campaign found the slow callback on the io thread: the
// stream stopped while it ran and the machine stood Idle with the jet on.
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace lamina::drivers::detail {

template <typename T>
class LatestRelay {
 public:
  explicit LatestRelay(std::function<void(const T&)> callback) : callback_(std::move(callback)) {
    thread_ = std::thread([this] { run(); });
  }
  ~LatestRelay() { close(); }
  // Waits for a callback in progress, drops a value not delivered yet: once this returns the
  // callback never runs again, and post() does nothing. Not from the callback itself.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closing_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  LatestRelay(const LatestRelay&) = delete;
  LatestRelay& operator=(const LatestRelay&) = delete;

  void post(T value) {  // never waits for the callback
    {
      std::lock_guard lock(mutex_);
      if (closing_) return;
      pending_ = std::move(value);
    }
    wake_.notify_one();
  }

 private:
  void run() {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return closing_ || pending_; });
      if (closing_) return;
      T value = std::move(*pending_);
      pending_.reset();
      lock.unlock();
      callback_(value);
      lock.lock();
    }
  }

  std::function<void(const T&)> callback_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<T> pending_;
  bool closing_ = false;
  std::thread thread_;
};

}  // namespace lamina::drivers::detail
