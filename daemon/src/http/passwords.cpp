#include "http/passwords.hpp"

#include <array>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <sodium.h>

namespace lamina::daemon::http {
namespace {

void ensure_sodium() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (sodium_init() < 0) throw std::runtime_error("libsodium cannot be initialised");
  });
}

std::string hex(const unsigned char* data, std::size_t size) {
  std::string out(size * 2 + 1, '\0');
  sodium_bin2hex(out.data(), out.size(), data, size);
  out.pop_back();
  return out;
}

}  // namespace

std::expected<std::string, std::string> hash_password(std::string_view password) {
  ensure_sodium();
  if (password.empty()) return std::unexpected(std::string("the password is empty"));
  std::array<char, crypto_pwhash_argon2id_STRBYTES> out{};
  // libsodium's "interactive" cost (2 passes, 64 MiB): about 0.1 s here, for every guess too.
  if (crypto_pwhash_argon2id_str(out.data(), password.data(), password.size(), crypto_pwhash_argon2id_OPSLIMIT_INTERACTIVE,
                                 crypto_pwhash_argon2id_MEMLIMIT_INTERACTIVE) != 0)
    return std::unexpected(std::string("out of memory while hashing"));
  return std::string(out.data());
}

bool verify_password(const std::string& hash, std::string_view password) {
  ensure_sodium();
  return crypto_pwhash_argon2id_str_verify(hash.c_str(), password.data(), password.size()) == 0;
}

std::expected<void, std::string> check_password_hash(std::string_view hash) {
  if (!hash.starts_with("$argon2id$v=19$m="))
    return std::unexpected(std::string("expected an Argon2id hash (\"$argon2id$v=19$m=…\", from laminad --hash-password)"));
  if (hash.size() >= crypto_pwhash_argon2id_STRBYTES)
    return std::unexpected(fmt::format("the hash is {} characters, longer than an Argon2id string can be", hash.size()));
  return {};
}

std::string random_token() {
  ensure_sodium();
  std::array<unsigned char, 32> bytes{};
  randombytes_buf(bytes.data(), bytes.size());
  return hex(bytes.data(), bytes.size());
}

std::string token_digest(std::string_view token) {
  ensure_sodium();
  std::array<unsigned char, 32> digest{};
  crypto_generichash(digest.data(), digest.size(), reinterpret_cast<const unsigned char*>(token.data()), token.size(),
                     nullptr, 0);
  return hex(digest.data(), digest.size());
}

}  // namespace lamina::daemon::http
