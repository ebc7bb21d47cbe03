// Schema versions: a new file gets the latest schema, an older file is migrated in order keeping
// its data, a failed migration leaves the previous version intact, and a file from a newer brdfd
// (or from another program) is refused without being touched.
#include "storage/schema.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vector>

#include "storage_test_util.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;
using testing::MakeNewSession;
using testing::MakeReading;
using testing::MakeSteps;
using testing::TempDir;

std::unique_ptr<Database> OpenOrDie(const std::string& path) {
  Result<std::unique_ptr<Database>> db = Database::Open(path);
  EXPECT_TRUE(db.ok()) << db.status().ToString();
  return db.ok() ? std::move(db).value() : nullptr;
}

// The real migrations plus a hypothetical version 2, as a later brdfd would ship it.
std::vector<Migration> WithVersion2(std::string_view v2_sql) {
  std::vector<Migration> list(SchemaMigrations().begin(), SchemaMigrations().end());
  list.push_back(Migration{static_cast<int>(list.size()) + 1, "add operator notes", v2_sql});
  return list;
}

// A version-1 file with one session, two steps done (one with its reading).
std::int64_t MakeVersion1File(const std::string& path) {
  auto store = SessionStore::Open(path);
  EXPECT_TRUE(store.ok()) << store.status().ToString();
  auto id = (*store)->CreateSession(MakeNewSession(), MakeSteps(3));
  EXPECT_TRUE(id.ok());
  EXPECT_TRUE((*store)->SetSessionState(*id, SessionState::kRunning, "").ok());
  EXPECT_TRUE((*store)->CompleteStep(*id, 0).ok());
  EXPECT_TRUE(
      (*store)->CompleteStepWithReading(*id, 1, MakeReading(1, ReadingKind::kReference)).ok());
  return *id;
}

TEST(SchemaTest, NewFileGetsTheLatestSchemaAndBrdfdsApplicationId) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("new.db"));
  EXPECT_EQ(*SchemaVersion(*db), 0);
  ASSERT_TRUE(Migrate(*db).ok());
  EXPECT_EQ(*SchemaVersion(*db), LatestSchemaVersion());
  EXPECT_EQ(*db->QueryInt64("PRAGMA application_id"), kApplicationId);
  for (const char* table : {"sessions", "steps", "readings", "devices", "audit"}) {
    EXPECT_EQ(*db->QueryInt64(std::string("SELECT count(*) FROM sqlite_schema WHERE type = "
                                          "'table' AND name = '") +
                              table + "'"),
              1)
        << table;
  }
  // Migrating again is a no-op.
  ASSERT_TRUE(Migrate(*db).ok());
  EXPECT_EQ(*SchemaVersion(*db), LatestSchemaVersion());
}

TEST(SchemaTest, OlderFileMigratesInOrderAndKeepsItsData) {
  TempDir dir;
  const std::string path = dir.File("old.db");
  const std::int64_t session = MakeVersion1File(path);
  auto db = OpenOrDie(path);
  ASSERT_EQ(*SchemaVersion(*db), 1);
  const auto list = WithVersion2(
      "ALTER TABLE sessions ADD COLUMN operator_note TEXT NOT NULL DEFAULT '';"
      "CREATE INDEX sessions_by_name ON sessions (name);");
  ASSERT_TRUE(Migrate(*db, list).ok());
  EXPECT_EQ(*SchemaVersion(*db), 2);
  EXPECT_EQ(*db->QueryText("SELECT name || '|' || operator_note || '|' || done_steps FROM "
                           "sessions WHERE id = " +
                           std::to_string(session)),
            "paint sample||2");
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM readings"), 1);
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM sqlite_schema WHERE name = 'sessions_by_name'"),
            1);
}

TEST(SchemaTest, FailedMigrationLeavesThePreviousVersionIntact) {
  TempDir dir;
  const std::string path = dir.File("old.db");
  MakeVersion1File(path);
  auto db = OpenOrDie(path);
  // The first statement works, the second fails: neither may persist.
  const auto list = WithVersion2(
      "ALTER TABLE sessions ADD COLUMN operator_note TEXT;"
      "ALTER TABLE no_such_table ADD COLUMN x TEXT;");
  Status s = Migrate(*db, list);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("migrating " + path + " to schema version 2"));
  EXPECT_THAT(s.message(), HasSubstr("no_such_table"));
  EXPECT_EQ(*SchemaVersion(*db), 1);
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM pragma_table_info('sessions') "
                            "WHERE name = 'operator_note'"),
            0);
  EXPECT_FALSE(db->in_transaction());
}

TEST(SchemaTest, NewerFileIsRefusedUntouchedWithAClearMessage) {
  TempDir dir;
  const std::string path = dir.File("newer.db");
  MakeVersion1File(path);
  {
    auto db = OpenOrDie(path);
    ASSERT_TRUE(
        Migrate(*db, WithVersion2("CREATE TABLE calibrations (id INTEGER PRIMARY KEY);")).ok());
  }
  auto store = SessionStore::Open(path);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(store.status().message(), HasSubstr(path + " has schema version 2"));
  EXPECT_THAT(store.status().message(), HasSubstr("newer than the latest this brdfd knows (" +
                                                  std::to_string(LatestSchemaVersion()) + ")"));
  EXPECT_THAT(store.status().message(), HasSubstr("written by a newer brdfd"));
  auto db = OpenOrDie(path);
  EXPECT_EQ(*SchemaVersion(*db), 2);
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM readings"), 1);
}

TEST(SchemaTest, AnotherProgramsDatabaseIsRefused) {
  TempDir dir;
  const std::string path = dir.File("other.db");
  {
    auto db = OpenOrDie(path);
    ASSERT_TRUE(db->Exec("CREATE TABLE sessions (who TEXT)").ok());
  }
  auto store = SessionStore::Open(path);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(store.status().message(), HasSubstr("is not a brdfd database"));
  auto db = OpenOrDie(path);
  EXPECT_EQ(*SchemaVersion(*db), 0);
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM sqlite_schema"), 1);
}

TEST(SchemaTest, MisnumberedMigrationListIsABug) {
  TempDir dir;
  auto db = OpenOrDie(dir.File("a.db"));
  const Migration gap[] = {{1, "one", "CREATE TABLE a (x)"}, {3, "three", "CREATE TABLE b (x)"}};
  Status s = Migrate(*db, gap);
  EXPECT_EQ(s.code(), StatusCode::kInternal);
  EXPECT_EQ(*SchemaVersion(*db), 0);
}

}  // namespace
}  // namespace brdf::storage
