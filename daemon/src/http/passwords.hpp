#pragma once
// The web console's secrets, through libsodium: passwords as Argon2id hashes (the PHC string
// "$argon2id$v=19$m=…,t=…,p=…$salt$hash" that `laminad --hash-password` prints), session tokens
// as 256 random bits. Hashing and verifying take ~0.1 s and 64 MiB by design: never on the io
// thread (the login runs them on a thread of its own).
#include <expected>
#include <string>
#include <string_view>

namespace lamina::daemon::http {

std::expected<std::string, std::string> hash_password(std::string_view password);
bool verify_password(const std::string& hash, std::string_view password);
// For the config: is this an Argon2id PHC string libsodium can verify? (The reason if not.)
std::expected<void, std::string> check_password_hash(std::string_view hash);

std::string random_token();                          // 64 hex digits
std::string token_digest(std::string_view token);    // what the session table keeps (BLAKE2b, hex)

}  // namespace lamina::daemon::http
