// Schema versions: a new file gets the latest schema, an older file is migrated in order keeping
// its data, a failed migration leaves the previous version intact, and a file from a newer brdfd
// (or from another program) is refused without being touched.
#include "storage/schema.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "storage/uuid.h"
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

// The real migrations plus a hypothetical next version, as a later brdfd would ship it.
std::vector<Migration> WithNextVersion(std::string_view v2_sql) {
  std::vector<Migration> list(SchemaMigrations().begin(), SchemaMigrations().end());
  list.push_back(Migration{static_cast<int>(list.size()) + 1, "add operator notes", v2_sql});
  return list;
}

// A file of the latest version with one session, two steps done (one with its reading).
std::int64_t MakeCurrentFile(const std::string& path) {
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
  const std::int64_t session = MakeCurrentFile(path);
  auto db = OpenOrDie(path);
  ASSERT_EQ(*SchemaVersion(*db), LatestSchemaVersion());
  const auto list = WithNextVersion(
      "ALTER TABLE sessions ADD COLUMN operator_note TEXT NOT NULL DEFAULT '';"
      "CREATE INDEX sessions_by_name ON sessions (name);");
  ASSERT_TRUE(Migrate(*db, list).ok());
  EXPECT_EQ(*SchemaVersion(*db), LatestSchemaVersion() + 1);
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
  MakeCurrentFile(path);
  auto db = OpenOrDie(path);
  // The first statement works, the second fails: neither may persist.
  const auto list = WithNextVersion(
      "ALTER TABLE sessions ADD COLUMN operator_note TEXT;"
      "ALTER TABLE no_such_table ADD COLUMN x TEXT;");
  Status s = Migrate(*db, list);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("migrating " + path + " to schema version " +
                                     std::to_string(LatestSchemaVersion() + 1)));
  EXPECT_THAT(s.message(), HasSubstr("no_such_table"));
  EXPECT_EQ(*SchemaVersion(*db), LatestSchemaVersion());
  EXPECT_EQ(*db->QueryInt64("SELECT count(*) FROM pragma_table_info('sessions') "
                            "WHERE name = 'operator_note'"),
            0);
  EXPECT_FALSE(db->in_transaction());
}

// A file written by a brdfd before global identity (schema version 1): migration 2 gives each
// session its own UUID and an empty rig, which the daemon then adopts as its own.
TEST(SchemaTest, Version1SessionsGetDistinctUuidsAndAdoptTheRig) {
  TempDir dir;
  const std::string path = dir.File("v1.db");
  {
    auto db = OpenOrDie(path);
    ASSERT_TRUE(Migrate(*db, SchemaMigrations().first(1)).ok());
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(db->Exec("INSERT INTO sessions (name, plan_kind, plan_json, created_at, "
                           "total_steps) VALUES ('old', 'pose_list', '{}', 1.0, 0)")
                      .ok());
    }
  }
  auto store = SessionStore::Open(path);
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  auto sessions = (*store)->ListSessions();
  ASSERT_TRUE(sessions.ok());
  ASSERT_EQ(sessions->size(), 3u);
  std::set<std::string> uuids;
  for (const SessionRecord& s : *sessions) {
    EXPECT_TRUE(IsUuid(s.uuid)) << s.uuid;
    EXPECT_EQ(s.uuid[14], '4') << s.uuid;  // version 4
    EXPECT_NE(std::string("89ab").find(s.uuid[19]), std::string::npos) << s.uuid;
    EXPECT_EQ(s.rig, "");
    uuids.insert(s.uuid);
  }
  EXPECT_EQ(uuids.size(), 3u);
  ASSERT_TRUE((*store)->AdoptUnnamedSessions("rig-a").ok());
  auto again = (*store)->GetSessionByUuid((*sessions)[1].uuid);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->id, (*sessions)[1].id);
  EXPECT_EQ(again->rig, "rig-a");
  EXPECT_EQ((*store)->GetSessionByUuid("no-such").status().code(), StatusCode::kNotFound);
}

TEST(SchemaTest, NewSessionsGetAUuidAndKeepTheirRig) {
  TempDir dir;
  auto store = SessionStore::Open(dir.File("new.db"));
  ASSERT_TRUE(store.ok());
  NewSession session = MakeNewSession();
  session.rig = "rig-b";
  auto a = (*store)->CreateSession(session, MakeSteps(2));
  auto b = (*store)->CreateSession(session, MakeSteps(2));
  ASSERT_TRUE(a.ok() && b.ok());
  auto ra = (*store)->GetSession(*a);
  auto rb = (*store)->GetSession(*b);
  ASSERT_TRUE(ra.ok() && rb.ok());
  EXPECT_TRUE(IsUuid(ra->uuid)) << ra->uuid;
  EXPECT_NE(ra->uuid, rb->uuid);
  EXPECT_EQ(ra->rig, "rig-b");
  session.uuid = ra->uuid;  // the database refuses a second session with the same identity
  EXPECT_FALSE((*store)->CreateSession(session, MakeSteps(2)).ok());
}

TEST(SchemaTest, NewerFileIsRefusedUntouchedWithAClearMessage) {
  TempDir dir;
  const std::string path = dir.File("newer.db");
  MakeCurrentFile(path);
  {
    auto db = OpenOrDie(path);
    ASSERT_TRUE(
        Migrate(*db, WithNextVersion("CREATE TABLE calibrations (id INTEGER PRIMARY KEY);")).ok());
  }
  auto store = SessionStore::Open(path);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(store.status().message(),
              HasSubstr(path + " has schema version " + std::to_string(LatestSchemaVersion() + 1)));
  EXPECT_THAT(store.status().message(), HasSubstr("newer than the latest this brdfd knows (" +
                                                  std::to_string(LatestSchemaVersion()) + ")"));
  EXPECT_THAT(store.status().message(), HasSubstr("written by a newer brdfd"));
  auto db = OpenOrDie(path);
  EXPECT_EQ(*SchemaVersion(*db), LatestSchemaVersion() + 1);
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
