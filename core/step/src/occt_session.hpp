#pragma once
// What the reader needs around OpenCASCADE: its messages caught (OCCT prints its reader's
// complaints on stdout, where the CLI writes JSON) and its long loops stopped at a deadline.
#include <Message_Gravity.hxx>
#include <Message_ProgressIndicator.hxx>

#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace lamina::step_detail {

// While alive, OCCT's default messenger prints into this instead of stdout. One at a time
// (the messenger is global): a second reader waits for the first.
class CaughtMessages {
 public:
  CaughtMessages();
  ~CaughtMessages();
  CaughtMessages(const CaughtMessages&) = delete;
  CaughtMessages& operator=(const CaughtMessages&) = delete;

  // Warnings and worse, each text once with its count, in the order first seen.
  struct Message {
    std::string text;
    Message_Gravity gravity;
    std::size_t count;
  };
  std::vector<Message> messages() const;

 private:
  std::unique_lock<std::mutex> lock_;
};

// A progress indicator that only answers "stop" once the deadline has passed.
class Deadline : public Message_ProgressIndicator {
 public:
  explicit Deadline(double seconds)
      : end_(std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                    std::chrono::duration<double>(seconds))) {}
  bool passed() const { return std::chrono::steady_clock::now() > end_; }
  Standard_Boolean UserBreak() override { return passed(); }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}

 private:
  std::chrono::steady_clock::time_point end_;
};

}  // namespace lamina::step_detail
