// A small RAII layer over libpq for the lab's archive (PostgreSQL): PgConnection (one connection),
// PgResult (one result, freed on destruction) and PgParams (text parameters, NULLs and bytea).
//
// Every failure becomes a Status naming what we were doing and PostgreSQL's own message:
//   no connection, a dropped connection, the server shutting down, out of resources such as a
//       full disk (no SQLSTATE, or SQLSTATE class 08, 57, 53, 58) → kDisconnected (try later);
//   a unique violation (23505) → kFailedPrecondition; other integrity violations (class 23) and
//       bad values (class 22) → kInvalidArgument;
//   authentication failures (class 28, a wrong password) → kConfigurationError;
//   anything else → kInternal.
// Messages never include the conninfo: it may hold a password.
//
// Threading: a connection is used by one thread at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"

struct pg_conn;
struct pg_result;

namespace brdf::storage {

// One query's result. Text format: values come back as PostgreSQL prints them (float8 as the
// shortest text that reads back to the same double, PostgreSQL 12 and later).
class PgResult {
 public:
  explicit PgResult(pg_result* result) : result_(result) {}
  PgResult(PgResult&& other) noexcept;
  PgResult& operator=(PgResult&& other) noexcept;
  PgResult(const PgResult&) = delete;
  PgResult& operator=(const PgResult&) = delete;
  ~PgResult();

  int rows() const;
  int columns() const;
  bool IsNull(int row, int column) const;
  std::string_view Text(int row, int column) const;
  std::int64_t Int64(int row, int column) const;
  double Double(int row, int column) const;
  std::optional<double> OptionalDouble(int row, int column) const;
  std::optional<std::int64_t> OptionalInt64(int row, int column) const;
  std::optional<std::string> OptionalText(int row, int column) const;
  // A bytea column (text format "\x…" hex) as bytes.
  std::vector<std::uint8_t> Bytes(int row, int column) const;
  // The number of rows an INSERT/UPDATE/DELETE touched.
  std::int64_t affected() const;

 private:
  pg_result* result_ = nullptr;
};

// Parameters for one statement, in order ($1, $2, …). Numbers are sent as text that reads back
// exactly (doubles with 17 significant digits); bytes as binary bytea.
class PgParams {
 public:
  PgParams& Add(std::string_view text);
  PgParams& Add(const char* text) { return Add(std::string_view(text)); }
  PgParams& Add(const std::string& text) { return Add(std::string_view(text)); }
  PgParams& Add(std::int64_t v);
  PgParams& Add(int v) { return Add(static_cast<std::int64_t>(v)); }
  PgParams& Add(double v);
  PgParams& Add(bool v);
  PgParams& AddBytes(std::span<const std::uint8_t> bytes);
  PgParams& AddNull();
  template <typename T>
  PgParams& Add(const std::optional<T>& v) {
    return v.has_value() ? Add(*v) : AddNull();
  }

  int size() const { return static_cast<int>(values_.size()); }
  const char* const* values() const { return pointers_.data(); }
  const int* lengths() const { return lengths_.data(); }
  const int* formats() const { return formats_.data(); }
  // Fixes the pointers once every value is added (PgConnection calls it).
  void Seal();

 private:
  std::vector<std::string> values_;
  std::vector<bool> null_;
  std::vector<const char*> pointers_;
  std::vector<int> lengths_;
  std::vector<int> formats_;
};

class PgConnection {
 public:
  // Connects with a libpq conninfo ("host=… dbname=… user=… password=… sslmode=…" or a
  // postgresql:// URI). connect_timeout defaults to 5 s unless the conninfo sets it.
  // kDisconnected when the server cannot be reached, kConfigurationError when it refuses us.
  static Result<std::unique_ptr<PgConnection>> Open(const std::string& conninfo);
  ~PgConnection();
  PgConnection(const PgConnection&) = delete;
  PgConnection& operator=(const PgConnection&) = delete;

  // Runs one or more statements without parameters.
  Status Exec(std::string_view sql);
  // Runs one statement with parameters; the result (rows or none).
  Result<PgResult> Query(std::string_view sql, PgParams params = PgParams());
  // Prepares `sql` once per connection under `name`, then runs it.
  Result<PgResult> QueryPrepared(const std::string& name, std::string_view sql, PgParams params);

  // False after the server went away (the connection must be opened again).
  bool healthy() const;
  // The server's version number (e.g. 150005).
  int server_version() const;

 private:
  explicit PgConnection(pg_conn* conn) : conn_(conn) {}
  Result<PgResult> Check(pg_result* result, std::string_view what);

  pg_conn* conn_ = nullptr;
  std::vector<std::string> prepared_;
};

// A transaction: BEGIN now, ROLLBACK on destruction unless committed.
class PgTransaction {
 public:
  static Result<PgTransaction> Begin(PgConnection& conn);
  PgTransaction(PgTransaction&& other) noexcept : conn_(other.conn_) { other.conn_ = nullptr; }
  PgTransaction& operator=(PgTransaction&&) = delete;
  ~PgTransaction();
  Status Commit();

 private:
  explicit PgTransaction(PgConnection* conn) : conn_(conn) {}
  PgConnection* conn_;
};

// Reads a libpq conninfo from a credentials file (its first non-empty, non-# line, trimmed).
// kNotFound / kIoError naming the file (never its content) when it cannot be read; kInvalidArgument
// when it is empty.
Result<std::string> ReadConninfoFile(const std::string& path);

}  // namespace brdf::storage
