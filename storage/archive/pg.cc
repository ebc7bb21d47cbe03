#include "storage/archive/pg.h"

#include <libpq-fe.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <utility>

namespace brdf::storage {
namespace {

std::string Trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  std::size_t start = 0;
  while (start < s.size() && (s[start] == ' ' || s[start] == '\t')) ++start;
  return s.substr(start);
}

Status FromSqlState(const char* sqlstate, const std::string& message) {
  const std::string state = sqlstate != nullptr ? sqlstate : "";
  const std::string cls = state.substr(0, std::min<std::size_t>(2, state.size()));
  if (state.empty() || cls == "08" || cls == "57" || cls == "53" || cls == "58") {
    return Disconnected(message +
                        " (the archive is unreachable or out of resources; brdfd "
                        "keeps the data and tries again)");
  }
  if (state == "23505") return FailedPrecondition(message);
  if (cls == "23" || cls == "22") return InvalidArgument(message);
  if (cls == "28") {
    return ConfigurationError(message +
                              " (check the user and password in the archive's "
                              "credentials file)");
  }
  return Internal(message);
}

std::string OneLine(const char* text) {
  std::string s = text != nullptr ? text : "";
  std::replace(s.begin(), s.end(), '\n', ' ');
  return Trim(s);
}

}  // namespace

// --- PgResult ---------------------------------------------------------------------------------

PgResult::PgResult(PgResult&& other) noexcept : result_(std::exchange(other.result_, nullptr)) {}
PgResult& PgResult::operator=(PgResult&& other) noexcept {
  if (this != &other) {
    if (result_ != nullptr) PQclear(result_);
    result_ = std::exchange(other.result_, nullptr);
  }
  return *this;
}
PgResult::~PgResult() {
  if (result_ != nullptr) PQclear(result_);
}
int PgResult::rows() const {
  return PQntuples(result_);
}
int PgResult::columns() const {
  return PQnfields(result_);
}
bool PgResult::IsNull(int row, int column) const {
  return PQgetisnull(result_, row, column) != 0;
}
std::string_view PgResult::Text(int row, int column) const {
  return std::string_view(PQgetvalue(result_, row, column),
                          static_cast<std::size_t>(PQgetlength(result_, row, column)));
}
std::int64_t PgResult::Int64(int row, int column) const {
  return std::strtoll(PQgetvalue(result_, row, column), nullptr, 10);
}
double PgResult::Double(int row, int column) const {
  return std::strtod(PQgetvalue(result_, row, column), nullptr);
}
std::optional<double> PgResult::OptionalDouble(int row, int column) const {
  if (IsNull(row, column)) return std::nullopt;
  return Double(row, column);
}
std::optional<std::int64_t> PgResult::OptionalInt64(int row, int column) const {
  if (IsNull(row, column)) return std::nullopt;
  return Int64(row, column);
}
std::optional<std::string> PgResult::OptionalText(int row, int column) const {
  if (IsNull(row, column)) return std::nullopt;
  return std::string(Text(row, column));
}
std::vector<std::uint8_t> PgResult::Bytes(int row, int column) const {
  std::size_t n = 0;
  unsigned char* raw =
      PQunescapeBytea(reinterpret_cast<const unsigned char*>(PQgetvalue(result_, row, column)), &n);
  if (raw == nullptr) return {};
  std::vector<std::uint8_t> out(raw, raw + n);
  PQfreemem(raw);
  return out;
}
std::int64_t PgResult::affected() const {
  const char* n = PQcmdTuples(result_);
  return n != nullptr && *n != '\0' ? std::strtoll(n, nullptr, 10) : 0;
}

// --- PgParams ---------------------------------------------------------------------------------

PgParams& PgParams::Add(std::string_view text) {
  values_.emplace_back(text);
  null_.push_back(false);
  formats_.push_back(0);
  return *this;
}
PgParams& PgParams::Add(std::int64_t v) {
  return Add(std::string_view(std::to_string(v)));
}
PgParams& PgParams::Add(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return Add(std::string_view(buf));
}
PgParams& PgParams::Add(bool v) {
  return Add(std::string_view(v ? "true" : "false"));
}
PgParams& PgParams::AddBytes(std::span<const std::uint8_t> bytes) {
  values_.emplace_back(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  null_.push_back(false);
  formats_.push_back(1);
  return *this;
}
PgParams& PgParams::AddNull() {
  values_.emplace_back();
  null_.push_back(true);
  formats_.push_back(0);
  return *this;
}
void PgParams::Seal() {
  pointers_.clear();
  lengths_.clear();
  for (std::size_t i = 0; i < values_.size(); ++i) {
    pointers_.push_back(null_[i] ? nullptr : values_[i].data());
    lengths_.push_back(static_cast<int>(values_[i].size()));
  }
}

namespace {

// The server's notices (NOTICE, WARNING: "relation … already exists, skipping") go to the
// program's log at debug level, one line each, instead of libpq's default: its stderr.
void LogNotice(void* /*arg*/, const char* message) {
  spdlog::debug("archive: PostgreSQL says: {}", OneLine(message));
}

}  // namespace

// --- PgConnection -----------------------------------------------------------------------------

Result<std::unique_ptr<PgConnection>> PgConnection::Open(const std::string& conninfo) {
  // connect_timeout first: a value in the conninfo (expanded in place of dbname) overrides it.
  const char* keys[] = {"connect_timeout", "dbname", "application_name", nullptr};
  const char* values[] = {"5", conninfo.c_str(), "brdfd", nullptr};
  pg_conn* conn = PQconnectdbParams(keys, values, /*expand_dbname=*/1);
  if (conn == nullptr) return Internal("connecting to the archive: out of memory");
  if (PQstatus(conn) != CONNECTION_OK) {
    const std::string message = "connecting to the archive: " + OneLine(PQerrorMessage(conn));
    PQfinish(conn);
    const bool auth = message.find("authentication") != std::string::npos ||
                      message.find("password") != std::string::npos ||
                      message.find("role \"") != std::string::npos;
    return auth ? FromSqlState("28000", message) : FromSqlState(nullptr, message);
  }
  PQsetNoticeProcessor(conn, LogNotice, nullptr);
  return std::unique_ptr<PgConnection>(new PgConnection(conn));
}

PgConnection::~PgConnection() {
  if (conn_ != nullptr) PQfinish(conn_);
}

bool PgConnection::healthy() const {
  return PQstatus(conn_) == CONNECTION_OK;
}

int PgConnection::server_version() const {
  return PQserverVersion(conn_);
}

Result<PgResult> PgConnection::Check(pg_result* raw, std::string_view what) {
  PgResult result(raw);
  const ExecStatusType st = raw != nullptr ? PQresultStatus(raw) : PGRES_FATAL_ERROR;
  if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) return result;
  const char* sqlstate = raw != nullptr ? PQresultErrorField(raw, PG_DIAG_SQLSTATE) : nullptr;
  const std::string message =
      std::string(what) + ": " +
      OneLine(raw != nullptr ? PQresultErrorMessage(raw) : PQerrorMessage(conn_));
  if (!healthy()) return FromSqlState(nullptr, message);
  return FromSqlState(sqlstate, message);
}

Status PgConnection::Exec(std::string_view sql) {
  const std::string text(sql);
  Result<PgResult> r = Check(PQexec(conn_, text.c_str()), "archive: " + text.substr(0, 60));
  return r.status();
}

Result<PgResult> PgConnection::Query(std::string_view sql, PgParams params) {
  params.Seal();
  const std::string text(sql);
  return Check(PQexecParams(conn_, text.c_str(), params.size(), nullptr, params.values(),
                            params.lengths(), params.formats(), 0),
               "archive: " + text.substr(0, 60));
}

Result<PgResult> PgConnection::QueryPrepared(const std::string& name, std::string_view sql,
                                             PgParams params) {
  if (std::find(prepared_.begin(), prepared_.end(), name) == prepared_.end()) {
    const std::string text(sql);
    BRDF_RETURN_IF_ERROR(Check(PQprepare(conn_, name.c_str(), text.c_str(), 0, nullptr),
                               "archive: preparing " + name)
                             .status());
    prepared_.push_back(name);
  }
  params.Seal();
  return Check(PQexecPrepared(conn_, name.c_str(), params.size(), params.values(), params.lengths(),
                              params.formats(), 0),
               "archive: " + name);
}

// --- PgTransaction ----------------------------------------------------------------------------

Result<PgTransaction> PgTransaction::Begin(PgConnection& conn) {
  BRDF_RETURN_IF_ERROR(conn.Exec("BEGIN"));
  return PgTransaction(&conn);
}

PgTransaction::~PgTransaction() {
  if (conn_ != nullptr && conn_->healthy()) (void)conn_->Exec("ROLLBACK");
}

Status PgTransaction::Commit() {
  PgConnection* conn = std::exchange(conn_, nullptr);
  return conn->Exec("COMMIT");
}

Result<std::string> ReadConninfoFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    const int err = errno;
    if (err == ENOENT) {
      return NotFound("archive credentials file " + path +
                      ": no such file; create it with the archive's libpq conninfo");
    }
    return IoError("archive credentials file " + path + ": cannot read it (" + std::strerror(err) +
                   "); brdfd's user must be able to read it");
  }
  std::string line;
  while (std::getline(in, line)) {
    line = Trim(line);
    if (!line.empty() && line[0] != '#') return line;
  }
  return InvalidArgument("archive credentials file " + path +
                         " holds no conninfo; write one line such as \"host=archive.lab "
                         "dbname=brdf user=rig_a password=…\"");
}

}  // namespace brdf::storage
