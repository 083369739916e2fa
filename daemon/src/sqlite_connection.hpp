#pragma once
// A thin layer over the SQLite C API for the job store: one connection, a cache of prepared
// statements (the hot path re-binds, never re-parses), and transactions that roll back on any
// failure or exception. Values go in only as bound parameters. Not thread-safe: the owner
// serialises every use (JobStore holds a mutex).
#include <sqlite3.h>

#include <cstdint>
#include <expected>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>

#include <fmt/core.h>

#include "lamina/daemon/job_store.hpp"

namespace lamina::daemon::sqlite {

using Fail = std::unexpected<StoreError>;

// A cached prepared statement, leased for one use: bindings are sequential (?1, ?2, …), and the
// statement is reset on destruction so that no read stays open past its transaction. Errors
// name the step (`what`) and carry sqlite3_errmsg; the transaction adds the file.
class Statement {
 public:
  Statement(sqlite3* db, sqlite3_stmt* stmt, std::string_view what) : db_(db), stmt_(stmt), what_(what) {}
  Statement(Statement&& other) noexcept
      : db_(other.db_), stmt_(std::exchange(other.stmt_, nullptr)), what_(other.what_), next_(other.next_),
        bind_rc_(other.bind_rc_) {}
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement& operator=(Statement&&) = delete;
  ~Statement() {
    if (stmt_ == nullptr) return;
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }

  Statement& bind(std::int64_t v) { return note(sqlite3_bind_int64(stmt_, next_++, v)); }
  Statement& bind(int v) { return bind(std::int64_t{v}); }
  Statement& bind(std::size_t v) { return bind(static_cast<std::int64_t>(v)); }
  Statement& bind(double v) { return note(sqlite3_bind_double(stmt_, next_++, v)); }
  Statement& bind(std::string_view v) {
    // A null data pointer would bind NULL, not "".
    return note(sqlite3_bind_text(stmt_, next_++, v.data() != nullptr ? v.data() : "", static_cast<int>(v.size()),
                                  SQLITE_TRANSIENT));
  }
  Statement& bind(const char* v) { return bind(std::string_view{v}); }
  Statement& bind(const std::string& v) { return bind(std::string_view{v}); }
  // SQLite has no unsigned integers: a uint64 is stored as its int64 bit pattern; nullopt → NULL.
  Statement& bind(std::optional<std::uint64_t> v) {
    if (!v) return note(sqlite3_bind_null(stmt_, next_++));
    return bind(static_cast<std::int64_t>(*v));
  }

  // true: a row is ready; false: the statement is done.
  std::expected<bool, StoreError> step() {
    if (bind_rc_ != SQLITE_OK) return Fail(StoreError{fmt::format("{}: bind: {}", what_, sqlite3_errstr(bind_rc_))});
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    return Fail(StoreError{fmt::format("{}: {}", what_, sqlite3_errmsg(db_))});
  }
  std::expected<void, StoreError> run() {
    auto stepped = step();
    if (!stepped) return Fail(stepped.error());
    return {};
  }

  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }
  bool is_null(int col) const { return sqlite3_column_type(stmt_, col) == SQLITE_NULL; }
  std::string text(int col) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, col));
    return p != nullptr ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(stmt_, col))) : std::string();
  }

 private:
  Statement& note(int rc) {
    if (bind_rc_ == SQLITE_OK) bind_rc_ = rc;
    return *this;
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_;
  std::string_view what_;
  int next_ = 1;
  int bind_rc_ = SQLITE_OK;
};

class Connection {
 public:
  explicit Connection(std::filesystem::path path) : path_(std::move(path)) {}
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  ~Connection();

  // Opens (creating) the file; errors without the file name (the caller adds it).
  std::expected<void, StoreError> open(int busy_timeout_ms);
  // The file at path() is still the one opened. SQLite writes on into a deleted (or renamed,
  // or replaced) file without a word, and a restart then finds none of it: every write checks.
  std::expected<void, StoreError> still_the_file() const;
  sqlite3* handle() const { return db_; }
  const std::filesystem::path& path() const { return path_; }

  // `sql` is a literal (the cache key); `what` names the step in an error and must outlive the
  // lease (a literal too).
  std::expected<Statement, StoreError> statement(const char* sql, std::string_view what);
  std::expected<void, StoreError> run(const char* sql, std::string_view what);
  std::expected<std::int64_t, StoreError> single_integer(const char* sql, std::string_view what);
  std::expected<void, StoreError> run_script(const char* sql, std::string_view what);  // constant text only
  // For an update by primary key: `missing` is the error when no row changed.
  std::expected<void, StoreError> run_one(Statement& statement, std::string_view missing);

  // Runs `body` (returning std::expected<T, StoreError>) inside BEGIN … COMMIT, rolled back on
  // any failure or exception. Errors come back as "<file>: <context>: <what failed>".
  enum class Access : bool { read, write };  // a write takes the lock at BEGIN (IMMEDIATE)
  template <typename Body>
  auto transaction(std::string_view context, Access access, Body&& body) -> decltype(body()) {
    const bool write = access == Access::write;
    using Result = decltype(body());
    auto fail = [&](const StoreError& e) {
      return Result(Fail(StoreError{fmt::format("{}: {}: {}", path_.string(), context, e.message)}));
    };
    if (write)
      if (auto same = still_the_file(); !same) return fail(same.error());
    // Reads take a deferred BEGIN: a consistent snapshot without taking the write lock.
    if (auto begun = run(write ? "BEGIN IMMEDIATE" : "BEGIN", "begin a transaction"); !begun)
      return fail(begun.error());
    struct Rollback {
      sqlite3* db;
      bool armed = true;
      ~Rollback() {
        // A failed COMMIT may leave the transaction open (SQLITE_BUSY) or already rolled back.
        if (armed && sqlite3_get_autocommit(db) == 0) sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
      }
    } rollback{db_};
    Result result = body();
    if (!result) return fail(result.error());
    if (auto committed = run("COMMIT", "commit"); !committed) return fail(committed.error());
    rollback.armed = false;
    return result;
  }

 private:
  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
  std::uint64_t device_ = 0, inode_ = 0;
  std::unordered_map<std::string_view, sqlite3_stmt*> cache_;  // keyed by the SQL literal
};

}  // namespace lamina::daemon::sqlite
