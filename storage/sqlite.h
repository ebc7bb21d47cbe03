// A small RAII layer over SQLite's C API: Database (a connection), Statement (a prepared statement,
// cached per connection) and Transaction (BEGIN IMMEDIATE … COMMIT, rolled back unless committed).
//
// Every SQLite failure becomes a Status that names the database file, the SQL operation and
// SQLite's own message, plus what to do about it:
//   SQLITE_FULL, SQLITE_READONLY*, SQLITE_IOERR*, SQLITE_CANTOPEN, SQLITE_NOMEM → kIoError with a
//       hint (free disk space; check permissions of the file AND its directory — WAL mode creates
//       <file>-wal and <file>-shm next to it);
//   SQLITE_CORRUPT, SQLITE_NOTADB → kIoError with an integrity-check hint;
//   SQLITE_CONSTRAINT_UNIQUE / _PRIMARYKEY → kFailedPrecondition (the row already exists);
//   other SQLITE_CONSTRAINT_* (foreign key, check, not null), SQLITE_TOOBIG, SQLITE_RANGE →
//       kInvalidArgument;
//   SQLITE_BUSY / SQLITE_LOCKED → kTimeout (another connection held the lock past busy_timeout);
//   anything else (SQL errors, misuse) → kInternal: a bug of ours.
//
// Threading: a Database and its Statements are used by one thread at a time (callers serialise;
// SessionStore holds a mutex for its writer and leases reader connections). Never share a
// connection across fork(): open a new one in the child.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "core/status.h"

struct sqlite3;
struct sqlite3_stmt;

namespace brdf::storage {

class Database;

// Builds the Status for SQLite result code `rc` (extended codes understood) on the database file
// at `path`, for `operation` (what we were doing: the SQL or "opening"). `sqlite_message` is
// sqlite3_errmsg() at the time of the failure.
Status SqliteStatus(int rc, std::string_view path, std::string_view operation,
                    std::string_view sqlite_message);

// A prepared statement. Obtained from Database::Prepare, which caches the compiled statement: when
// a Statement is destroyed it is reset, its bindings cleared, and it goes back to the cache.
// A Statement must not outlive its Database.
//
// Binding never fails loudly: Bind records the first error (bad parameter name, out of range) and
// Step()/Run() return it, so a call site reads as a list of binds followed by one checked Step.
class Statement {
 public:
  // Bytes of a BLOB parameter or column.
  using Blob = std::span<const std::uint8_t>;

  Statement() = default;
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&& other) noexcept;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  ~Statement();

  // Binds parameter `index` (1-based, as in SQLite) or a named parameter (":name", "@name",
  // "$name", spelled with its prefix). Supported: integers and bool (INTEGER), floating point
  // (REAL), anything convertible to std::string_view (TEXT, copied), Blob (BLOB, copied),
  // std::nullopt / nullptr (NULL), std::optional<T> of those (NULL when empty).
  template <typename T>
  Statement& Bind(int index, const T& value);
  template <typename T>
  Statement& Bind(std::string_view name, const T& value) {
    return Bind(ParameterIndex(name), value);
  }

  // Advances: true when a row is available, false when the statement has finished.
  Result<bool> Step();
  // Steps a statement that returns no rows (INSERT, UPDATE, DDL) to completion.
  Status Run();
  // Rewinds the statement and clears its bindings (and any recorded bind error) for another use.
  void Reset();

  // Columns of the current row, 0-based. A NULL reads as 0, 0.0, "" or an empty blob; use IsNull
  // or the Optional* variants where NULL is meaningful.
  int ColumnCount() const;
  bool IsNull(int column) const;
  std::int64_t Int64(int column) const;
  int Int(int column) const;
  double Double(int column) const;
  std::string Text(int column) const;
  // The BLOB's bytes; valid until the next Step, Reset or destruction.
  Blob BlobView(int column) const;
  std::optional<std::int64_t> OptionalInt64(int column) const;
  std::optional<double> OptionalDouble(int column) const;
  std::optional<std::string> OptionalText(int column) const;

  const std::string& sql() const { return sql_; }
  bool valid() const { return stmt_ != nullptr; }

 private:
  friend class Database;
  Statement(Database* db, sqlite3_stmt* stmt, std::string sql)
      : db_(db), stmt_(stmt), sql_(std::move(sql)) {}

  int ParameterIndex(std::string_view name);
  void BindInt64(int index, std::int64_t v);
  void BindDouble(int index, double v);
  void BindText(int index, std::string_view v);
  void BindBlob(int index, Blob v);
  void BindNull(int index);
  void NoteBindResult(int rc, int index);
  void Release();

  Database* db_ = nullptr;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
  Status bind_error_;
};

struct OpenOptions {
  // Open without write access (SQLITE_OPEN_READONLY). Writes then fail with kIoError.
  bool read_only = false;
  // Create the file when missing (ignored when read_only).
  bool create = true;
  // How long a statement waits for another connection's lock before failing with kTimeout.
  std::chrono::milliseconds busy_timeout{5000};
  // Upper bound on the database size in pages (PRAGMA max_page_count; 0 = SQLite's default). A
  // quota on a shared disk; writes beyond it fail exactly like a full disk (kIoError).
  std::int64_t max_page_count = 0;
};

// One SQLite connection. Opening applies, in order: busy_timeout, journal_mode=WAL (readers never
// block the writer and a crash never leaves a half-written page in the main file),
// synchronous=FULL (a committed transaction survives power loss, not only a process crash) and
// foreign_keys=ON. A file that the OS lets us open only for reading, when `read_only` was not
// asked for, is refused with kIoError at open rather than at the first write.
class Database {
 public:
  static Result<std::unique_ptr<Database>> Open(const std::string& path,
                                                const OpenOptions& options = {});
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  const std::string& path() const { return path_; }

  // A prepared statement for `sql` (one statement), from this connection's cache when possible.
  Result<Statement> Prepare(std::string_view sql);
  // Runs one or more statements that return no rows (DDL, PRAGMA settings, migrations).
  Status Exec(std::string_view sql);
  // Runs a single-value query ("PRAGMA user_version", "SELECT count(*) …") and returns the value.
  Result<std::int64_t> QueryInt64(std::string_view sql);
  Result<std::string> QueryText(std::string_view sql);

  std::int64_t last_insert_rowid() const;
  // Rows changed by the last INSERT/UPDATE/DELETE on this connection.
  int changes() const;
  // True while an explicit transaction is open (false after SQLite rolled one back on its own).
  bool in_transaction() const;

  // The Status for result code `rc` of `operation` on this connection (uses sqlite3_errmsg).
  Status Error(int rc, std::string_view operation) const;

  sqlite3* handle() const { return db_; }

 private:
  friend class Statement;
  Database(sqlite3* db, std::string path) : db_(db), path_(std::move(path)) {}
  Status Configure(const OpenOptions& options);
  // Takes back a statement released by a Statement (reset and cleared by the caller).
  void ReturnToCache(std::string sql, sqlite3_stmt* stmt);

  sqlite3* db_ = nullptr;
  std::string path_;
  std::unordered_map<std::string, sqlite3_stmt*> cache_;
};

// BEGIN IMMEDIATE … COMMIT. IMMEDIATE takes the write lock up front, so a transaction that reads
// then writes can never fail half-way with SQLITE_BUSY. If the Transaction is destroyed without a
// successful Commit() (an early return on error), it rolls back: nothing partial persists.
// Transactions do not nest.
class Transaction {
 public:
  static Result<Transaction> Begin(Database& db);
  // BEGIN DEFERRED, for readers: the queries until Commit() all see one consistent snapshot (the
  // one taken at the first read), however many writes other connections commit meanwhile.
  static Result<Transaction> BeginRead(Database& db);
  Transaction(Transaction&& other) noexcept : db_(other.db_) { other.db_ = nullptr; }
  Transaction& operator=(Transaction&&) = delete;
  Transaction(const Transaction&) = delete;
  ~Transaction();

  // Commits. On failure the transaction is rolled back (by SQLite or by us) and the Status says
  // why.
  Status Commit();
  // Rolls back now (also what the destructor does).
  void Rollback();
  bool active() const { return db_ != nullptr; }

 private:
  explicit Transaction(Database* db) : db_(db) {}
  Database* db_;
};

// --- Implementation of the Bind template ---------------------------------------------------------

namespace internal {
template <typename T>
struct IsOptional : std::false_type {};
template <typename T>
struct IsOptional<std::optional<T>> : std::true_type {};
template <typename>
inline constexpr bool kAlwaysFalse = false;
}  // namespace internal

template <typename T>
Statement& Statement::Bind(int index, const T& value) {
  using V = std::remove_cvref_t<T>;
  if constexpr (internal::IsOptional<V>::value) {
    if (value.has_value()) return Bind(index, *value);
    BindNull(index);
  } else if constexpr (std::is_same_v<V, std::nullopt_t> || std::is_same_v<V, std::nullptr_t>) {
    BindNull(index);
  } else if constexpr (std::is_same_v<V, bool>) {
    BindInt64(index, value ? 1 : 0);
  } else if constexpr (std::is_integral_v<V>) {
    BindInt64(index, static_cast<std::int64_t>(value));
  } else if constexpr (std::is_floating_point_v<V>) {
    BindDouble(index, static_cast<double>(value));
  } else if constexpr (std::is_convertible_v<const V&, Blob>) {
    BindBlob(index, Blob(value));
  } else if constexpr (std::is_convertible_v<const V&, std::string_view>) {
    BindText(index, std::string_view(value));
  } else {
    static_assert(internal::kAlwaysFalse<V>, "Statement::Bind: unsupported type");
  }
  return *this;
}

}  // namespace brdf::storage
