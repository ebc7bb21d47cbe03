// The stage simulator's Modbus RTU endpoint: a pseudo-terminal standing in for an RS-485 line
// with several drives on it. The client opens the slave side (path()); this endpoint reads the
// master side, cuts frames by length and timing, checks each CRC itself (RtuFrameSplitter) and
// answers every unit id the dispatcher knows, in order, with the injected delays. A frame for a
// unit id nobody has, or with a bad CRC, gets no answer, as on a real line.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <thread>
#include <vector>

#include "tools/brdf-sim/stage/dispatch.h"
#include "tools/brdf-sim/stage/rtu_frame.h"

namespace brdf::sim {

class StageRtuEndpoint {
 public:
  explicit StageRtuEndpoint(StageDispatcher& dispatcher) : dispatcher_(dispatcher) {}
  ~StageRtuEndpoint();
  StageRtuEndpoint(const StageRtuEndpoint&) = delete;
  StageRtuEndpoint& operator=(const StageRtuEndpoint&) = delete;

  // Creates the pty and starts serving. False with `error` set on failure.
  bool Start(std::string* error);
  void Stop();
  // The slave side a client opens, e.g. /dev/pts/7.
  const std::string& path() const { return path_; }
  int crc_errors() const { return crc_errors_.load(); }

 private:
  struct Outgoing {
    std::chrono::steady_clock::time_point due;
    std::vector<std::uint8_t> bytes;
  };

  void Run();
  void Serve(const std::vector<std::uint8_t>& frame);
  void SendDue();

  StageDispatcher& dispatcher_;
  int master_fd_ = -1;
  int keep_slave_fd_ = -1;  // keeps the line up (no EIO/HUP) while no client has it open
  int wake_[2] = {-1, -1};
  std::string path_;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  RtuFrameSplitter splitter_;
  std::deque<Outgoing> queue_;
  std::atomic<int> crc_errors_{0};
};

}  // namespace brdf::sim
