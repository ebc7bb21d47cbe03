// brdf-archive against a real PostgreSQL and a real rig: brdf-sim and brdfd (processes) record
// and ship; two brdf-archive processes serve the archive. For the same session the archive
// answers Interpolate, InterpolateBatch, StreamReadings and Export exactly as the rig's brdfd does
// (the messages compared field by field, doubles exactly; the exported files byte for byte),
// ListSessions filters and pages across the catalogue (brdfd applies the same filters), an adaptive
// session's rounds are listed as the rig lists them, the rig's verbs are refused naming the rig,
// and brdfctl works against it unchanged.
#include <gmock/gmock.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "daemon/config/config.h"
#include "tests/archive/archive_status.h"
#include "tests/brdfctl/ctl_runner.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/pg/server_fixture.h"
#include "tests/support/plan_fixtures.h"
#include "tests/support/process_launcher.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;
using ::google::protobuf::util::MessageDifferencer;
using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;

constexpr std::string_view kListening = "brdf-archive listening on ";

// One brdf-archive process and its stubs.
class ArchiveProcess {
 public:
  static Result<std::unique_ptr<ArchiveProcess>> Start(const std::string& config,
                                                       const std::string& log) {
    BRDF_ASSIGN_OR_RETURN(std::string binary, BuiltProgram("brdf-archive", "daemon/brdf-archive",
                                                           "BRDF_ARCHIVE_BINARY"));
    LaunchOptions options({"--config", config});
    options.stderr_to = LaunchOptions::Stderr::kAppendToFile;
    options.stderr_path = log;
    BRDF_ASSIGN_OR_RETURN(std::unique_ptr<ChildProcess> child,
                          ChildProcess::Launch("brdf-archive", binary, options));
    std::unique_ptr<ArchiveProcess> a(new ArchiveProcess());
    a->child_ = std::move(child);
    Result<std::string> line = a->child_->ReadLine(Clock::now() + 15s);
    if (!line.ok() || line->rfind(kListening, 0) != 0) {
      return Internal("brdf-archive did not start: " +
                      (line.ok() ? *line : line.status().ToString()));
    }
    a->address_ = line->substr(kListening.size());
    a->channel_ = grpc::CreateChannel(a->address_, grpc::InsecureChannelCredentials());
    a->control_ = v1::Control::NewStub(a->channel_);
    a->data_ = v1::Data::NewStub(a->channel_);
    a->interpolation_ = v1::Interpolation::NewStub(a->channel_);
    return a;
  }
  std::optional<int> Stop() { return child_->Terminate(10s); }

  const std::string& address() const { return address_; }
  v1::Control::Stub& control() { return *control_; }
  v1::Data::Stub& data() { return *data_; }
  v1::Interpolation::Stub& interpolation() { return *interpolation_; }

 private:
  ArchiveProcess() = default;
  std::unique_ptr<ChildProcess> child_;
  std::string address_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Control::Stub> control_;
  std::unique_ptr<v1::Data::Stub> data_;
  std::unique_ptr<v1::Interpolation::Stub> interpolation_;
};

// `text` with "session <id>" written "session <as>".
std::string WithId(std::string text, const std::string& id, const std::string& as) {
  const std::string from = "session " + id;
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + 1)) {
    const std::size_t end = at + from.size();
    if (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) continue;
    text.replace(at, from.size(), "session " + as);
  }
  return text;
}

// The plan's JSON with a sample block.
std::string WithSample(const std::string& plan_json, const std::string& sample_json) {
  return "{\"sample\": " + sample_json + ", " + plan_json.substr(plan_json.find('{') + 1);
}

const std::string kPaint =
    R"({"id": "P-0042", "name": "Red Gloss", "material": "paint", "tags": ["glossy", "red"]})";
const std::string kFabric =
    R"({"id": "F-0007", "name": "grey felt", "material": "fabric", "tags": ["matte"]})";

// Every (θi, θo, φ) of a small grid over and around the session's readings.
std::vector<v1::DirectionQuery> Directions() {
  std::vector<v1::DirectionQuery> out;
  for (double ti : {0.0, 7.5, 15.0, 22.0, 35.0}) {
    for (double to : {10.0, 20.0, 31.0, 40.0}) {
      for (double phi : {0.0, 45.0, 120.0, 170.0, 180.0}) {
        v1::DirectionQuery q;
        q.mutable_iso()->set_theta_i(ti);
        q.mutable_iso()->set_theta_o(to);
        q.mutable_iso()->set_phi(phi);
        out.push_back(q);
      }
    }
  }
  return out;
}

class ArchiveServerTest : public PgServerTest {
 protected:
  void SetUp() override {
    PgServerTest::SetUp();
    if (!PgReady()) return;
    rig_ = std::make_unique<DaemonRig>();
    const Status sim = rig_->StartSim();
    ASSERT_TRUE(sim.ok()) << sim.ToString();
    const std::string cred = rig_->dir().file("archive.conninfo").string();
    ASSERT_TRUE(PgServer::WriteCredentials(cred, pg_->conninfo()).ok());
    const std::string toml = DaemonConfigToml(rig_->sim(), rig_->database()) +
                             "[rig]\nname = \"rig-a\"\n[archive]\ncredentials = \"" + cred +
                             "\"\nretry_ms = 100\n";
    Status daemon = rig_->StartDaemon(toml);
    ASSERT_TRUE(daemon.ok()) << daemon.ToString();
  }
  void TearDown() override {
    for (auto& op : operators_) op->Stop();
    for (auto& a : archives_) (void)a->Stop();
    if (rig_ != nullptr && rig_->daemon() != nullptr) (void)rig_->StopDaemon();
    if (HasFailure() && rig_ != nullptr) std::cerr << "---- brdfd log ----\n" << rig_->log();
    if (HasFailure()) {
      for (std::size_t i = 0; i < archives_.size(); ++i) {
        std::ifstream in(rig_->dir().file("archive" + std::to_string(i) + ".log"));
        std::cerr << "---- brdf-archive " << i << " log ----\n" << in.rdbuf();
      }
    }
  }

  // Submits (started), with an operator answering its prompts.
  v1::Session Submit(const std::string& plan_json) {
    Result<v1::Session> s = rig_->Submit(plan_json);
    EXPECT_TRUE(s.ok()) << s.status().ToString();
    if (!s.ok()) return {};
    operators_.push_back(std::make_unique<GrpcOperator>(*rig_, s->session_id()));
    return *s;
  }
  bool WaitCaughtUp() {
    return WaitRigArchiveStatus(*rig_, [](const v1::ArchiveStatus& s) {
      return s.state() == v1::ARCHIVE_STATE_CAUGHT_UP && s.lag_readings() == 0;
    });
  }
  ArchiveProcess& StartArchive() {
    const std::size_t i = archives_.size();
    const std::string cred = rig_->dir().file("archive-server.conninfo").string();
    EXPECT_TRUE(PgServer::WriteCredentials(cred, pg_->conninfo()).ok());
    const std::string config = rig_->dir().file("archive" + std::to_string(i) + ".toml").string();
    std::ofstream(config) << "[server]\nlisten = \"127.0.0.1:0\"\n[archive]\ncredentials = \""
                          << cred << "\"\n[[auth.tokens]]\nname = \"op\"\ntoken = \""
                          << kOperatorToken
                          << "\"\nrole = \"operator\"\n[[auth.tokens]]\nname = \"an\"\ntoken = \""
                          << kAnalystToken << "\"\nrole = \"analyst\"\n";
    Result<std::unique_ptr<ArchiveProcess>> a = ArchiveProcess::Start(
        config, rig_->dir().file("archive" + std::to_string(i) + ".log").string());
    if (!a.ok()) {
      ADD_FAILURE() << a.status().ToString();
      throw std::runtime_error("brdf-archive did not start");
    }
    archives_.push_back(std::move(*a));
    return *archives_.back();
  }

  // ListSessions (every page), as uuids.
  static std::vector<std::string> Uuids(v1::Control::Stub& control,
                                        v1::ListSessionsRequest request) {
    std::vector<std::string> out;
    for (int pages = 0; pages < 100; ++pages) {
      v1::ListSessionsResponse page;
      grpc::Status st =
          control.ListSessions(DaemonRig::Context(kAnalystToken).get(), request, &page);
      EXPECT_TRUE(st.ok()) << st.error_message();
      if (!st.ok()) break;
      for (const v1::Session& s : page.sessions()) out.push_back(s.uuid());
      if (page.next_page_token().empty()) break;
      request.set_page_token(page.next_page_token());
    }
    return out;
  }

  // The archive's id of the session with `uuid`.
  static std::string ArchiveId(ArchiveProcess& a, const std::string& uuid) {
    v1::ListSessionsResponse all;
    EXPECT_TRUE(a.control().ListSessions(DaemonRig::Context().get(), {}, &all).ok());
    for (const v1::Session& s : all.sessions()) {
      if (s.uuid() == uuid) return s.session_id();
    }
    ADD_FAILURE() << "session " << uuid << " is not in the archive";
    return "";
  }

  // Interpolate at every direction: the responses (or the statuses, as "code: message").
  // `base`: the request's other fields (method, options, include_vertex_spectra).
  static std::vector<std::string> InterpolateAll(v1::Interpolation::Stub& stub,
                                                 const std::string& id, v1::Quantity quantity,
                                                 const v1::InterpolateRequest& base = {}) {
    std::vector<std::string> out;
    for (const v1::DirectionQuery& d : Directions()) {
      v1::InterpolateRequest request = base;
      request.set_session_id(id);
      request.set_quantity(quantity);
      *request.mutable_direction() = d;
      v1::InterpolateResponse response;
      grpc::Status st =
          stub.Interpolate(DaemonRig::Context(kAnalystToken).get(), request, &response);
      out.push_back(st.ok() ? response.SerializeAsString()
                            : std::to_string(st.error_code()) + ": " + st.error_message());
    }
    return out;
  }
  static std::vector<v1::InterpolationResult> Batch(
      v1::Interpolation::Stub& stub, const std::string& id,
      v1::InterpolationCoordinates coordinates = v1::INTERPOLATION_COORDINATES_UNSPECIFIED) {
    v1::InterpolateBatchRequest request;
    request.set_session_id(id);
    request.mutable_options()->set_coordinates(coordinates);
    request.set_quantity(v1::QUANTITY_BRDF);
    for (const v1::DirectionQuery& d : Directions()) *request.add_directions() = d;
    request.set_chunk_size(16);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = stub.InterpolateBatch(context.get(), request);
    std::vector<v1::InterpolationResult> out;
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
      for (const v1::InterpolationResult& r : chunk.results()) out.push_back(r);
    }
    grpc::Status st = reader->Finish();
    EXPECT_TRUE(st.ok()) << st.error_message();
    return out;
  }
  static std::vector<v1::Reading> Readings(v1::Data::Stub& data, const std::string& id) {
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = data.StreamReadings(context.get(), request);
    std::vector<v1::Reading> out;
    v1::Reading r;
    while (reader->Read(&r)) out.push_back(r);
    grpc::Status st = reader->Finish();
    EXPECT_TRUE(st.ok()) << st.error_message();
    return out;
  }
  // Every ReadingPoints message of the session's readings, serialized and concatenated.
  static std::string Points(v1::Data::Stub& data, const std::string& id) {
    v1::StreamReadingsRequest request;
    request.set_session_id(id);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = data.StreamReadingPoints(context.get(), request);
    std::string out;
    v1::ReadingPoints points;
    while (reader->Read(&points)) out += points.SerializeAsString();
    grpc::Status st = reader->Finish();
    EXPECT_TRUE(st.ok()) << st.error_message();
    return out;
  }
  // An exported file's bytes and the export's report.
  static std::pair<std::string, v1::ExportReport> Export(v1::Data::Stub& data,
                                                         v1::ExportRequest request,
                                                         const std::string& id) {
    request.set_session_id(id);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = data.Export(context.get(), request);
    std::pair<std::string, v1::ExportReport> out;
    v1::ExportChunk chunk;
    while (reader->Read(&chunk)) {
      if (chunk.has_data()) out.first += chunk.data().content();
      if (chunk.has_report()) out.second = chunk.report();
    }
    grpc::Status st = reader->Finish();
    EXPECT_TRUE(st.ok()) << st.error_message();
    return out;
  }

  std::unique_ptr<DaemonRig> rig_;
  std::vector<std::unique_ptr<GrpcOperator>> operators_;
  std::vector<std::unique_ptr<ArchiveProcess>> archives_;
};

TEST_F(ArchiveServerTest, TwoReplicasAnswerBitForBitWhatTheRigAnswers) {
  const v1::Session paint = Submit(WithSample(plans::InterpolationGrid(), kPaint));
  const v1::Session felt = Submit(WithSample(plans::TinyPoseList(), kFabric));
  for (const v1::Session& s : {paint, felt}) {
    ASSERT_EQ(rig_->WaitForState(s.session_id(), v1::SESSION_STATE_COMPLETED, 120s).state(),
              v1::SESSION_STATE_COMPLETED);
  }
  ASSERT_TRUE(WaitCaughtUp());
  ArchiveProcess& a = StartArchive();
  ArchiveProcess& b = StartArchive();

  // The catalogue, across the archive; the rig's brdfd filters the same way.
  const std::string p = paint.uuid();
  const std::string f = felt.uuid();
  v1::ListSessionsRequest q;
  for (v1::Control::Stub* control : {&a.control(), &b.control(), &rig_->control()}) {
    EXPECT_EQ(Uuids(*control, q), (std::vector<std::string>{f, p}));  // newest first
    q.set_material("PAINT");
    EXPECT_EQ(Uuids(*control, q), std::vector<std::string>{p});
    q.Clear();
    q.set_tag("matte");
    EXPECT_EQ(Uuids(*control, q), std::vector<std::string>{f});
    q.Clear();
    q.set_sample("red gloss");
    EXPECT_EQ(Uuids(*control, q), std::vector<std::string>{p});
    q.set_sample("F-0007");
    EXPECT_EQ(Uuids(*control, q), std::vector<std::string>{f});
    q.Clear();
    q.set_rig("rig-a");
    q.add_states(v1::SESSION_STATE_COMPLETED);
    q.set_page_size(1);  // two pages
    EXPECT_EQ(Uuids(*control, q), (std::vector<std::string>{f, p}));
    q.set_rig("rig-b");
    EXPECT_TRUE(Uuids(*control, q).empty());
    q.Clear();
    q.mutable_created_before()->set_seconds(paint.created_at().seconds() - 1);
    EXPECT_TRUE(Uuids(*control, q).empty());
    q.Clear();
    q.mutable_created_after()->set_seconds(paint.created_at().seconds() - 1);
    EXPECT_EQ(Uuids(*control, q).size(), 2U);
    q.Clear();
  }

  const std::string id_a = ArchiveId(a, p);
  ASSERT_EQ(id_a, ArchiveId(b, p)) << "replicas number sessions alike";
  v1::GetSessionRequest get;
  get.set_session_id(id_a);
  v1::Session archived;
  ASSERT_TRUE(a.control().GetSession(DaemonRig::Context().get(), get, &archived).ok());
  const v1::Session on_rig = *rig_->Get(paint.session_id());
  EXPECT_EQ(archived.uuid(), p);
  EXPECT_EQ(archived.rig(), "rig-a");
  EXPECT_EQ(archived.state(), v1::SESSION_STATE_COMPLETED);
  EXPECT_TRUE(MessageDifferencer::Equals(archived.plan(), on_rig.plan()));
  EXPECT_TRUE(MessageDifferencer::Equals(archived.sample(), on_rig.sample()));
  EXPECT_TRUE(MessageDifferencer::Equals(archived.progress(), on_rig.progress()));
  EXPECT_TRUE(MessageDifferencer::Equals(archived.created_at(), on_rig.created_at()));
  // The session's wavelength grid (its first reading's), as the rig says it.
  ASSERT_TRUE(on_rig.has_grid());
  EXPECT_EQ(on_rig.grid().count(), 101U);
  EXPECT_TRUE(MessageDifferencer::Equals(archived.grid(), on_rig.grid()))
      << archived.grid().ShortDebugString() << " vs " << on_rig.grid().ShortDebugString();
  // The session's history of states: the rig's, byte for byte (the same ids and times), on both
  // replicas, for the analyst too; an unknown archive id is NOT_FOUND.
  {
    v1::ListSessionEventsRequest ask;
    ask.set_session_id(paint.session_id());
    v1::ListSessionEventsResponse rig_events, a_events, b_events;
    grpc::Status st =
        rig_->control().ListSessionEvents(DaemonRig::Context().get(), ask, &rig_events);
    ASSERT_TRUE(st.ok()) << st.error_message();
    ASSERT_GE(rig_events.events_size(), 3);  // queued, running, …, completed
    EXPECT_EQ(rig_events.events(0).state(), v1::SESSION_STATE_QUEUED);
    EXPECT_EQ(rig_events.events(rig_events.events_size() - 1).state(), v1::SESSION_STATE_COMPLETED);
    ask.set_session_id(id_a);
    st = a.control().ListSessionEvents(DaemonRig::Context(kAnalystToken).get(), ask, &a_events);
    ASSERT_TRUE(st.ok()) << st.error_message();
    st = b.control().ListSessionEvents(DaemonRig::Context().get(), ask, &b_events);
    ASSERT_TRUE(st.ok()) << st.error_message();
    EXPECT_EQ(a_events.SerializeAsString(), rig_events.SerializeAsString())
        << a_events.DebugString() << "\nrig:\n"
        << rig_events.DebugString();
    EXPECT_EQ(b_events.SerializeAsString(), rig_events.SerializeAsString());
    ask.set_session_id("987654");
    st = a.control().ListSessionEvents(DaemonRig::Context().get(), ask, &a_events);
    EXPECT_EQ(st.error_code(), grpc::StatusCode::NOT_FOUND) << st.error_message();
    EXPECT_THAT(st.error_message(), HasSubstr("987654"));
  }

  // Interpolate in every quantity: byte for byte the rig's responses, on both replicas.
  for (v1::Quantity quantity :
       {v1::QUANTITY_BRDF, v1::QUANTITY_REFLECTANCE, v1::QUANTITY_RADIANCE}) {
    const std::vector<std::string> rig_answers =
        InterpolateAll(rig_->interpolation(), paint.session_id(), quantity);
    int answered = 0;
    for (const std::string& s : rig_answers) answered += s.find(": ") == std::string::npos;
    EXPECT_GT(answered, 20) << "the grid should mostly be answerable";
    EXPECT_EQ(InterpolateAll(a.interpolation(), id_a, quantity), rig_answers);
    EXPECT_EQ(InterpolateAll(b.interpolation(), id_a, quantity), rig_answers);
  }
  // With the vertices' own spectra (Figure 8 in one call; Delaunay, which answers most of the
  // grid): the rig's bytes too, spectra and all.
  {
    v1::InterpolateRequest figure8;
    figure8.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
    const std::vector<std::string> without =
        InterpolateAll(rig_->interpolation(), paint.session_id(), v1::QUANTITY_BRDF, figure8);
    figure8.set_include_vertex_spectra(true);
    const std::vector<std::string> with =
        InterpolateAll(rig_->interpolation(), paint.session_id(), v1::QUANTITY_BRDF, figure8);
    int longer = 0;  // answers that gained their vertices' spectra
    for (std::size_t i = 0; i < with.size() && i < without.size(); ++i) {
      longer += with[i].size() > without[i].size();
    }
    EXPECT_GT(longer, 20);
    EXPECT_TRUE(InterpolateAll(a.interpolation(), id_a, v1::QUANTITY_BRDF, figure8) == with);
  }
  const std::vector<v1::InterpolationResult> rig_batch =
      Batch(rig_->interpolation(), paint.session_id());
  ASSERT_EQ(rig_batch.size(), Directions().size());
  for (ArchiveProcess* server : {&a, &b}) {
    const std::vector<v1::InterpolationResult> batch = Batch(server->interpolation(), id_a);
    ASSERT_EQ(batch.size(), rig_batch.size());
    for (std::size_t i = 0; i < batch.size(); ++i) {
      EXPECT_EQ(batch[i].SerializeAsString(), rig_batch[i].SerializeAsString())
          << "direction " << i;
    }
  }
  // The colour and lit sphere (RenderAppearance, the same service code): the rig's images,
  // byte for byte.
  {
    v1::AppearanceRequest look;
    look.set_sphere_size(32);
    look.set_session_id(paint.session_id());
    v1::AppearanceResponse on_rig_look, archived_look;
    grpc::Status st = rig_->interpolation().RenderAppearance(
        DaemonRig::Context(kAnalystToken).get(), look, &on_rig_look);
    ASSERT_TRUE(st.ok()) << st.error_message();
    look.set_session_id(id_a);
    st = a.interpolation().RenderAppearance(DaemonRig::Context(kAnalystToken).get(), look,
                                            &archived_look);
    ASSERT_TRUE(st.ok()) << st.error_message();
    ASSERT_EQ(on_rig_look.images_size(), 2);
    EXPECT_EQ(archived_look.SerializeAsString(), on_rig_look.SerializeAsString());
  }
  // In half/difference coordinates too (the same service code): the rig's answers, which are
  // not the incidence ones.
  const std::vector<v1::InterpolationResult> rig_half = Batch(
      rig_->interpolation(), paint.session_id(), v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE);
  ASSERT_EQ(rig_half.size(), rig_batch.size());
  int differ = 0;
  for (std::size_t i = 0; i < rig_half.size(); ++i) {
    differ += rig_half[i].SerializeAsString() != rig_batch[i].SerializeAsString();
  }
  EXPECT_GT(differ, 0);
  const std::vector<v1::InterpolationResult> archive_half =
      Batch(b.interpolation(), id_a, v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE);
  ASSERT_EQ(archive_half.size(), rig_half.size());
  for (std::size_t i = 0; i < archive_half.size(); ++i) {
    EXPECT_EQ(archive_half[i].SerializeAsString(), rig_half[i].SerializeAsString())
        << "direction " << i << " in half/difference coordinates";
  }

  // The readings, as the rig streams them (but for the session id, which is the archive's).
  std::vector<v1::Reading> rig_readings = Readings(rig_->data(), paint.session_id());
  std::vector<v1::Reading> archive_readings = Readings(b.data(), id_a);
  ASSERT_EQ(archive_readings.size(), rig_readings.size());
  ASSERT_GT(rig_readings.size(), 10U);
  for (std::size_t i = 0; i < rig_readings.size(); ++i) {
    EXPECT_EQ(archive_readings[i].session_id(), id_a);
    archive_readings[i].set_session_id(rig_readings[i].session_id());
    EXPECT_EQ(archive_readings[i].SerializeAsString(), rig_readings[i].SerializeAsString())
        << "reading " << rig_readings[i].id();
  }
  // And as columns (StreamReadingPoints, read without the spectra): the rig's bytes.
  const std::string rig_points = Points(rig_->data(), paint.session_id());
  EXPECT_GT(rig_points.size(), 100U);
  EXPECT_EQ(Points(a.data(), id_a), rig_points);
  EXPECT_EQ(Points(b.data(), id_a), rig_points);

  // Every export format: the rig's file byte for byte (the readings CSV names the session by
  // the server's id in its first line, and the file name carries it).
  v1::ExportRequest csv;
  csv.set_format(v1::EXPORT_FORMAT_READINGS_CSV);
  v1::ExportRequest grid;
  grid.set_format(v1::EXPORT_FORMAT_GRID_NPY);
  grid.set_step_theta_i(15);
  grid.set_step_theta_o(15);
  grid.set_step_phi(30);
  v1::ExportRequest rgl;
  rgl.set_format(v1::EXPORT_FORMAT_RGL_BSDF);
  rgl.set_rgl_theta_i_count(4);
  rgl.set_rgl_resolution(8);
  v1::ExportRequest merl;
  merl.set_format(v1::EXPORT_FORMAT_MERL_BINARY);
  merl.set_fill(v1::EXPORT_FILL_NONE);
  for (const v1::ExportRequest& request : {csv, grid, rgl, merl}) {
    auto [rig_file, rig_report] = Export(rig_->data(), request, paint.session_id());
    auto [archive_file, archive_report] = Export(b.data(), request, id_a);
    ASSERT_GT(rig_file.size(), 100U) << v1::ExportFormat_Name(request.format());
    if (request.format() == v1::EXPORT_FORMAT_READINGS_CSV) {
      EXPECT_THAT(archive_file.substr(0, archive_file.find('\n')), HasSubstr("session " + id_a));
      rig_file.erase(0, rig_file.find('\n'));
      archive_file.erase(0, archive_file.find('\n'));
    }
    EXPECT_TRUE(archive_file == rig_file) << v1::ExportFormat_Name(request.format());
    archive_report.clear_file_name();
    rig_report.clear_file_name();
    EXPECT_EQ(archive_report.SerializeAsString(), rig_report.SerializeAsString())
        << v1::ExportFormat_Name(request.format());
  }
}

TEST_F(ArchiveServerTest, RefusesTheRigsVerbsAndUnknownSessionsAndChecksTokens) {
  const v1::Session s = Submit(plans::TinyPoseList());
  ASSERT_EQ(rig_->WaitForState(s.session_id(), v1::SESSION_STATE_COMPLETED, 60s).state(),
            v1::SESSION_STATE_COMPLETED);
  ASSERT_TRUE(WaitCaughtUp());
  ArchiveProcess& a = StartArchive();
  const std::string id = ArchiveId(a, s.uuid());

  v1::PauseSessionRequest pause;
  pause.set_session_id(id);
  v1::PauseSessionResponse paused;
  grpc::Status st = a.control().PauseSession(DaemonRig::Context().get(), pause, &paused);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(st.error_message(), HasSubstr("brdf-archive"));
  EXPECT_THAT(st.error_message(), HasSubstr("rig \"rig-a\"'s brdfd"));
  v1::SubmitPlanRequest submit;
  v1::SubmitPlanResponse submitted;
  st = a.control().SubmitPlan(DaemonRig::Context(kAnalystToken).get(), submit, &submitted);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::PERMISSION_DENIED) << "roles as on a rig";
  v1::RigStatus rig_status;
  st = a.control().GetRigStatus(DaemonRig::Context().get(), {}, &rig_status);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION);

  v1::GetSessionRequest get;
  get.set_session_id(id);
  v1::Session got;
  st = a.control().GetSession(DaemonRig::Context("").get(), get, &got);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  get.set_session_id("987654");
  st = a.control().GetSession(DaemonRig::Context().get(), get, &got);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::NOT_FOUND) << st.error_message();
  v1::ListSessionsRequest list;
  list.set_page_token("17");
  v1::ListSessionsResponse listed;
  st = a.control().ListSessions(DaemonRig::Context().get(), list, &listed);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(st.error_message(), HasSubstr("page_token"));
}

// An adaptive session (docs/adaptive.md): brdf-archive answers ListAdaptiveRounds with the rounds
// the rig shipped, message for message what the rig's brdfd answers (the spend the rig computed
// included); a session of another kind has none, an unknown one is NOT_FOUND.
TEST_F(ArchiveServerTest, ListAdaptiveRoundsAnswersWhatTheRigAnswers) {
  // Three detector positions, a seed of 3 + 3 × 4, rounds of 6 to 27 readings.
  const v1::Session adaptive = Submit(R"({
    "name": "adaptive, archived",
    "adaptive": {
      "target": {"expandedUncertainty": 0.001},
      "budget": {"maxReadings": 27},
      "region": {"thetaIMaxDeg": 80, "thetaOMaxDeg": 80},
      "method": "ADAPTIVE_JUDGE_OCTANT",
      "delta": {"start": 0, "stop": 22.5, "step": 11.25},
      "seed": {"retroReadings": 3, "readingsPerDelta": 4},
      "roundReadings": 6
    },
    "reference": {"perDetectorPosition": true},
    "measurement": {"integrationMs": 100, "averages": 1}
  })");
  const v1::Session plain = Submit(plans::TinyPoseList());
  for (const v1::Session& s : {adaptive, plain}) {
    ASSERT_EQ(rig_->WaitForState(s.session_id(), v1::SESSION_STATE_COMPLETED, 180s).state(),
              v1::SESSION_STATE_COMPLETED);
  }
  ASSERT_TRUE(WaitCaughtUp());
  ArchiveProcess& a = StartArchive();
  auto rounds = [](v1::Control::Stub& control, const std::string& id,
                   v1::ListAdaptiveRoundsResponse* out) {
    v1::ListAdaptiveRoundsRequest request;
    request.set_session_id(id);
    return control.ListAdaptiveRounds(DaemonRig::Context(kAnalystToken).get(), request, out);
  };
  v1::ListAdaptiveRoundsResponse from_rig;
  grpc::Status st = rounds(rig_->control(), adaptive.session_id(), &from_rig);
  ASSERT_TRUE(st.ok()) << st.error_message();
  ASSERT_GE(from_rig.rounds_size(), 1);
  v1::ListAdaptiveRoundsResponse from_archive;
  st = rounds(a.control(), ArchiveId(a, adaptive.uuid()), &from_archive);
  ASSERT_TRUE(st.ok()) << st.error_code() << ": " << st.error_message();
  EXPECT_TRUE(MessageDifferencer::Equals(from_archive, from_rig))
      << "archive:\n"
      << from_archive.DebugString() << "rig:\n"
      << from_rig.DebugString();
  EXPECT_GT(from_archive.rounds(0).spent_rig_s(), 0);

  v1::ListAdaptiveRoundsResponse none;
  st = rounds(a.control(), ArchiveId(a, plain.uuid()), &none);
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(none.rounds_size(), 0);
  st = rounds(a.control(), "987654", &none);
  EXPECT_EQ(st.error_code(), grpc::StatusCode::NOT_FOUND) << st.error_message();
}

TEST_F(ArchiveServerTest, BrdfctlAndThePythonClientReadTheArchiveUnchanged) {
  const v1::Session paint = Submit(WithSample(plans::InterpolationGrid(), kPaint));
  ASSERT_EQ(rig_->WaitForState(paint.session_id(), v1::SESSION_STATE_COMPLETED, 120s).state(),
            v1::SESSION_STATE_COMPLETED);
  ASSERT_TRUE(WaitCaughtUp());
  ArchiveProcess& a = StartArchive();
  const std::string id = ArchiveId(a, paint.uuid());
  const EnvVars archive_env{{"BRDF_ADDRESS", a.address()}, {"BRDF_TOKEN", kAnalystToken}};
  const EnvVars rig_env{{"BRDF_ADDRESS", rig_->daemon()->address()}, {"BRDF_TOKEN", kAnalystToken}};

  Result<CommandResult> list = RunBrdfctl({"list", "--material", "paint"}, archive_env);
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->exit_code, 0) << list->err;
  ASSERT_EQ(Lines(list->out).size(), 1U) << list->out;
  EXPECT_THAT(list->out, HasSubstr(id + "  completed"));
  EXPECT_THAT(list->out, HasSubstr("(rig rig-a)"));
  Result<CommandResult> none = RunBrdfctl({"list", "--tag", "no-such-tag"}, archive_env);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->out, "no sessions match\n");

  // The same answer, to the byte; and the same refusal where the octant method finds no sample.
  for (const std::vector<std::string>& where :
       {std::vector<std::string>{"--theta-i", "15", "--theta-o", "31", "--phi", "170", "--method",
                                 "nearest"},
        std::vector<std::string>{"--theta-i", "15", "--theta-o", "31", "--phi", "170"}}) {
    std::vector<std::string> on_archive = {"interpolate", id};
    std::vector<std::string> on_rig = {"interpolate", paint.session_id()};
    on_archive.insert(on_archive.end(), where.begin(), where.end());
    on_rig.insert(on_rig.end(), where.begin(), where.end());
    Result<CommandResult> from_archive = RunBrdfctl(on_archive, archive_env);
    Result<CommandResult> from_rig = RunBrdfctl(on_rig, rig_env);
    ASSERT_TRUE(from_archive.ok() && from_rig.ok());
    EXPECT_EQ(from_archive->exit_code, from_rig->exit_code) << from_archive->err;
    // The same text but for the session id ("session 7: …"), which is the archive's there.
    EXPECT_EQ(WithId(from_archive->out, id, "ID"), WithId(from_rig->out, paint.session_id(), "ID"));
    EXPECT_EQ(WithId(from_archive->err, id, "ID"), WithId(from_rig->err, paint.session_id(), "ID"));
    if (where.size() == 8) {
      EXPECT_EQ(from_rig->exit_code, 0) << from_rig->err;
      EXPECT_GT(Lines(from_rig->out).size(), 10U);
    }
  }

  // The Python client, unchanged, reads the archive as it reads the rig
  // (tests/archive/python_client_check.py says what it compares).
  const char* build = std::getenv("BRDF_BUILD_DIR");
  ASSERT_NE(build, nullptr) << "run through ctest (it sets BRDF_BUILD_DIR)";
  LaunchOptions python;
  python.args = {SourceDir() + "/tests/archive/python_client_check.py",
                 "--rig",
                 rig_->daemon()->address(),
                 "--archive",
                 a.address(),
                 "--token",
                 kAnalystToken,
                 "--rig-session",
                 paint.session_id(),
                 "--archive-session",
                 id,
                 "--uuid",
                 paint.uuid(),
                 "--material",
                 "paint",
                 "--workdir",
                 rig_->dir().path().string()};
  python.stderr_to = LaunchOptions::Stderr::kPipe;
  python.stdin_from_null = true;
  python.set_env = {{"BRDF_PY_STUBS", std::string(build) + "/clients/python/stubs"},
                    {"PYTHONDONTWRITEBYTECODE", "1"}};
  Result<CommandResult> checked =
      RunToCompletion("python3", "/usr/bin/python3", python, std::chrono::seconds(120));
  ASSERT_TRUE(checked.ok()) << checked.status().ToString();
  EXPECT_EQ(checked->exit_code, 0) << checked->out << checked->err;
  EXPECT_THAT(checked->out, HasSubstr("export rgl:")) << checked->out << checked->err;
}

TEST_F(ArchiveServerTest, ASessionCachedWhileRecordingGrowsAsItIsShipped) {
  ASSERT_TRUE(WaitCaughtUp()) << "the rig migrates the archive when it first connects";
  ArchiveProcess& a = StartArchive();
  const v1::Session paint = Submit(WithSample(plans::InterpolationGrid(), kPaint));
  rig_->WaitFor(
      paint.session_id(), [](const v1::Session& s) { return s.progress().done_samples() >= 6; },
      60s);
  // Cache the session in the archive server while it records.
  std::string id;
  std::vector<std::string> early;
  const auto deadline = Clock::now() + 30s;
  while (Clock::now() < deadline) {
    v1::ListSessionsResponse all;
    if (a.control().ListSessions(DaemonRig::Context().get(), {}, &all).ok() &&
        all.sessions_size() == 1) {
      id = all.sessions(0).session_id();
      early = InterpolateAll(a.interpolation(), id, v1::QUANTITY_BRDF);
      if (std::count_if(early.begin(), early.end(), [](const std::string& s) {
            return s.find(": ") == std::string::npos;
          }) > 0) {
        break;
      }
    }
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_FALSE(id.empty());
  ASSERT_EQ(rig_->WaitForState(paint.session_id(), v1::SESSION_STATE_COMPLETED, 120s).state(),
            v1::SESSION_STATE_COMPLETED);
  ASSERT_TRUE(WaitCaughtUp());
  const std::vector<std::string> final_answers =
      InterpolateAll(rig_->interpolation(), paint.session_id(), v1::QUANTITY_BRDF);
  EXPECT_NE(early, final_answers) << "the early answers should be over fewer readings";
  // Within a few refresh periods the archive server's cached index has every reading.
  std::vector<std::string> now;
  const auto until = Clock::now() + 15s;
  while (Clock::now() < until) {
    now = InterpolateAll(a.interpolation(), id, v1::QUANTITY_BRDF);
    if (now == final_answers) break;
    std::this_thread::sleep_for(200ms);
  }
  EXPECT_EQ(now, final_answers);
}

TEST(ArchiveServerConfigTest, TheExampleConfigurationParsesWithCredentialsAndAnAnalystToken) {
  Result<daemon::Config> config =
      daemon::LoadConfig(SourceDir() + "/deploy/brdf-archive.example.toml");
  ASSERT_TRUE(config.ok()) << config.status().ToString();
  EXPECT_TRUE(config->archive.enabled());
  ASSERT_EQ(config->tokens.size(), 1U);
  EXPECT_EQ(config->tokens[0].role, daemon::Role::kAnalyst);
}

}  // namespace
}  // namespace brdf::testing
