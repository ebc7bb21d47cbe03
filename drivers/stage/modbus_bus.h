// One Modbus bus (a TCP connection to a drive or gateway, or an RS-485 line), owned by one thread.
//
// A libmodbus context is not thread-safe ("isn't thread safe and won't be"), so every libmodbus
// call for a bus happens on that bus's owner thread. Public calls post a job to it and wait, with
// the caller's CallContext, for the answer; a caller whose deadline passes or whose token is
// cancelled returns at once and the job is abandoned (skipped if not started, its answer dropped
// if running). Urgent jobs (stop) go to the head of the queue.
//
// Recovery policy (stage-modbus.md, "patterns and pitfalls"), all bounded:
//  - the input is flushed before every request, and the response timeout is configurable
//    (default 0.5 s); MODBUS_ERROR_RECOVERY_LINK is never used (it can loop for seconds);
//  - exception 01/02/03 → kConfigurationError, no retry (the register map does not fit the drive);
//  - exception 04 (on an AZ: command execution disabled, e.g. while the drive is busy or just
//    after a change of setting) and 06 (busy) → retried with a back-off that starts at
//    busy_backoff and doubles up to busy_backoff_max, for busy_window in all, then kDeviceError
//    with the exception code (a configuration mismatch is named by the caller, see axis_io.h);
//  - other exceptions → kDeviceError with the exception code;
//  - no reply (ETIMEDOUT) → retried timeout_retries times, then kTimeout;
//  - a reply that does not belong to the request (TCP transaction-id mismatch, RTU CRC or slave
//    mismatch) → retried garbled_retries times, then kProtocolError;
//  - a dropped link → reconnect (reconnect_attempts, doubling backoff) and retry, else
//    kDisconnected.
// A late reply must never be read as the answer to the next request: after a timeout or a stray
// reply, a TCP bus reconnects (the late bytes die with the old socket), and an RTU bus discards
// whatever arrives on the line for rtu_drain before flushing. (RTU has no transaction id: a reply
// later than response_timeout + rtu_drain can still be mistaken; keep the timeout generous.)
//
// Retried writes are safe here because everything the stage writes is idempotent (absolute
// targets, level bits written as whole words).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "core/call_context.h"
#include "core/mutex.h"
#include "core/status.h"

namespace brdf::drivers::stage {

struct TcpEndpoint {
  std::string host = "127.0.0.1";
  int port = 502;
};

struct RtuEndpoint {
  std::string device;  // /dev/ttyUSB0, /dev/serial/by-id/...
  int baud = 115200;
  char parity = 'E';  // 'N', 'E' or 'O'
  int data_bits = 8;
  int stop_bits = 1;
};

struct BusConfig {
  std::variant<TcpEndpoint, RtuEndpoint> endpoint = TcpEndpoint{};
  std::chrono::milliseconds response_timeout{500};
  int timeout_retries = 2;
  // Exception 04/06: keep retrying for this long from the first such answer to a request.
  std::chrono::milliseconds busy_window{3000};
  std::chrono::milliseconds busy_backoff{50};       // first wait; doubles after each retry
  std::chrono::milliseconds busy_backoff_max{500};  // longest wait between retries
  int garbled_retries = 2;
  int reconnect_attempts = 3;
  std::chrono::milliseconds reconnect_backoff{100};  // doubles after each failed attempt
  std::chrono::milliseconds rtu_drain{500};          // RTU: discard stray bytes this long
};

// kConfigurationError naming the bus index and the field.
Status ValidateBus(int index, const BusConfig& config);
// "Modbus TCP 127.0.0.1:502" or "Modbus RTU /dev/ttyUSB0 (115200 8E1)".
std::string DescribeBus(const BusConfig& config);

enum class BusPriority { kNormal, kUrgent };

class ModbusBus {
 public:
  explicit ModbusBus(BusConfig config);
  ~ModbusBus();
  ModbusBus(const ModbusBus&) = delete;
  ModbusBus& operator=(const ModbusBus&) = delete;

  // Starts the owner thread (if needed) and connects, with bounded attempts. On failure the
  // thread is stopped again. kConfigurationError for an RTU device that does not exist at the
  // first connection, kDisconnected when the peer cannot be reached.
  Status Open(const CallContext& ctx);
  // Closes the link and stops the owner thread; queued calls fail with kDisconnected.
  void Close();
  // Open() succeeded and Close() was not called (the link may be re-establishing itself).
  bool is_open() const { return open_.load(); }
  const std::string& description() const { return description_; }

  // FC03, `count` ≤ 125 registers.
  Result<std::vector<std::uint16_t>> ReadRegisters(int unit, std::uint16_t address, int count,
                                                   const CallContext& ctx,
                                                   BusPriority priority = BusPriority::kNormal);
  // FC06 for one register, FC16 for more (≤ 123), in one request.
  Status WriteRegisters(int unit, std::uint16_t address, std::vector<std::uint16_t> values,
                        const CallContext& ctx, BusPriority priority = BusPriority::kNormal);

 private:
  struct Job;
  class Link;

  Result<std::vector<std::uint16_t>> Submit(const std::shared_ptr<Job>& job, const CallContext& ctx,
                                            BusPriority priority);
  void Run();
  void StopThread();

  const BusConfig config_;
  const std::string description_;
  std::atomic<bool> open_{false};

  Mutex lifecycle_mu_;  // serializes Open/Close
  Mutex mu_;            // guards queue_ and running_; stopping_ is set under it
  CondVar cv_;
  std::deque<std::shared_ptr<Job>> queue_ GUARDED_BY(mu_);
  bool running_ GUARDED_BY(mu_) = false;
  std::atomic<bool> stopping_{false};  // also read by the owner thread while it waits or retries
  std::thread thread_;
};

}  // namespace brdf::drivers::stage
