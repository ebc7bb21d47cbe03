// The stage simulator's Modbus TCP endpoint: listens on host:port with libmodbus
// (modbus_new_tcp + modbus_tcp_listen; port 0 picks a free port) and serves several clients from
// one thread with select().
//
// Requests are framed by the MBAP header, as the Modbus TCP specification says, never by a byte
// count inside the PDU: transaction id (2 bytes), protocol id (2, 0 = Modbus), length (2: the
// unit id plus the PDU), unit id (1), then `length - 1` PDU bytes. So a malformed PDU inside a
// well-framed ADU is answered with an exception (stage/pdu.h) and the next request on the
// connection is read from the right place, with its own transaction id and unit. An ADU whose
// protocol id is not 0 is read past and dropped without a reply. A length outside 2–254 (no
// function code, or more than the 253-byte PDU maximum) means the stream can no longer be framed
// (there is no start marker to resync on): the connection is closed, as a real gateway does.
// Each request is dispatched on its unit id through a StageDispatcher (every unit id has its own
// registers); replies are framed here (the request's transaction id and unit id, protocol 0) so
// that an injected delay holds back only that client's replies, in order, while the other clients
// are served. An injected outage (StageReply::refuse_connections) closes the listening socket for
// a while, so that clients are refused as by a drive or gateway that is switched off, then listens
// on the same port again.
#pragma once

#include <modbus.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "tools/brdf-sim/stage/dispatch.h"

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
    std::vector<std::uint8_t> input;  // bytes received, not yet a whole ADU
    std::deque<Outgoing> queue;       // in order; each due no earlier than the one before
  };

  void Run();
  void Accept();
  void Receive(int fd);
  // Serves every whole ADU at the front of the client's input; false when the connection must
  // close (an unframeable length, or a dropped-connection fault).
  bool ServeFramed(Client& client);
  void SendDue();
  void CloseClient(int fd);
  // An injected outage: stop listening until `until` (connections are refused meanwhile).
  void RefuseUntil(std::chrono::steady_clock::time_point until);
  // Listens again on the same port once the outage is over (retried each turn if that fails).
  void ListenAgainWhenDue();

  StageDispatcher& dispatcher_;
  modbus_t* ctx_ = nullptr;
  int listen_fd_ = -1;
  int wake_[2] = {-1, -1};
  int port_ = 0;
  std::string host_;
  std::chrono::steady_clock::time_point refuse_until_{};  // while listen_fd_ is closed
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::map<int, Client> clients_;  // by socket; owned by the serving thread
  std::atomic<int> clients_count_{0};
};

}  // namespace brdf::sim
