#pragma once
// Models sent over the socket in chunks (job.submit with an upload) for clients that are not on
// the cell PC: upload.begin names the file and its size, upload.chunk appends base64 pieces at
// their offset (in order; a repeated chunk is accepted again, a gap is refused), and job.submit
// takes the finished file. Files live in <state_dir>/uploads until a job takes them; the folder
// is emptied at start-up (an upload does not survive the daemon).
//
// An upload's id is its capability: 128 random bits, so no other client can add to, take or
// cancel it. One that has had no chunk for `idle_s` is dropped (its slot and file freed) —
// a client that vanished mid-upload must not hold one of the slots until the next restart.
// Time is an argument (as in sim::Machine), so the expiry is tested without waiting.
#include <chrono>
#include <cstdint>
#include <expected>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

#include "job_error.hpp"

#include <optional>

namespace lamina::daemon {

struct UploadLimits {
  std::uint64_t max_file_bytes = 512ull << 20;   // a 10M-triangle binary STL is 500 MB
  std::size_t max_chunk_bytes = 512 << 10;       // decoded; base64 makes it 683 kB, under the line limit
  std::size_t max_open = 16;                     // unfinished uploads at once
  double idle_s = 600;                           // no chunk this long: dropped
};

class Uploads {
 public:
  using Clock = std::chrono::steady_clock;
  Uploads(std::filesystem::path dir, UploadLimits limits = {});
  std::expected<std::string, JobError> begin(const std::string& file_name, std::uint64_t size_bytes,
                                             Clock::time_point now = Clock::now());
  // Returns the bytes received so far.
  std::expected<std::uint64_t, JobError> chunk(const std::string& id, std::uint64_t offset, std::string_view base64,
                                               Clock::time_point now = Clock::now());
  // The same with the bytes as they are (the web console's POST body, read in pieces).
  std::expected<std::uint64_t, JobError> append(const std::string& id, std::uint64_t offset, std::string_view bytes,
                                                Clock::time_point now = Clock::now());
  // The complete file (the upload is forgotten; the caller moves or deletes the file).
  std::expected<std::filesystem::path, JobError> take(const std::string& id, Clock::time_point now = Clock::now());
  // Drops an unfinished (or finished, not yet taken) upload and its file.
  std::expected<void, JobError> cancel(const std::string& id);
  std::size_t open_count() const;

 private:
  struct Upload {
    std::filesystem::path path;
    std::uint64_t size = 0, received = 0;
    Clock::time_point last_activity;
  };
  void expire(Clock::time_point now);  // under mutex_
  std::expected<Upload*, JobError> find(const std::string& id, Clock::time_point now);  // under mutex_

  std::filesystem::path dir_;
  UploadLimits limits_;
  mutable std::mutex mutex_;
  std::map<std::string, Upload> open_;
};

// RFC 4648 base64 (no line breaks); nullopt on a character outside the alphabet or bad padding.
std::optional<std::string> decode_base64(std::string_view text);

}  // namespace lamina::daemon
