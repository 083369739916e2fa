#include "sqlite_connection.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace lamina::daemon::sqlite {

Connection::~Connection() {
  for (auto& [sql, stmt] : cache_) sqlite3_finalize(stmt);
  sqlite3_close(db_);  // the last connection checkpoints the WAL
}

std::expected<void, StoreError> Connection::open(int busy_timeout_ms) {
  // NOMUTEX: the owner serialises every use of the connection.
  if (sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                      nullptr) != SQLITE_OK)
    return Fail(StoreError{db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory"});
  // Another process (the CLI, a backup) may hold the lock for a moment.
  sqlite3_busy_timeout(db_, busy_timeout_ms);
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0) return Fail(StoreError{fmt::format("stat: {}", std::strerror(errno))});
  device_ = st.st_dev;
  inode_ = st.st_ino;
  return {};
}

std::expected<void, StoreError> Connection::still_the_file() const {
  struct stat st {};
  if (::stat(path_.c_str(), &st) != 0)
    return Fail(StoreError{fmt::format("the database file is gone ({}): it was deleted under the running daemon",
                                       std::strerror(errno))});
  if (st.st_dev != device_ || st.st_ino != inode_)
    return Fail(StoreError{"the database file was replaced under the running daemon (another file has its name)"});
  return {};
}

std::expected<Statement, StoreError> Connection::statement(const char* sql, std::string_view what) {
  auto found = cache_.find(sql);
  if (found == cache_.end()) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v3(db_, sql, -1, SQLITE_PREPARE_PERSISTENT, &stmt, nullptr) != SQLITE_OK)
      return Fail(StoreError{fmt::format("{} (prepare): {}", what, sqlite3_errmsg(db_))});
    found = cache_.emplace(sql, stmt).first;
  }
  return Statement(db_, found->second, what);
}

std::expected<void, StoreError> Connection::run(const char* sql, std::string_view what) {
  auto stmt = statement(sql, what);
  if (!stmt) return Fail(stmt.error());
  return stmt->run();
}

std::expected<std::int64_t, StoreError> Connection::single_integer(const char* sql, std::string_view what) {
  auto stmt = statement(sql, what);
  if (!stmt) return Fail(stmt.error());
  auto row = stmt->step();
  if (!row) return Fail(row.error());
  if (!*row) return Fail(StoreError{fmt::format("{}: no result", what)});
  return stmt->integer(0);
}

std::expected<void, StoreError> Connection::run_script(const char* sql, std::string_view what) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    StoreError error{fmt::format("{}: {}", what, message != nullptr ? message : sqlite3_errmsg(db_))};
    sqlite3_free(message);
    return Fail(error);
  }
  return {};
}

std::expected<void, StoreError> Connection::run_one(Statement& statement, std::string_view missing) {
  if (auto done = statement.run(); !done) return done;
  if (sqlite3_changes(db_) != 1) return Fail(StoreError{std::string(missing)});
  return {};
}

}  // namespace lamina::daemon::sqlite
