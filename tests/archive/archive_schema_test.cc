// The archive's schema on a real PostgreSQL: a new database gets the latest version, migrating
// again changes nothing, an older archive with sessions migrates, a newer archive is refused, and
// the libpq layer reports a wrong password and an unreachable server as what they are -- without
// the password in the message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "storage/archive/pg.h"
#include "storage/archive/reader.h"
#include "storage/archive/schema.h"
#include "tests/support/pg/server_fixture.h"

namespace brdf::storage {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::PgServer;
using testing::PgServerTest;

class ArchiveSchemaTest : public PgServerTest {
 protected:
  void SetUp() override {
    PgServerTest::SetUp();
    if (!PgReady()) return;
  }
  std::unique_ptr<PgConnection> Connect() {
    Result<std::unique_ptr<PgConnection>> c = PgConnection::Open(pg_->conninfo());
    EXPECT_TRUE(c.ok()) << c.status().ToString();
    return c.ok() ? std::move(*c) : nullptr;
  }
};

TEST_F(ArchiveSchemaTest, NewArchiveGetsTheLatestSchemaAndMigratingAgainIsANoOp) {
  auto conn = Connect();
  ASSERT_NE(conn, nullptr);
  EXPECT_GE(conn->server_version(), 120000);
  EXPECT_EQ(*ArchiveVersion(*conn), 0);
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  EXPECT_EQ(*ArchiveVersion(*conn), LatestArchiveVersion());
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM archive_schema"),
            std::to_string(LatestArchiveVersion()));
  EXPECT_EQ(
      *pg_->Psql("SELECT string_agg(table_name, ',' ORDER BY table_name) FROM "
                 "information_schema.tables WHERE table_schema = 'public'"),
      "adaptive_rounds,archive_schema,audit,devices,reading_uncertainty,readings,session_events,"
      "sessions,steps");
}

// An archive of version 4 (before adaptive rounds) with a session in it migrates to the latest;
// the session is kept and has no rounds (brdf-archive answers an empty list).
TEST_F(ArchiveSchemaTest, AnArchiveBeforeRoundsMigratesAndItsSessionsHaveNone) {
  auto conn = Connect();
  ASSERT_NE(conn, nullptr);
  ASSERT_TRUE(MigrateArchive(*conn, ArchiveMigrations().first(4)).ok());
  EXPECT_EQ(*ArchiveVersion(*conn), 4);
  EXPECT_EQ(*pg_->Psql("SELECT to_regclass('adaptive_rounds') IS NULL"), "t");
  ASSERT_TRUE(pg_->Psql("INSERT INTO sessions (uuid, rig, rig_session_id, name, plan_kind, "
                        "plan_json, state, created_at, total_steps, done_steps) VALUES "
                        "('7d1c4bd8-7a29-4f6e-9a57-1bb2a5f7c9e1', 'rig-a', 1, 'old', 'adaptive', "
                        "'{}', 'completed', 1765000000.5, 3, 3)")
                  .ok());
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  EXPECT_EQ(*ArchiveVersion(*conn), LatestArchiveVersion());
  EXPECT_EQ(*pg_->Psql("SELECT count(*) FROM adaptive_rounds"), "0");
  auto reader = ArchiveReader::Open(pg_->conninfo());
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  const std::int64_t id = std::stoll(*pg_->Psql("SELECT archive_id FROM sessions"));
  Result<SessionRecord> session = (*reader)->GetSession(id);
  ASSERT_TRUE(session.ok()) << session.status().ToString();
  EXPECT_EQ(session->name, "old");
  Result<std::vector<ArchivedRound>> rounds = (*reader)->GetRounds(id);
  ASSERT_TRUE(rounds.ok()) << rounds.status().ToString();
  EXPECT_TRUE(rounds->empty());
}

TEST_F(ArchiveSchemaTest, TwoConnectionsMigratingAtOnceBothSucceed) {
  auto a = Connect();
  auto b = Connect();
  ASSERT_TRUE(a && b);
  Status sa, sb;
  std::thread t([&] { sa = MigrateArchive(*a); });
  sb = MigrateArchive(*b);
  t.join();
  EXPECT_TRUE(sa.ok()) << sa.ToString();
  EXPECT_TRUE(sb.ok()) << sb.ToString();
  EXPECT_EQ(*ArchiveVersion(*a), LatestArchiveVersion());
}

TEST_F(ArchiveSchemaTest, NewerArchiveIsRefused) {
  auto conn = Connect();
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  ASSERT_TRUE(
      pg_->Psql("INSERT INTO archive_schema (version, description) VALUES (99, 'later')").ok());
  Status s = MigrateArchive(*conn);
  EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition);
  EXPECT_THAT(s.message(), HasSubstr("schema version 99"));
}

TEST_F(ArchiveSchemaTest, ServerNoticesGoToTheLogAtDebugLevelNotToStderr) {
  auto conn = Connect();
  ASSERT_NE(conn, nullptr);
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  auto ring = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(64);
  auto logger = std::make_shared<spdlog::logger>("notices", ring);
  logger->set_level(spdlog::level::debug);
  std::shared_ptr<spdlog::logger> before = spdlog::default_logger();
  spdlog::set_default_logger(logger);
  ::testing::internal::CaptureStderr();
  // Every reconnect of a rig migrates: an archive at this build's version is only read.
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  std::vector<std::string> logged = ring->last_formatted();
  // A statement that makes the server say something: it reaches the log, not stderr.
  ASSERT_TRUE(conn->Exec("CREATE TABLE IF NOT EXISTS archive_schema (version integer)").ok());
  const std::string err = ::testing::internal::GetCapturedStderr();
  spdlog::set_default_logger(before);
  EXPECT_TRUE(logged.empty()) << logged.front();
  std::vector<std::string> after = ring->last_formatted();
  ASSERT_EQ(after.size(), 1u);
  EXPECT_THAT(after[0], HasSubstr("PostgreSQL says: NOTICE:"));
  EXPECT_THAT(after[0], HasSubstr("already exists, skipping"));
  EXPECT_THAT(after[0], HasSubstr("[debug]"));
  EXPECT_EQ(err, "");
}

TEST_F(ArchiveSchemaTest, AConnectionCutDuringTheCheckSaysTheCheckFailedNotAMigration) {
  auto conn = Connect();
  ASSERT_NE(conn, nullptr);
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  ASSERT_TRUE(pg_->Psql("SELECT count(pg_terminate_backend(pid)) FROM pg_stat_activity WHERE "
                        "application_name = 'brdfd'")
                  .ok());
  Status s = MigrateArchive(*conn);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.message(), HasSubstr("checking the archive's schema version"));
  EXPECT_THAT(s.message(), Not(HasSubstr("migrating")));
}

TEST_F(ArchiveSchemaTest, WrongPasswordAndUnreachableServerSayWhatHappened) {
  auto wrong = PgConnection::Open(pg_->conninfo_with_password("not-the-password-42"));
  ASSERT_FALSE(wrong.ok());
  EXPECT_EQ(wrong.status().code(), StatusCode::kConfigurationError) << wrong.status().ToString();
  EXPECT_THAT(wrong.status().message(), HasSubstr("password"));
  EXPECT_THAT(wrong.status().message(), Not(HasSubstr("not-the-password-42")));
  ASSERT_TRUE(pg_->Stop().ok());
  auto away = PgConnection::Open(pg_->conninfo());
  ASSERT_FALSE(away.ok());
  EXPECT_EQ(away.status().code(), StatusCode::kDisconnected) << away.status().ToString();
}

TEST_F(ArchiveSchemaTest, ValuesRoundTripExactly) {
  auto conn = Connect();
  ASSERT_TRUE(MigrateArchive(*conn).ok());
  const double tricky[] = {0.1, 1.0 / 3.0, 5e-324, 1.7976931348623157e308, -0.0, 123456.789e-7};
  for (double v : tricky) {
    Result<PgResult> r = conn->Query("SELECT $1::double precision", PgParams().Add(v));
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    const double back = r->Double(0, 0);
    EXPECT_EQ(std::memcmp(&back, &v, sizeof v), 0) << v << " came back as " << back;
  }
  const std::vector<std::uint8_t> bytes = {0, 1, 0x5c, 0x78, 0xff, 0};
  Result<PgResult> r = conn->Query("SELECT $1::bytea", PgParams().AddBytes(bytes));
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->Bytes(0, 0), bytes);
}

}  // namespace
}  // namespace brdf::storage
