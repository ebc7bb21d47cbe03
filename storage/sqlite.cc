#include "storage/sqlite.h"

#include <sqlite3.h>

#include <cstring>
#include <filesystem>
#include <utility>

namespace brdf::storage {
namespace {

// The name of a primary result code, for messages an operator may search for.
const char* PrimaryCodeName(int rc) {
  switch (rc & 0xff) {
    case SQLITE_ERROR:
      return "SQLITE_ERROR";
    case SQLITE_INTERNAL:
      return "SQLITE_INTERNAL";
    case SQLITE_PERM:
      return "SQLITE_PERM";
    case SQLITE_ABORT:
      return "SQLITE_ABORT";
    case SQLITE_BUSY:
      return "SQLITE_BUSY";
    case SQLITE_LOCKED:
      return "SQLITE_LOCKED";
    case SQLITE_NOMEM:
      return "SQLITE_NOMEM";
    case SQLITE_READONLY:
      return "SQLITE_READONLY";
    case SQLITE_INTERRUPT:
      return "SQLITE_INTERRUPT";
    case SQLITE_IOERR:
      return "SQLITE_IOERR";
    case SQLITE_CORRUPT:
      return "SQLITE_CORRUPT";
    case SQLITE_NOTFOUND:
      return "SQLITE_NOTFOUND";
    case SQLITE_FULL:
      return "SQLITE_FULL";
    case SQLITE_CANTOPEN:
      return "SQLITE_CANTOPEN";
    case SQLITE_PROTOCOL:
      return "SQLITE_PROTOCOL";
    case SQLITE_SCHEMA:
      return "SQLITE_SCHEMA";
    case SQLITE_TOOBIG:
      return "SQLITE_TOOBIG";
    case SQLITE_CONSTRAINT:
      return "SQLITE_CONSTRAINT";
    case SQLITE_MISMATCH:
      return "SQLITE_MISMATCH";
    case SQLITE_MISUSE:
      return "SQLITE_MISUSE";
    case SQLITE_AUTH:
      return "SQLITE_AUTH";
    case SQLITE_RANGE:
      return "SQLITE_RANGE";
    case SQLITE_NOTADB:
      return "SQLITE_NOTADB";
    default:
      return "SQLITE_?";
  }
}

std::string DirectoryOf(std::string_view path) {
  std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? std::string(".") : dir;
}

// SQL shortened to one line for messages: "INSERT INTO readings (session_id, …".
std::string DescribeSql(std::string_view sql) {
  std::string out;
  bool space = false;
  for (char c : sql) {
    if (c == ' ' || c == '\n' || c == '\t' || c == '\r') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += c;
    if (out.size() >= 72) {
      out += "…";
      break;
    }
  }
  return out;
}

// SQLite's message plus, for an I/O failure, what the operating system said ("No space left on
// device", "File too large", "Operation not permitted"): "disk I/O error" alone does not tell the
// operator whether to free space, lift a quota or remount.
std::string WithSystemError(sqlite3* db, int rc, std::string message) {
  const int primary = rc & 0xff;
  if (primary != SQLITE_IOERR && primary != SQLITE_FULL && primary != SQLITE_READONLY &&
      primary != SQLITE_CANTOPEN) {
    return message;
  }
  const int err = sqlite3_system_errno(db);
  if (err != 0) message += " (operating system: " + std::string(std::strerror(err)) + ")";
  return message;
}

}  // namespace

Status SqliteStatus(int rc, std::string_view path, std::string_view operation,
                    std::string_view sqlite_message) {
  const std::string p(path);
  std::string m = std::string(operation) + " on " + p + " failed: " + std::string(sqlite_message) +
                  " [" + PrimaryCodeName(rc) + "]";
  switch (rc & 0xff) {
    case SQLITE_FULL:
      return IoError(m + "; the disk holding " + DirectoryOf(path) +
                     " is full or the database reached its size limit: free space on that "
                     "filesystem (or raise the limit), then resume; the failed write was not kept");
    case SQLITE_READONLY:
      return IoError(
          m + "; " + p + " cannot be written: check the permissions of the file AND of " +
          "its directory " + DirectoryOf(path) + " (WAL mode creates " + p + "-wal and " + p +
          "-shm there) and that the filesystem is not mounted read-only");
    case SQLITE_CANTOPEN:
      return IoError(m + "; check that the directory " + DirectoryOf(path) +
                     " exists and that brdfd may read and write both it and the file (WAL mode "
                     "creates " +
                     p + "-wal and " + p + "-shm next to it)");
    case SQLITE_IOERR:
      return IoError(m +
                     "; the operating system reported an I/O error: check the disk (dmesg), "
                     "free space and the filesystem; committed data is intact");
    case SQLITE_NOMEM:
      return IoError(m + "; SQLite ran out of memory: check the host's memory use");
    case SQLITE_PERM:
    case SQLITE_AUTH:
      return IoError(m + "; access was denied: check the permissions of " + p + " and " +
                     DirectoryOf(path));
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
      return IoError(m +
                     "; the database file is damaged or is not a SQLite database: stop brdfd, " +
                     "keep a copy of " + p + " (with its -wal file), run sqlite3 " + p +
                     " 'PRAGMA integrity_check' and restore from a backup if it reports problems");
    case SQLITE_CONSTRAINT:
      if (rc == SQLITE_CONSTRAINT_UNIQUE || rc == SQLITE_CONSTRAINT_PRIMARYKEY) {
        return FailedPrecondition(m + "; the row already exists");
      }
      if (rc == SQLITE_CONSTRAINT_FOREIGNKEY) {
        return InvalidArgument(m + "; it refers to a row that does not exist");
      }
      return InvalidArgument(m + "; a value is outside what the schema allows");
    case SQLITE_TOOBIG:
    case SQLITE_RANGE:
    case SQLITE_MISMATCH:
      return InvalidArgument(m);
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      return Timeout(m +
                     "; another connection (a second brdfd? a sqlite3 shell?) held the lock on " +
                     p + " longer than the busy timeout: find and stop it");
    default:
      return Internal(m + "; this is a bug in brdfd's storage, please report it with this message");
  }
}

// --- Statement
// ------------------------------------------------------------------------------------

Statement::Statement(Statement&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)),
      stmt_(std::exchange(other.stmt_, nullptr)),
      sql_(std::move(other.sql_)),
      bind_error_(std::move(other.bind_error_)) {}

Statement& Statement::operator=(Statement&& other) noexcept {
  if (this != &other) {
    Release();
    db_ = std::exchange(other.db_, nullptr);
    stmt_ = std::exchange(other.stmt_, nullptr);
    sql_ = std::move(other.sql_);
    bind_error_ = std::move(other.bind_error_);
  }
  return *this;
}

Statement::~Statement() {
  Release();
}

void Statement::Release() {
  if (stmt_ == nullptr) return;
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
  db_->ReturnToCache(std::move(sql_), stmt_);
  stmt_ = nullptr;
  db_ = nullptr;
}

int Statement::ParameterIndex(std::string_view name) {
  const std::string n(name);
  const int index = sqlite3_bind_parameter_index(stmt_, n.c_str());
  if (index == 0 && bind_error_.ok()) {
    bind_error_ = Internal("binding " + n + " in \"" + DescribeSql(sql_) + "\" on " + db_->path() +
                           ": the statement has no such parameter (a bug in brdfd's storage)");
  }
  return index;
}

void Statement::NoteBindResult(int rc, int index) {
  if (rc == SQLITE_OK || !bind_error_.ok()) return;
  if (index == 0) return;  // already reported by ParameterIndex
  bind_error_ =
      db_->Error(rc, "binding parameter " + std::to_string(index) + " of " + DescribeSql(sql_));
}

void Statement::BindInt64(int index, std::int64_t v) {
  NoteBindResult(sqlite3_bind_int64(stmt_, index, v), index);
}
void Statement::BindDouble(int index, double v) {
  NoteBindResult(sqlite3_bind_double(stmt_, index, v), index);
}
void Statement::BindText(int index, std::string_view v) {
  NoteBindResult(
      sqlite3_bind_text64(stmt_, index, v.data(), v.size(), SQLITE_TRANSIENT, SQLITE_UTF8), index);
}
void Statement::BindBlob(int index, Blob v) {
  // A zero-length blob must still be a BLOB, not NULL: SQLite treats a null pointer as NULL.
  static const std::uint8_t kEmpty = 0;
  const void* data = v.empty() ? &kEmpty : v.data();
  NoteBindResult(sqlite3_bind_blob64(stmt_, index, data, v.size(), SQLITE_TRANSIENT), index);
}
void Statement::BindNull(int index) {
  NoteBindResult(sqlite3_bind_null(stmt_, index), index);
}

Result<bool> Statement::Step() {
  if (stmt_ == nullptr) return Internal("stepping an empty Statement (a bug in brdfd's storage)");
  if (!bind_error_.ok()) return bind_error_;
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  return db_->Error(rc, DescribeSql(sql_));
}

Status Statement::Run() {
  BRDF_ASSIGN_OR_RETURN(bool row, Step());
  if (row) {
    return Internal("\"" + DescribeSql(sql_) + "\" on " + db_->path() +
                    " returned rows where none were expected (a bug in brdfd's storage)");
  }
  return Status::Ok();
}

void Statement::Reset() {
  if (stmt_ == nullptr) return;
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
  bind_error_ = Status::Ok();
}

int Statement::ColumnCount() const {
  return sqlite3_data_count(stmt_);
}
bool Statement::IsNull(int column) const {
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}
std::int64_t Statement::Int64(int column) const {
  return sqlite3_column_int64(stmt_, column);
}
int Statement::Int(int column) const {
  return sqlite3_column_int(stmt_, column);
}
double Statement::Double(int column) const {
  return sqlite3_column_double(stmt_, column);
}
std::string Statement::Text(int column) const {
  const unsigned char* text = sqlite3_column_text(stmt_, column);
  if (text == nullptr) return {};
  const int n = sqlite3_column_bytes(stmt_, column);
  return std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(n));
}
Statement::Blob Statement::BlobView(int column) const {
  const void* data = sqlite3_column_blob(stmt_, column);
  const int n = sqlite3_column_bytes(stmt_, column);
  if (data == nullptr || n <= 0) return {};
  return Blob(static_cast<const std::uint8_t*>(data), static_cast<std::size_t>(n));
}
std::optional<std::int64_t> Statement::OptionalInt64(int column) const {
  if (IsNull(column)) return std::nullopt;
  return Int64(column);
}
std::optional<double> Statement::OptionalDouble(int column) const {
  if (IsNull(column)) return std::nullopt;
  return Double(column);
}
std::optional<std::string> Statement::OptionalText(int column) const {
  if (IsNull(column)) return std::nullopt;
  return Text(column);
}

// --- Database
// -------------------------------------------------------------------------------------

Result<std::unique_ptr<Database>> Database::Open(const std::string& path,
                                                 const OpenOptions& options) {
  int flags = options.read_only ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE;
  if (!options.read_only && options.create) flags |= SQLITE_OPEN_CREATE;
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, flags, nullptr);
  if (rc != SQLITE_OK) {
    Status status = SqliteStatus(rc, path, "opening the database",
                                 raw != nullptr ? sqlite3_errmsg(raw) : sqlite3_errstr(rc));
    sqlite3_close_v2(raw);
    return status;
  }
  std::unique_ptr<Database> db(new Database(raw, path));
  BRDF_RETURN_IF_ERROR(db->Configure(options));
  return db;
}

Status Database::Configure(const OpenOptions& options) {
  sqlite3_extended_result_codes(db_, 1);
  sqlite3_busy_timeout(db_, static_cast<int>(options.busy_timeout.count()));
  if (!options.read_only && sqlite3_db_readonly(db_, "main") == 1) {
    return SqliteStatus(SQLITE_READONLY, path_, "opening the database for writing",
                        "the operating system allows reading only");
  }
  BRDF_ASSIGN_OR_RETURN(std::string mode, QueryText("PRAGMA journal_mode=WAL"));
  // An in-memory database reports "memory"; a read-only connection cannot change the mode.
  if (mode != "wal" && mode != "memory" && !options.read_only) {
    return IoError("switching " + path_ + " to WAL journal mode failed (SQLite kept \"" + mode +
                   "\"): the filesystem may lack shared-memory support (a network share?); keep "
                   "the database on a local disk");
  }
  std::string pragmas = "PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON;";
  if (options.max_page_count > 0) {
    pragmas += " PRAGMA max_page_count=" + std::to_string(options.max_page_count) + ";";
  }
  return Exec(pragmas);
}

Database::~Database() {
  for (auto& [sql, stmt] : cache_) sqlite3_finalize(stmt);
  cache_.clear();
  sqlite3_close_v2(db_);
}

Result<Statement> Database::Prepare(std::string_view sql) {
  std::string key(sql);
  if (auto it = cache_.find(key); it != cache_.end()) {
    sqlite3_stmt* stmt = it->second;
    cache_.erase(it);
    return Statement(this, stmt, std::move(key));
  }
  sqlite3_stmt* stmt = nullptr;
  const char* tail = nullptr;
  const int rc = sqlite3_prepare_v3(db_, key.data(), static_cast<int>(key.size()),
                                    SQLITE_PREPARE_PERSISTENT, &stmt, &tail);
  if (rc != SQLITE_OK) return Error(rc, "preparing " + DescribeSql(key));
  if (stmt == nullptr) return Internal("preparing empty SQL on " + path_);
  for (; tail != nullptr && *tail != '\0'; ++tail) {
    if (*tail != ' ' && *tail != '\n' && *tail != '\t' && *tail != '\r' && *tail != ';') {
      sqlite3_finalize(stmt);
      return Internal("preparing \"" + DescribeSql(key) +
                      "\": more than one statement (a bug in brdfd's storage; use Exec)");
    }
  }
  return Statement(this, stmt, std::move(key));
}

void Database::ReturnToCache(std::string sql, sqlite3_stmt* stmt) {
  // The same SQL may be in use twice at once (nested use); keep one idle copy.
  auto [it, inserted] = cache_.try_emplace(std::move(sql), stmt);
  if (!inserted) sqlite3_finalize(stmt);
}

Status Database::Exec(std::string_view sql) {
  const std::string s(sql);
  char* message = nullptr;
  const int rc = sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &message);
  if (rc == SQLITE_OK) return Status::Ok();
  const std::string text =
      WithSystemError(db_, rc, message != nullptr ? message : sqlite3_errstr(rc));
  sqlite3_free(message);
  return SqliteStatus(rc, path_, DescribeSql(s), text);
}

Result<std::int64_t> Database::QueryInt64(std::string_view sql) {
  BRDF_ASSIGN_OR_RETURN(Statement st, Prepare(sql));
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return Internal("\"" + DescribeSql(sql) + "\" on " + path_ + " returned no row");
  return st.Int64(0);
}

Result<std::string> Database::QueryText(std::string_view sql) {
  BRDF_ASSIGN_OR_RETURN(Statement st, Prepare(sql));
  BRDF_ASSIGN_OR_RETURN(bool row, st.Step());
  if (!row) return Internal("\"" + DescribeSql(sql) + "\" on " + path_ + " returned no row");
  return st.Text(0);
}

std::int64_t Database::last_insert_rowid() const {
  return sqlite3_last_insert_rowid(db_);
}
int Database::changes() const {
  return sqlite3_changes(db_);
}
bool Database::in_transaction() const {
  return sqlite3_get_autocommit(db_) == 0;
}

Status Database::Error(int rc, std::string_view operation) const {
  return SqliteStatus(rc, path_, operation, WithSystemError(db_, rc, sqlite3_errmsg(db_)));
}

// --- Transaction
// ----------------------------------------------------------------------------------

Result<Transaction> Transaction::Begin(Database& db) {
  if (db.in_transaction()) {
    return Internal("beginning a transaction on " + db.path() +
                    " while another is open (transactions do not nest; a bug in brdfd's storage)");
  }
  BRDF_RETURN_IF_ERROR(db.Exec("BEGIN IMMEDIATE"));
  return Transaction(&db);
}

Result<Transaction> Transaction::BeginRead(Database& db) {
  if (db.in_transaction()) {
    return Internal("beginning a transaction on " + db.path() +
                    " while another is open (transactions do not nest; a bug in brdfd's storage)");
  }
  BRDF_RETURN_IF_ERROR(db.Exec("BEGIN DEFERRED"));
  return Transaction(&db);
}

Transaction::~Transaction() {
  Rollback();
}

Status Transaction::Commit() {
  if (db_ == nullptr) return Internal("committing a transaction that is no longer open");
  Status status = db_->Exec("COMMIT");
  if (!status.ok()) {
    Rollback();
    return status;
  }
  db_ = nullptr;
  return Status::Ok();
}

void Transaction::Rollback() {
  if (db_ == nullptr) return;
  // After SQLITE_FULL, SQLITE_IOERR or SQLITE_NOMEM SQLite may already have rolled back.
  if (db_->in_transaction()) (void)db_->Exec("ROLLBACK");
  db_ = nullptr;
}

}  // namespace brdf::storage
