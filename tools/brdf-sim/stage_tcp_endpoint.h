// The stage simulator's Modbus TCP endpoint: listens on host:port with libmodbus
// (modbus_new_tcp + modbus_tcp_listen; port 0 picks a free port), serves several clients from one
// thread with select(), reads each request with modbus_receive and dispatches it on its unit id
// (byte 6 of the MBAP header) through a StageDispatcher, so every unit id has its own registers.
// Replies are framed here (MBAP + PDU) so that an injected delay holds back only that client's
// replies, in order, while the other clients are served.
#pragma once

#include <modbus.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "tools/brdf-sim/stage_dispatch.h"

namespace brdf::sim {

class StageTcpEndpoint {
 public:
  explicit StageTcpEndpoint(StageDispatcher& dispatcher) : dispatcher_(dispatcher) {}
  ~StageTcpEndpoint();
  StageTcpEndpoint(const StageTcpEndpoint&) = delete;
  StageTcpEndpoint& operator=(const StageTcpEndpoint&) = delete;

  // Binds and starts serving. False with `error` set when the port cannot be bound.
  bool Start(const std::string& host, int port, std::string* error);
  void Stop();
  int port() const { return port_; }
  int clients() const { return clients_count_.load(); }

 private:
  struct Outgoing {
    std::chrono::steady_clock::time_point due;
    std::vector<std::uint8_t> bytes;
  };
  struct Client {
    std::deque<Outgoing> queue;  // in order; each due no earlier than the one before
  };

  void Run();
  void Accept();
  void Receive(int fd);
  void SendDue();
  void CloseClient(int fd);

  StageDispatcher& dispatcher_;
  modbus_t* ctx_ = nullptr;
  int listen_fd_ = -1;
  int wake_[2] = {-1, -1};
  int port_ = 0;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::map<int, Client> clients_;  // by socket; owned by the serving thread
  std::atomic<int> clients_count_{0};
};

}  // namespace brdf::sim
