// The seam between the stage simulator's transports (TCP, RTU pty) and the simulated drives: an
// endpoint frames a request, asks the dispatcher what to do with it, and frames the answer.
// Faults decide here whether there is an answer, when, and whether the link survives.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

namespace brdf::sim {

enum class StageTransport { kTcp, kRtu };

struct StageReply {
  enum class Kind {
    kReply,   // send `pdu` after `delay`
    kSilent,  // send nothing (RTU: no such unit on the line; injected missing reply)
    kDrop,    // close the connection without answering (TCP; RTU treats it as kSilent)
  };
  Kind kind = Kind::kReply;
  std::vector<std::uint8_t> pdu;
  std::chrono::milliseconds delay{0};  // real time
  // kDrop only: the drives went away; a TCP endpoint also stops listening for this long (new
  // connections are refused), then listens on the same port again.
  std::chrono::milliseconds refuse_connections{0};
};

class StageDispatcher {
 public:
  virtual ~StageDispatcher() = default;
  // `unit` is the MBAP unit id (TCP) or the slave address (RTU); `pdu` starts at the function code.
  virtual StageReply Handle(std::uint8_t unit, std::span<const std::uint8_t> pdu,
                            StageTransport transport) = 0;
};

}  // namespace brdf::sim
