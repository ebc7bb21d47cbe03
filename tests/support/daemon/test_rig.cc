#include "tests/support/daemon/test_rig.h"

#include <fstream>
#include <optional>
#include <sstream>

#include "core/plan/plan_json.h"

namespace brdf::testing {

using namespace std::chrono_literals;

std::string DaemonConfigToml(const SimProcess& sim, const std::string& database) {
  std::ostringstream t;
  t << "[server]\n"
    << "listen = \"127.0.0.1:0\"\n"
    << "[storage]\n"
    << "database = \"" << database << "\"\n"
    << "[meter]\n"
    << "port = \"" << sim.pr650_path() << "\"\n"
    << "pacing_ms = 5\n"
    << "quiet_gap_ms = 20\n"
    << "reply_timeout_ms = 500\n"
    << "measurement_timeout_ms = 3000\n"
    << "wake_attempts = 3\n"
    << "rts_settle_ms = 20\n"
    // brdf-sim's meter, for the estimates (docs/pr650.md, "How long a reading takes").
    << "overhead_ms = 1000\nadaptive_reference_ms = 150\n"
    << "adaptive_dark_ms = 6000\nadaptive_sample_ms = 650\n"
    // Dark readings are weak by nature (the simulator's earn quality 10): accept them flagged,
    // as a lab that takes darks configures it.
    << "[meter.quality]\n"
    << "\"10\" = \"accept_and_flag\"\n"
    << "[stage]\n"
    << "transport = \"tcp\"\n"
    << "address = \"" << sim.modbus_host() << ":" << sim.modbus_port() << "\"\n"
    << "response_timeout_ms = 300\n"
    << "detector_arm_motorized = true\n"
    // Speeds are simulated degrees per second (the simulator runs kTimeScale times faster).
    << "[stage.axes.alpha]\nspeed_deg_s = 30\n"
    << "[stage.axes.beta]\nspeed_deg_s = 30\n"
    << "[stage.axes.delta]\nspeed_deg_s = 30\n"
    << "[sample]\n"
    << "white_reflectance = 0.99\n"
    << "[[auth.tokens]]\n"
    << "name = \"" << kOperatorName << "\"\n"
    << "token = \"" << kOperatorToken << "\"\n"
    << "role = \"operator\"\n"
    << "[[auth.tokens]]\n"
    << "name = \"test-analyst\"\n"
    << "token = \"" << kAnalystToken << "\"\n"
    << "role = \"analyst\"\n"
    << "[log]\n"
    << "level = \"debug\"\n";
  return t.str();
}

bool IsTerminal(v1::SessionState state) {
  return state == v1::SESSION_STATE_COMPLETED || state == v1::SESSION_STATE_ABORTED ||
         state == v1::SESSION_STATE_FAILED;
}

DaemonRig::DaemonRig() : dir_("brdfd-test") {}

DaemonRig::~DaemonRig() {
  // The daemon first: it must not see its devices vanish under a session.
  daemon_.reset();
  sim_control_.reset();
  sim_.reset();
}

Status DaemonRig::StartSim(const std::vector<std::string>& extra) {
  if (dir_.path().empty()) return IoError("no temporary directory: " + dir_.error());
  BRDF_ASSIGN_OR_RETURN(SimRig rig, StartSimRig(/*seed=*/11, extra));
  sim_ = std::move(rig.sim);
  sim_control_ = std::move(rig.control);
  return Status::Ok();
}

Status DaemonRig::StartDaemon(const std::string& toml) {
  if (dir_.path().empty()) return IoError("no temporary directory: " + dir_.error());
  {
    std::ofstream out(config_path());
    out << (toml.empty() ? DaemonConfigToml(*sim_, database()) : toml);
    if (!out) return IoError("cannot write " + config_path());
  }
  BRDF_ASSIGN_OR_RETURN(
      std::unique_ptr<DaemonProcess> daemon,
      DaemonProcess::Start({"--config", config_path(), "--shutdown-timeout", "10"}, log_path()));
  daemon_ = std::move(daemon);
  channel_ = grpc::CreateChannel(daemon_->address(), grpc::InsecureChannelCredentials());
  control_ = v1::Control::NewStub(channel_);
  data_ = v1::Data::NewStub(channel_);
  interpolation_ = v1::Interpolation::NewStub(channel_);
  return Status::Ok();
}

Result<int> DaemonRig::StopDaemon() {
  if (!daemon_) return Internal("no daemon running");
  // Our connection goes first: a server's graceful shutdown waits (up to its grace period) for
  // connected clients to hang up.
  DropChannel();
  Result<int> code = daemon_->Stop();
  daemon_.reset();
  return code;
}

void DaemonRig::DropChannel() {
  control_.reset();
  data_.reset();
  interpolation_.reset();
  channel_.reset();
}

void DaemonRig::KillDaemon() {
  DropChannel();
  if (daemon_) daemon_->Kill();
  daemon_.reset();
}

std::string DaemonRig::log() const {
  std::ifstream in(log_path());
  std::ostringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  if (s.size() > 8000) s = "…" + s.substr(s.size() - 8000);
  return s;
}

std::unique_ptr<grpc::ClientContext> DaemonRig::Context(const std::string& token,
                                                        std::chrono::milliseconds deadline) {
  auto context = std::make_unique<grpc::ClientContext>();
  if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
  context->set_deadline(std::chrono::system_clock::now() + deadline);
  return context;
}

Result<v1::Session> DaemonRig::Submit(const std::string& plan_json, bool start_now) {
  BRDF_ASSIGN_OR_RETURN(v1::Plan plan, plan::ParsePlanJson(plan_json));
  v1::SubmitPlanRequest request;
  *request.mutable_plan() = plan;
  request.set_start_now(start_now);
  v1::SubmitPlanResponse response;
  grpc::Status st = control_->SubmitPlan(Context().get(), request, &response);
  if (!st.ok()) {
    return Internal("SubmitPlan: " + std::to_string(st.error_code()) + " " + st.error_message());
  }
  return response.session();
}

Result<v1::Session> DaemonRig::Get(const std::string& session_id) {
  v1::GetSessionRequest request;
  request.set_session_id(session_id);
  v1::Session session;
  grpc::Status st = control_->GetSession(Context().get(), request, &session);
  if (!st.ok()) {
    return Internal("GetSession: " + std::to_string(st.error_code()) + " " + st.error_message());
  }
  return session;
}

v1::Session DaemonRig::WaitFor(const std::string& session_id,
                               const std::function<bool(const v1::Session&)>& done,
                               std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  v1::Session last;
  for (;;) {
    if (Result<v1::Session> s = Get(session_id); s.ok()) {
      last = *s;
      if (done(last)) return last;
    }
    if (std::chrono::steady_clock::now() >= until) return last;
    std::this_thread::sleep_for(20ms);
  }
}

v1::Session DaemonRig::WaitForState(const std::string& session_id, v1::SessionState state,
                                    std::chrono::milliseconds timeout) {
  return WaitFor(
      session_id,
      [state](const v1::Session& s) { return s.state() == state || IsTerminal(s.state()); },
      timeout);
}

Result<std::vector<v1::Reading>> DaemonRig::Readings(const std::string& session_id) {
  v1::StreamReadingsRequest request;
  request.set_session_id(session_id);
  auto context = Context(kAnalystToken, 30s);
  std::unique_ptr<grpc::ClientReader<v1::Reading>> reader =
      data_->StreamReadings(context.get(), request);
  std::vector<v1::Reading> out;
  v1::Reading reading;
  while (reader->Read(&reading)) out.push_back(reading);
  grpc::Status st = reader->Finish();
  if (!st.ok()) {
    return Internal("StreamReadings: " + std::to_string(st.error_code()) + " " +
                    st.error_message());
  }
  return out;
}

// --- GrpcOperator -------------------------------------------------------------------------

GrpcOperator::GrpcOperator(DaemonRig& rig, std::string session_id, bool answering)
    : session_id_(std::move(session_id)), channel_(rig.channel()), answering_(answering) {
  stub_ = v1::Control::NewStub(channel_);
  Result<std::unique_ptr<ModbusControl>> control = ModbusControl::Connect(
      rig.sim().modbus_host(), rig.sim().modbus_port(), rig.sim().control_unit());
  if (!control.ok()) {
    errors_.push_back(control.status().ToString());
    finished_ = true;
    return;
  }
  control_ = std::move(*control);
  context_.AddMetadata("authorization", std::string("Bearer ") + kOperatorToken);
  thread_ = std::thread([this] { Run(); });
}

GrpcOperator::~GrpcOperator() {
  Stop();
}

void GrpcOperator::Stop() {
  context_.TryCancel();
  if (thread_.joinable()) thread_.join();
}

std::vector<v1::SessionEvent> GrpcOperator::events() const {
  std::lock_guard lock(mu_);
  return events_;
}
std::vector<v1::Prompt> GrpcOperator::prompts_answered() const {
  std::lock_guard lock(mu_);
  return answered_;
}
std::vector<std::string> GrpcOperator::errors() const {
  std::lock_guard lock(mu_);
  return errors_;
}
grpc::Status GrpcOperator::stream_status() const {
  std::lock_guard lock(mu_);
  return stream_status_;
}

void GrpcOperator::Run() {
  v1::WatchSessionRequest request;
  request.set_session_id(session_id_);
  std::unique_ptr<grpc::ClientReader<v1::SessionEvent>> reader =
      stub_->WatchSession(&context_, request);
  v1::SessionEvent event;
  while (reader->Read(&event)) {
    std::optional<v1::Prompt> open;
    {
      std::lock_guard lock(mu_);
      events_.push_back(event);
    }
    if (event.has_prompt()) open = event.prompt();
    if (event.has_snapshot() && event.snapshot().has_pending_prompt()) {
      open = event.snapshot().pending_prompt();
    }
    if (!open.has_value() || !answering_) continue;

    // Do what the prompt asks on the simulated rig, then confirm it.
    Status acted = Status::Ok();
    switch (open->kind()) {
      case v1::PROMPT_KIND_MOUNT_WHITE:
        acted = control_->SetMounted(sim::MountedTarget::kWhite);
        break;
      case v1::PROMPT_KIND_MOUNT_SAMPLE:
        acted = control_->SetMounted(sim::MountedTarget::kSample);
        break;
      case v1::PROMPT_KIND_CLOSE_SHUTTER:
        acted = control_->SetMounted(sim::MountedTarget::kDark);
        break;
      default:
        break;  // relocations: nothing to do on the simulator (see the tests)
    }
    if (!acted.ok()) {
      std::lock_guard lock(mu_);
      errors_.push_back("acting on prompt " + std::to_string(open->step_index()) + ": " +
                        acted.ToString());
      continue;
    }
    v1::AnswerPromptRequest answer;
    answer.set_session_id(session_id_);
    answer.set_step_index(open->step_index());
    answer.set_note("done by the test");
    v1::AnswerPromptResponse response;
    grpc::Status st = stub_->AnswerPrompt(DaemonRig::Context().get(), answer, &response);
    std::lock_guard lock(mu_);
    if (st.ok()) {
      answered_.push_back(*open);
    } else if (st.error_code() != grpc::StatusCode::FAILED_PRECONDITION) {
      // (FAILED_PRECONDITION: paused meanwhile; the prompt comes again on resume.)
      errors_.push_back("AnswerPrompt: " + std::to_string(st.error_code()) + " " +
                        st.error_message());
    }
  }
  grpc::Status st = reader->Finish();
  std::lock_guard lock(mu_);
  stream_status_ = st;
  finished_ = true;
}

}  // namespace brdf::testing
