// What the daemon's integration tests stand on: brdf-sim and brdfd as real PROCESSES (free ports,
// a generated TOML configuration, a temporary SQLite file), and clients that talk to brdfd only
// through its gRPC API with the generated C++ stubs, as any client would. The test plays the
// operator: GrpcOperator watches a session (WatchSession) and answers its prompts (AnswerPrompt)
// after doing what they ask on the simulated rig (mounting the white standard or the sample,
// closing the shutter) through the simulator's control unit (tests/support ModbusControl).
//
// Simulated time runs kTimeScale times faster; brdfd's meter and stage timings are shortened in
// its configuration so that a reading takes ~0.1 s and a move ~0.2 s of real time.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"
#include "core/status.h"
#include "tests/support/daemon/process.h"
#include "tests/support/sim/modbus_control.h"
#include "tests/support/sim/process.h"
#include "tests/support/sim/rig.h"
#include "tests/support/test_env.h"

namespace brdf::testing {

inline constexpr double kTimeScale = kSimTimeScale;
inline constexpr const char* kOperatorToken = "op-token-2f9c61d0a7b34e58";
inline constexpr const char* kAnalystToken = "an-token-93be07c4d1a24f6e";
inline constexpr const char* kOperatorName = "test-operator";

// The TOML configuration of a brdfd driving `sim` with the database at `database`: listen on
// 127.0.0.1:0, short meter and stage timings, a motorized detector arm, an operator and an
// analyst token.
std::string DaemonConfigToml(const SimProcess& sim, const std::string& database);

bool IsTerminal(v1::SessionState state);

// brdf-sim + brdfd + stubs. Not thread-safe except where said.
class DaemonRig {
 public:
  DaemonRig();
  ~DaemonRig();

  // Starts brdf-sim (tests/support/sim/rig.h, seed 11, then `extra`) and connects to its
  // control unit.
  Status StartSim(const std::vector<std::string>& extra = {});
  // Writes the configuration (DaemonConfigToml unless `toml` is given) and starts brdfd on it;
  // builds the channel and the stubs. May be called again after StopDaemon/KillDaemon: the same
  // database, a new port. Stopping drops the channel and the stubs.
  Status StartDaemon(const std::string& toml = "");
  Result<int> StopDaemon();
  void KillDaemon();

  // A context carrying "authorization: Bearer <token>" (none when empty) and a deadline.
  static std::unique_ptr<grpc::ClientContext> Context(
      const std::string& token = kOperatorToken,
      std::chrono::milliseconds deadline = std::chrono::seconds(10));

  v1::Control::Stub& control() { return *control_; }
  v1::Data::Stub& data() { return *data_; }
  v1::Interpolation::Stub& interpolation() { return *interpolation_; }
  const std::shared_ptr<grpc::Channel>& channel() const { return channel_; }
  ModbusControl& sim_control() { return *sim_control_; }
  const SimProcess& sim() const { return *sim_; }
  DaemonProcess* daemon() { return daemon_.get(); }
  const TempDir& dir() const { return dir_; }
  std::string database() const { return dir_.file("brdfd.db").string(); }
  std::string config_path() const { return dir_.file("brdfd.toml").string(); }
  std::string log_path() const { return dir_.file("brdfd.log").string(); }
  // The daemon's log so far (for failure messages).
  std::string log() const;

  // SubmitPlan (start_now) with a plan in its JSON form; the session, or the failure.
  Result<v1::Session> Submit(const std::string& plan_json, bool start_now = true);
  // GetSession until `done` holds or `timeout`; the last session seen.
  v1::Session WaitFor(const std::string& session_id,
                      const std::function<bool(const v1::Session&)>& done,
                      std::chrono::milliseconds timeout = std::chrono::seconds(30));
  v1::Session WaitForState(const std::string& session_id, v1::SessionState state,
                           std::chrono::milliseconds timeout = std::chrono::seconds(30));
  Result<v1::Session> Get(const std::string& session_id);
  // Every reading of the session (StreamReadings without follow).
  Result<std::vector<v1::Reading>> Readings(const std::string& session_id);

 private:
  void DropChannel();

  TempDir dir_;
  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<ModbusControl> sim_control_;
  std::unique_ptr<DaemonProcess> daemon_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Control::Stub> control_;
  std::unique_ptr<v1::Data::Stub> data_;
  std::unique_ptr<v1::Interpolation::Stub> interpolation_;
};

// The test as the operator of one session: watches it over gRPC and, when `answering`, does
// what each prompt asks on the simulator (its own Modbus connection) and answers it. Keeps every
// event seen. Runs on its own thread until the stream ends (the session ended, the daemon went
// away) or Stop().
class GrpcOperator {
 public:
  GrpcOperator(DaemonRig& rig, std::string session_id, bool answering = true);
  ~GrpcOperator();

  void Stop();
  void set_answering(bool on) { answering_ = on; }
  // Thread-safe copies.
  std::vector<v1::SessionEvent> events() const;
  std::vector<v1::Prompt> prompts_answered() const;
  std::vector<std::string> errors() const;
  // How the WatchSession stream ended (OK once the session ended).
  grpc::Status stream_status() const;
  bool finished() const { return finished_; }

 private:
  void Run();

  std::string session_id_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Control::Stub> stub_;
  std::unique_ptr<ModbusControl> control_;
  std::atomic<bool> answering_;
  std::atomic<bool> finished_{false};
  grpc::ClientContext context_;
  mutable std::mutex mu_;
  std::vector<v1::SessionEvent> events_;
  std::vector<v1::Prompt> answered_;
  std::vector<std::string> errors_;
  grpc::Status stream_status_;
  std::thread thread_;
};

}  // namespace brdf::testing
