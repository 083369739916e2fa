#include "uploads.hpp"

#include <algorithm>
#include <array>
#include <fstream>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

namespace lamina::daemon {
namespace fs = std::filesystem;

namespace {


bool model_extension(const std::string& name) {
  const auto dot = name.rfind('.');
  if (dot == std::string::npos) return false;
  std::string ext = name.substr(dot + 1);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // STEP and IGES too: the planner child says so if it was built without OpenCASCADE.
  return ext == "stl" || ext == "obj" || ext == "3mf" || ext == "step" || ext == "stp" || ext == "iges" || ext == "igs";
}

// 128 bits from the kernel's generator, as hex: the upload's capability.
std::string random_id() {
  std::array<unsigned char, 16> bytes{};
  std::ifstream urandom("/dev/urandom", std::ios::binary);
  urandom.read(reinterpret_cast<char*>(bytes.data()), bytes.size());
  if (!urandom) throw std::runtime_error("cannot read /dev/urandom");
  std::string id = "u";
  for (unsigned char b : bytes) id += fmt::format("{:02x}", b);
  return id;
}

}  // namespace

std::optional<std::string> decode_base64(std::string_view text) {
  static const std::array<int, 256> table = [] {
    std::array<int, 256> t{};
    t.fill(-1);
    const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(alphabet[i])] = i;
    return t;
  }();
  if (text.size() % 4 != 0) return std::nullopt;
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = text[i + static_cast<std::size_t>(k)];
      if (c == '=') {
        // Padding only in the last group's last two places.
        if (i + 4 != text.size() || k < 2) return std::nullopt;
        v[k] = 0;
        ++pad;
      } else {
        if (pad) return std::nullopt;
        v[k] = table[static_cast<unsigned char>(c)];
        if (v[k] < 0) return std::nullopt;
      }
    }
    const unsigned n = static_cast<unsigned>(v[0] << 18 | v[1] << 12 | v[2] << 6 | v[3]);
    out += static_cast<char>(n >> 16 & 0xFF);
    if (pad < 2) out += static_cast<char>(n >> 8 & 0xFF);
    if (pad < 1) out += static_cast<char>(n & 0xFF);
  }
  return out;
}

Uploads::Uploads(fs::path dir, UploadLimits limits) : dir_(std::move(dir)), limits_(limits) {
  std::error_code ec;
  fs::remove_all(dir_, ec);
  fs::create_directories(dir_, ec);
}

std::expected<std::string, JobError> Uploads::begin(const std::string& file_name, std::uint64_t size_bytes,
                                                    Clock::time_point now) {
  const bool control_char = std::any_of(file_name.begin(), file_name.end(),
                                        [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; });
  if (file_name.empty() || file_name.size() > 200 || file_name.find('/') != std::string::npos || file_name[0] == '.' ||
      control_char)  // a NUL would cut the name on disk short of what the client was told
    return std::unexpected(bad_request("params.name: a plain file name (no folders, no control characters), e.g. part.stl"));
  if (!model_extension(file_name)) return std::unexpected(bad_request("params.name: an .stl, .obj, .3mf, .step, .stp, .iges or .igs file"));
  if (size_bytes == 0 || size_bytes > limits_.max_file_bytes)
    return std::unexpected(bad_request(fmt::format("params.size: 1 … {} bytes", limits_.max_file_bytes)));
  std::lock_guard lock(mutex_);
  expire(now);
  if (open_.size() >= limits_.max_open)
    return std::unexpected(JobError{JobErrorKind::wrong_state,
                                    fmt::format("{} uploads are unfinished already (each is dropped after {} s without "
                                                "a chunk, or by upload.cancel)",
                                                open_.size(), limits_.idle_s)});
  const std::string id = random_id();
  Upload u{dir_ / (id + "-" + file_name), size_bytes, 0, now};
  std::ofstream create(u.path, std::ios::binary | std::ios::trunc);
  if (!create) return std::unexpected(JobError{JobErrorKind::storage, fmt::format("cannot create {}", u.path.string())});
  open_[id] = u;
  return id;
}

void Uploads::expire(Clock::time_point now) {
  const auto idle = std::chrono::duration<double>(limits_.idle_s);
  for (auto it = open_.begin(); it != open_.end();) {
    if (now - it->second.last_activity <= idle) {
      ++it;
      continue;
    }
    std::error_code ec;
    fs::remove(it->second.path, ec);
    it = open_.erase(it);
  }
}

std::expected<Uploads::Upload*, JobError> Uploads::find(const std::string& id, Clock::time_point now) {
  expire(now);
  auto it = open_.find(id);
  // The same answer for an id that never was, expired or was taken: the id is all a client has.
  if (it == open_.end()) return std::unexpected(bad_request(fmt::format("params.upload: no upload {} (unknown, expired or taken)", id)));
  return &it->second;
}

std::expected<std::uint64_t, JobError> Uploads::chunk(const std::string& id, std::uint64_t offset, std::string_view base64,
                                                      Clock::time_point now) {
  auto data = decode_base64(base64);
  if (!data) return std::unexpected(bad_request("params.data: not base64"));
  if (data->empty() || data->size() > limits_.max_chunk_bytes)
    return std::unexpected(bad_request(fmt::format("params.data: 1 … {} bytes per chunk", limits_.max_chunk_bytes)));
  return append(id, offset, *data, now);
}

std::expected<std::uint64_t, JobError> Uploads::append(const std::string& id, std::uint64_t offset,
                                                       std::string_view data, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  auto found = find(id, now);
  if (!found) return std::unexpected(found.error());
  Upload& u = **found;
  // In order: the next chunk, or the last one again (a client retrying after a lost reply).
  if (offset > u.received) return std::unexpected(bad_request(fmt::format("params.offset: {} leaves a gap (received {})", offset, u.received)));
  if (offset + data.size() > u.size)
    return std::unexpected(bad_request(fmt::format("params.offset: the chunk ends past the announced size {}", u.size)));
  std::fstream f(u.path, std::ios::binary | std::ios::in | std::ios::out);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(data.data(), static_cast<std::streamsize>(data.size()));
  if (!f) return std::unexpected(JobError{JobErrorKind::storage, fmt::format("writing {} failed", u.path.string())});
  u.received = std::max(u.received, offset + data.size());
  u.last_activity = now;
  return u.received;
}

std::expected<fs::path, JobError> Uploads::take(const std::string& id, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  auto found = find(id, now);
  if (!found) return std::unexpected(found.error());
  if ((*found)->received != (*found)->size)
    return std::unexpected(bad_request(fmt::format("params.upload: {} of {} bytes received", (*found)->received, (*found)->size)));
  fs::path p = (*found)->path;
  open_.erase(id);
  return p;
}

std::expected<void, JobError> Uploads::cancel(const std::string& id) {
  std::lock_guard lock(mutex_);
  auto it = open_.find(id);
  if (it == open_.end()) return std::unexpected(bad_request(fmt::format("params.upload: no upload {} (unknown, expired or taken)", id)));
  std::error_code ec;
  fs::remove(it->second.path, ec);
  open_.erase(it);
  return {};
}

std::size_t Uploads::open_count() const {
  std::lock_guard lock(mutex_);
  return open_.size();
}

}  // namespace lamina::daemon
