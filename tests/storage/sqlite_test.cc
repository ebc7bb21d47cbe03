// The RAII layer: connections configured as promised, statements bound and read back, cached and
// reset, transactions that roll back unless committed, and SQLite failures turned into Statuses
// that say what failed, where, and what to do.
#include "storage/sqlite.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fstream>

#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;
using testing::TempDir;

std::unique_ptr<Database> OpenOrDie(const std::string& path, const OpenOptions& options = {}) {
  Result<std::unique_ptr<Database>> db = Database::Open(path, options);
  EXPECT_TRUE(db.ok()) << db.status().ToString();
  return db.ok() ? std::move(db).value() : nullptr;
}

int PreparedStatements(Database& db) {
  int n = 0;
  for (sqlite3_stmt* s = sqlite3_next_stmt(db.handle(), nullptr); s != nullptr;
       s = sqlite3_next_stmt(db.handle(), s)) {
    ++n;
  }
  return n;
}

TEST(DatabaseTest, OpenAppliesWalFullSyncForeignKeysAndBusyTimeout) {
  TempDir dir;
  OpenOptions options;
  options.busy_timeout = std::chrono::milliseconds(1234);
  auto db = OpenOrDie(dir.File("a.db"), options);
  ASSERT_NE(db, nullptr);
  EXPECT_EQ(*db->QueryText("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(*db->QueryInt64("PRAGMA synchronous"), 2);  // FULL
  EXPECT_EQ(*db->QueryInt64("PRAGMA foreign_keys"), 1);
  EXPECT_EQ(*db->QueryInt64("PRAGMA busy_timeout"), 1234);
  EXPECT_EQ(db->path(), dir.File("a.db"));
}

TEST(DatabaseTest, BindsByIndexAndNameAndReadsTypedColumnsBack) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  ASSERT_TRUE(db->Exec("CREATE TABLE t (i INTEGER, r REAL, s TEXT, b BLOB, n INTEGER)").ok());
  const std::vector<std::uint8_t> bytes{0, 1, 2, 255, 0, 7};
  {
    auto st = db->Prepare("INSERT INTO t VALUES (?, :r, @s, $b, ?5)");
    ASSERT_TRUE(st.ok()) << st.status().ToString();
    st->Bind(1, std::int64_t{1} << 40)
        .Bind(":r", 2.5)
        .Bind("@s", std::string("héllo\nworld"))
        .Bind("$b", bytes)
        .Bind(5, std::optional<int>());
    ASSERT_TRUE(st->Run().ok());
  }
  auto st = db->Prepare("SELECT i, r, s, b, n FROM t");
  ASSERT_TRUE(st.ok());
  ASSERT_TRUE(*st->Step());
  EXPECT_EQ(st->ColumnCount(), 5);
  EXPECT_EQ(st->Int64(0), std::int64_t{1} << 40);
  EXPECT_EQ(st->Double(1), 2.5);
  EXPECT_EQ(st->Text(2), "héllo\nworld");
  auto blob = st->BlobView(3);
  EXPECT_EQ(std::vector<std::uint8_t>(blob.begin(), blob.end()), bytes);
  EXPECT_TRUE(st->IsNull(4));
  EXPECT_EQ(st->OptionalInt64(4), std::nullopt);
  EXPECT_EQ(st->OptionalInt64(0), std::int64_t{1} << 40);
  EXPECT_FALSE(*st->Step());
}

TEST(DatabaseTest, EmptyBlobIsABlobNotNull) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  auto st = db->Prepare("SELECT typeof(?)");
  ASSERT_TRUE(st.ok());
  st->Bind(1, std::vector<std::uint8_t>{});
  ASSERT_TRUE(*st->Step());
  EXPECT_EQ(st->Text(0), "blob");
}

TEST(DatabaseTest, UnknownParameterNameFailsAtStepNamingIt) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  auto st = db->Prepare("SELECT :a");
  ASSERT_TRUE(st.ok());
  st->Bind(":nope", 1);
  Result<bool> row = st->Step();
  ASSERT_FALSE(row.ok());
  EXPECT_EQ(row.status().code(), StatusCode::kInternal);
  EXPECT_THAT(row.status().message(), HasSubstr(":nope"));
}

TEST(DatabaseTest, StatementsAreCachedAndComeBackResetAndUnbound) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  const std::string sql = "SELECT ?1 IS NULL";
  const int before = PreparedStatements(*db);  // opening caches its PRAGMA statements
  for (int round = 0; round < 3; ++round) {
    auto st = db->Prepare(sql);
    ASSERT_TRUE(st.ok());
    ASSERT_TRUE(*st->Step());
    EXPECT_EQ(st->Int(0), 1) << "bindings of the previous use must be cleared";
    st->Reset();
    st->Bind(1, 5);
    ASSERT_TRUE(*st->Step());
    EXPECT_EQ(st->Int(0), 0);
    // Destroyed mid-result: goes back to the cache reset.
  }
  EXPECT_EQ(PreparedStatements(*db), before + 1);
  {
    // The same SQL in use twice at once gets two statements; one stays cached afterwards.
    auto a = db->Prepare(sql);
    auto b = db->Prepare(sql);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(PreparedStatements(*db), before + 2);
  }
  EXPECT_EQ(PreparedStatements(*db), before + 1);
}

TEST(DatabaseTest, PrepareRefusesSeveralStatements) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  auto st = db->Prepare("SELECT 1; SELECT 2");
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.status().code(), StatusCode::kInternal);
}

TEST(TransactionTest, CommitPersistsAndDestructionRollsBack) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  ASSERT_TRUE(db->Exec("CREATE TABLE t (x INTEGER)").ok());
  {
    auto tx = Transaction::Begin(*db);
    ASSERT_TRUE(tx.ok());
    ASSERT_TRUE(db->Exec("INSERT INTO t VALUES (1)").ok());
    ASSERT_TRUE(tx->Commit().ok());
    EXPECT_FALSE(tx->active());
  }
  {
    auto tx = Transaction::Begin(*db);
    ASSERT_TRUE(tx.ok());
    ASSERT_TRUE(db->Exec("INSERT INTO t VALUES (2)").ok());
    EXPECT_TRUE(db->in_transaction());
    // No Commit: an early return.
  }
  EXPECT_FALSE(db->in_transaction());
  EXPECT_EQ(*db->QueryInt64("SELECT group_concat(x) = '1' FROM t"), 1);
  // A second connection sees the same.
  auto other = OpenOrDie(dir.File("a.db"));
  EXPECT_EQ(*other->QueryInt64("SELECT count(*) FROM t"), 1);
}

TEST(TransactionTest, TransactionsDoNotNest) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  auto tx = Transaction::Begin(*db);
  ASSERT_TRUE(tx.ok());
  auto inner = Transaction::Begin(*db);
  ASSERT_FALSE(inner.ok());
  EXPECT_EQ(inner.status().code(), StatusCode::kInternal);
  EXPECT_TRUE(db->in_transaction()) << "the refused inner transaction must not end the outer one";
}

TEST(TransactionTest, WriterLockHeldElsewhereTimesOutWithAClearMessage) {
  TempDir dir;
  auto holder = OpenOrDie(dir.File("a.db"));
  ASSERT_TRUE(holder->Exec("CREATE TABLE t (x INTEGER)").ok());
  OpenOptions impatient;
  impatient.busy_timeout = std::chrono::milliseconds(50);
  auto waiter = OpenOrDie(dir.File("a.db"), impatient);
  auto held = Transaction::Begin(*holder);
  ASSERT_TRUE(held.ok());
  auto blocked = Transaction::Begin(*waiter);
  ASSERT_FALSE(blocked.ok());
  EXPECT_EQ(blocked.status().code(), StatusCode::kTimeout);
  EXPECT_THAT(blocked.status().message(), HasSubstr(dir.File("a.db")));
  EXPECT_THAT(blocked.status().message(), HasSubstr("SQLITE_BUSY"));
}

TEST(SqliteErrorTest, ConstraintViolationsMapToPreconditionOrArgument) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  ASSERT_TRUE(db->Exec("CREATE TABLE p (id INTEGER PRIMARY KEY);"
                       "CREATE TABLE c (id INTEGER PRIMARY KEY, p INTEGER REFERENCES p (id),"
                       "  v INTEGER CHECK (v > 0), u TEXT UNIQUE);"
                       "INSERT INTO p VALUES (1); INSERT INTO c VALUES (1, 1, 1, 'a');")
                  .ok());
  Status dup = db->Exec("INSERT INTO c VALUES (2, 1, 1, 'a')");
  EXPECT_EQ(dup.code(), StatusCode::kFailedPrecondition) << dup.ToString();
  EXPECT_THAT(dup.message(), HasSubstr("UNIQUE constraint failed: c.u"));
  EXPECT_THAT(dup.message(), HasSubstr("INSERT INTO c"));
  EXPECT_THAT(dup.message(), HasSubstr(dir.File("a.db")));
  Status pk = db->Exec("INSERT INTO c VALUES (1, 1, 1, 'b')");
  EXPECT_EQ(pk.code(), StatusCode::kFailedPrecondition) << pk.ToString();
  Status fk = db->Exec("INSERT INTO c VALUES (3, 42, 1, 'c')");
  EXPECT_EQ(fk.code(), StatusCode::kInvalidArgument) << fk.ToString();
  EXPECT_THAT(fk.message(), HasSubstr("FOREIGN KEY"));
  Status check = db->Exec("INSERT INTO c VALUES (4, 1, -1, 'd')");
  EXPECT_EQ(check.code(), StatusCode::kInvalidArgument) << check.ToString();
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM c"), 1);
}

TEST(SqliteErrorTest, SqlMistakesAreInternal) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  Status s = db->Exec("SELEC 1");
  EXPECT_EQ(s.code(), StatusCode::kInternal);
  EXPECT_THAT(s.message(), HasSubstr("syntax error"));
}

TEST(SqliteErrorTest, WriteOnReadOnlyConnectionIsIoErrorWithPermissionHint) {
  TempDir dir;
  {
    auto db = OpenOrDie(dir.File("a.db"));
    ASSERT_TRUE(db->Exec("CREATE TABLE t (x INTEGER)").ok());
  }
  OpenOptions ro;
  ro.read_only = true;
  auto db = OpenOrDie(dir.File("a.db"), ro);
  ASSERT_NE(db, nullptr);
  Status s = db->Exec("INSERT INTO t VALUES (1)");
  EXPECT_EQ(s.code(), StatusCode::kIoError) << s.ToString();
  EXPECT_THAT(s.message(), HasSubstr("SQLITE_READONLY"));
  EXPECT_THAT(s.message(), HasSubstr("permissions of the file AND of its directory"));
  EXPECT_THAT(s.message(), HasSubstr(dir.File("a.db") + "-wal"));
}

TEST(SqliteErrorTest, FullDatabaseIsIoErrorWithFreeSpaceHint) {
  TempDir dir;
  OpenOptions small;
  small.max_page_count = 8;
  auto db = OpenOrDie(dir.File("a.db"), small);
  ASSERT_TRUE(db->Exec("CREATE TABLE t (b BLOB)").ok());
  Status s;
  for (int i = 0; i < 100 && s.ok(); ++i) {
    auto st = db->Prepare("INSERT INTO t VALUES (?)");
    ASSERT_TRUE(st.ok());
    st->Bind(1, std::vector<std::uint8_t>(1000, 7));
    s = st->Run();
  }
  EXPECT_EQ(s.code(), StatusCode::kIoError) << s.ToString();
  EXPECT_THAT(s.message(), HasSubstr("SQLITE_FULL"));
  EXPECT_THAT(s.message(), HasSubstr("free space"));
}

TEST(SqliteErrorTest, MissingDirectoryIsIoErrorNamingTheDirectory) {
  TempDir dir;
  const std::string path = dir.File("no/such/dir/a.db");
  auto db = Database::Open(path);
  ASSERT_FALSE(db.ok());
  EXPECT_EQ(db.status().code(), StatusCode::kIoError) << db.status().ToString();
  EXPECT_THAT(db.status().message(), HasSubstr("SQLITE_CANTOPEN"));
  EXPECT_THAT(db.status().message(), HasSubstr(dir.File("no/such/dir")));
}

TEST(SqliteErrorTest, ForeignFileIsIoErrorWithIntegrityHint) {
  TempDir dir;
  const std::string path = dir.File("notes.txt");
  {
    std::ofstream f(path);
    for (int i = 0; i < 200; ++i) f << "this is not a database, it is a lab notebook line\n";
  }
  auto db = Database::Open(path);
  ASSERT_FALSE(db.ok());
  EXPECT_EQ(db.status().code(), StatusCode::kIoError) << db.status().ToString();
  EXPECT_THAT(db.status().message(), HasSubstr("SQLITE_NOTADB"));
  EXPECT_THAT(db.status().message(), HasSubstr("integrity_check"));
}

TEST(SqliteErrorTest, ExtendedCodesMapByTheirPrimaryCode) {
  struct Case {
    int rc;
    StatusCode code;
  };
  const Case cases[] = {
      {SQLITE_IOERR_FSYNC, StatusCode::kIoError},
      {SQLITE_IOERR_SHORT_READ, StatusCode::kIoError},
      {SQLITE_READONLY_DIRECTORY, StatusCode::kIoError},
      {SQLITE_CANTOPEN_ISDIR, StatusCode::kIoError},
      {SQLITE_CORRUPT_INDEX, StatusCode::kIoError},
      {SQLITE_FULL, StatusCode::kIoError},
      {SQLITE_CONSTRAINT_UNIQUE, StatusCode::kFailedPrecondition},
      {SQLITE_CONSTRAINT_PRIMARYKEY, StatusCode::kFailedPrecondition},
      {SQLITE_CONSTRAINT_NOTNULL, StatusCode::kInvalidArgument},
      {SQLITE_BUSY_SNAPSHOT, StatusCode::kTimeout},
      {SQLITE_MISUSE, StatusCode::kInternal},
  };
  for (const Case& c : cases) {
    Status s = SqliteStatus(c.rc, "/data/brdfd.db", "INSERT INTO readings", "message");
    EXPECT_EQ(s.code(), c.code) << c.rc << ": " << s.ToString();
    EXPECT_THAT(s.message(), HasSubstr("INSERT INTO readings on /data/brdfd.db failed: message"));
  }
}

}  // namespace
}  // namespace brdf::storage
