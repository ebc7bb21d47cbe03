#include "drivers/stage/modbus_bus.h"

#include <modbus.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <optional>
#include <utility>

#include "drivers/stage/modbus_errors.h"

namespace brdf::drivers::stage {

namespace {

using SteadyClock = std::chrono::steady_clock;
using std::chrono::milliseconds;

std::string Hex(unsigned value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", value);
  return buf;
}

}  // namespace

// A request posted to the owner thread, and its answer.
struct ModbusBus::Job {
  enum class Kind { kConnect, kRead, kWrite };
  Kind kind = Kind::kRead;
  int unit = 0;
  std::uint16_t address = 0;
  int count = 0;
  std::vector<std::uint16_t> values;
  SteadyClock::time_point deadline;  // real time: when the caller will have given up
  CancelToken cancel;
  std::atomic<bool> abandoned{false};

  Mutex mu;
  CondVar cv;
  bool done GUARDED_BY(mu) = false;
  Status status GUARDED_BY(mu);
  // Written by the owner thread before it sets `done`, read by the caller after.
  std::vector<std::uint16_t> data;

  // "unit 2: reading 4 registers at 0x007E"
  std::string What() const {
    switch (kind) {
      case Kind::kConnect:
        return "connecting";
      case Kind::kRead:
        return "unit " + std::to_string(unit) + ": reading " + std::to_string(count) +
               " register(s) at " + Hex(address);
      case Kind::kWrite:
        return "unit " + std::to_string(unit) + ": writing " + std::to_string(values.size()) +
               " register(s) at " + Hex(address);
    }
    return "?";
  }
  bool GivenUp() const {
    return abandoned.load() || cancel.cancelled() || SteadyClock::now() >= deadline;
  }
};

// The libmodbus context and the recovery policy. Used only on the owner thread.
class ModbusBus::Link {
 public:
  Link(const BusConfig& config, const std::string& description, const std::atomic<bool>& stopping)
      : config_(config), description_(description), stopping_(stopping) {}
  ~Link() { Destroy(); }

  Status Connect(const Job& job, bool first_time) {
    Status last;
    milliseconds backoff = config_.reconnect_backoff;
    for (int attempt = 1; attempt <= std::max(1, config_.reconnect_attempts); ++attempt) {
      if (job.GivenUp() || stopping_) return GaveUp(job);
      Drop();
      if (ctx_ == nullptr) BRDF_RETURN_IF_ERROR(Create());
      SetResponseTimeout(job);
      errno = 0;
      if (modbus_connect(ctx_) == 0) {
        connected_ = true;
        return Status::Ok();
      }
      const int err = errno;
      if (first_time && is_rtu() && (err == ENOENT || err == EACCES || err == ENOTDIR)) {
        return ConfigurationError(description_ +
                                  ": cannot open the serial device: " + ModbusErrorText(err) +
                                  "; check the device name and the permissions (dialout group)");
      }
      last = Disconnected(description_ + ": cannot connect (attempt " + std::to_string(attempt) +
                          " of " + std::to_string(config_.reconnect_attempts) +
                          "): " + ModbusErrorText(err));
      if (attempt < config_.reconnect_attempts) {
        if (!Sleep(backoff, job)) return GaveUp(job);
        backoff *= 2;
      }
    }
    return Disconnected(last.message() +
                        "; check that the drive or gateway is powered, cabled and at this address");
  }

  // One request with the bounded retry policy of the header.
  Status Execute(Job& job) {
    Retries retries;
    retries.busy_backoff = config_.busy_backoff;
    const std::string what = description_ + " " + job.What();
    while (true) {
      if (job.GivenUp() || stopping_) return GaveUp(job);
      if (!connected_) {
        if (retries.relinks++ > config_.reconnect_attempts) {
          return Disconnected(what + ": the link keeps dropping; check the cabling and the drive");
        }
        BRDF_RETURN_IF_ERROR(Connect(job, false).WithContext(what));
      }
      int err = 0;
      if (Transfer(job, err)) return Status::Ok();
      std::optional<Status> verdict =
          AfterFailure(job, err, what + ": " + ModbusErrorText(err), retries);
      if (verdict.has_value()) return *std::move(verdict);
    }
  }

  void Destroy() {
    Drop();
    if (ctx_ != nullptr) {
      modbus_free(ctx_);
      ctx_ = nullptr;
    }
  }

 private:
  // What the retry policy has counted so far for one request.
  struct Retries {
    int timeouts = 0, busy = 0, garbled = 0, relinks = 0;
    SteadyClock::time_point busy_since;
    milliseconds busy_backoff{};
  };

  // One exchange on the connected link: true when the drive answered the whole request; else
  // the errno (EMBBADDATA for a short answer) in `err`.
  bool Transfer(Job& job, int& err) {
    modbus_flush(ctx_);  // nothing left over from an earlier exchange may answer this one
    modbus_set_slave(ctx_, job.unit);
    SetResponseTimeout(job);
    errno = 0;
    int rc = -1;
    int expected = 0;
    if (job.kind == Job::Kind::kRead) {
      job.data.assign(static_cast<std::size_t>(job.count), 0);
      expected = job.count;
      rc = modbus_read_registers(ctx_, job.address, job.count, job.data.data());
    } else if (job.values.size() == 1) {
      expected = 1;
      rc = modbus_write_register(ctx_, job.address, job.values[0]);
    } else {
      expected = static_cast<int>(job.values.size());
      rc = modbus_write_registers(ctx_, job.address, expected, job.values.data());
    }
    if (rc == expected) return true;
    err = rc < 0 ? errno : EMBBADDATA;
    return false;
  }

  // A failed exchange (`problem` names it): the Status to return, or nullopt to try again
  // (busy within its window, a timeout or garbled reply within its retries, a dropped link).
  std::optional<Status> AfterFailure(Job& job, int err, const std::string& problem, Retries& r) {
    switch (ClassifyModbusErrno(err)) {
      case ModbusFailure::kIllegalRequest:
        return Status{StatusCode::kConfigurationError,
                      problem + " (exception " + std::to_string(ModbusExceptionCode(err)) +
                          "); the drive does not accept this register or value: check the "
                          "register profile and the unit id",
                      ModbusExceptionCode(err)};
      case ModbusFailure::kBusy:
        return AfterBusy(job, err, problem, r);
      case ModbusFailure::kDeviceException:
        return DeviceError(ModbusExceptionCode(err),
                           problem + " (exception " + std::to_string(ModbusExceptionCode(err)) +
                               "); check the drive's display or alarm log");
      case ModbusFailure::kTimeout:
        DiscardStrayReplies(job);
        if (++r.timeouts > config_.timeout_retries) {
          return Timeout(problem + " (no reply within " +
                         std::to_string(config_.response_timeout.count()) + " ms, " +
                         std::to_string(r.timeouts) +
                         " attempts); check the unit id, the cabling and the drive's power");
        }
        return std::nullopt;
      case ModbusFailure::kStaleOrGarbled:
        DiscardStrayReplies(job);
        if (++r.garbled > config_.garbled_retries) {
          return ProtocolError(problem + " (" + std::to_string(r.garbled) +
                               " replies did not match their request); check for another "
                               "master on the bus, the baud rate and the parity");
        }
        return std::nullopt;
      case ModbusFailure::kLinkDown:
        Drop();  // the next round reconnects, bounded
        return std::nullopt;
      case ModbusFailure::kOther:
        Drop();
        return IoError(problem + "; the local system refused the request");
    }
    return std::nullopt;
  }

  // The drive answered busy: wait (backing off) and try again, until busy_window has passed.
  std::optional<Status> AfterBusy(Job& job, int err, const std::string& problem, Retries& r) {
    const auto now = SteadyClock::now();
    if (r.busy++ == 0) r.busy_since = now;
    if (now - r.busy_since >= config_.busy_window) {
      const int code = ModbusExceptionCode(err);
      return DeviceError(code, problem + " (exception " + std::to_string(code) + ", " +
                                   std::to_string(r.busy) + " answers over " +
                                   std::to_string(config_.busy_window.count()) +
                                   " ms, the stage's busy_window_ms); the drive stays busy or "
                                   "refuses to execute: check the drive's display or alarm log");
    }
    if (!Sleep(r.busy_backoff, job)) return GaveUp(job);
    r.busy_backoff = std::min(r.busy_backoff * 2, config_.busy_backoff_max);
    return std::nullopt;
  }

  bool is_rtu() const { return std::holds_alternative<RtuEndpoint>(config_.endpoint); }

  Status Create() {
    if (const auto* tcp = std::get_if<TcpEndpoint>(&config_.endpoint)) {
      ctx_ = modbus_new_tcp(tcp->host.c_str(), tcp->port);
    } else {
      const auto& rtu = std::get<RtuEndpoint>(config_.endpoint);
      ctx_ = modbus_new_rtu(rtu.device.c_str(), rtu.baud, rtu.parity, rtu.data_bits, rtu.stop_bits);
    }
    if (ctx_ == nullptr) {
      return ConfigurationError(description_ + ": libmodbus refused the settings: " +
                                ModbusErrorText(errno) + "; check the bus configuration");
    }
    modbus_set_error_recovery(ctx_, MODBUS_ERROR_RECOVERY_NONE);
    if (is_rtu()) modbus_set_slave(ctx_, 1);  // the RTU backend asserts without a slave
    return Status::Ok();
  }

  void Drop() {
    if (ctx_ != nullptr && connected_) modbus_close(ctx_);
    connected_ = false;
  }

  // The response timeout, shortened to what is left of the caller's patience (at least 1 ms).
  void SetResponseTimeout(const Job& job) {
    auto left =
        std::chrono::duration_cast<std::chrono::microseconds>(job.deadline - SteadyClock::now());
    auto timeout = std::chrono::duration_cast<std::chrono::microseconds>(config_.response_timeout);
    timeout = std::clamp(left, std::chrono::microseconds(1000), timeout);
    modbus_set_response_timeout(ctx_, static_cast<std::uint32_t>(timeout.count() / 1'000'000),
                                static_cast<std::uint32_t>(timeout.count() % 1'000'000));
  }

  // After a timeout or a reply that did not match: make sure a late reply cannot answer the next
  // request. TCP: drop the connection (the next attempt reconnects). RTU: read and discard the
  // line for rtu_drain, then flush.
  void DiscardStrayReplies(const Job& job) {
    if (!is_rtu()) {
      Drop();
      return;
    }
    const int fd = modbus_get_socket(ctx_);
    const auto until = SteadyClock::now() + config_.rtu_drain;
    while (fd >= 0 && !stopping_ && !job.abandoned.load()) {
      const auto left = std::chrono::duration_cast<milliseconds>(until - SteadyClock::now());
      if (left.count() <= 0) break;
      pollfd p{fd, POLLIN, 0};
      const int n = ::poll(&p, 1, static_cast<int>(std::min<long>(left.count(), 20)));
      if (n > 0 && (p.revents & POLLIN) != 0) {
        unsigned char junk[256];
        if (::read(fd, junk, sizeof junk) <= 0) break;
      } else if (n < 0 && errno != EINTR) {
        break;
      }
    }
    if (ctx_ != nullptr && connected_) modbus_flush(ctx_);
  }

  // Sleeps up to `d`; false if the job was given up or the bus is closing meanwhile.
  bool Sleep(milliseconds d, const Job& job) {
    const auto until = SteadyClock::now() + d;
    while (SteadyClock::now() < until) {
      if (job.GivenUp() || stopping_) return false;
      const auto left = std::chrono::duration_cast<milliseconds>(until - SteadyClock::now());
      if (job.cancel.WaitFor(std::min(left, milliseconds(10)))) return false;
    }
    return !job.GivenUp();
  }

  Status GaveUp(const Job& job) const {
    const std::string what = description_ + " " + job.What();
    if (stopping_) return Disconnected(what + ": the bus was closed");
    if (job.cancel.cancelled())
      return Cancelled(what + ": cancelled (" + job.cancel.reason() + ")");
    return Timeout(what + ": the caller's deadline passed");
  }

  const BusConfig& config_;
  const std::string& description_;
  const std::atomic<bool>& stopping_;  // the bus is closing: stop waiting and retrying
  modbus_t* ctx_ = nullptr;
  bool connected_ = false;
};

Status ValidateBus(int index, const BusConfig& c) {
  auto fail = [&](const std::string& field, const std::string& problem) {
    return ConfigurationError("stage bus " + std::to_string(index) + " field '" + field +
                              "': " + problem + "; fix the stage bus in the configuration");
  };
  if (const auto* tcp = std::get_if<TcpEndpoint>(&c.endpoint)) {
    if (tcp->host.empty()) return fail("host", "is empty");
    if (tcp->port < 1 || tcp->port > 65535) {
      return fail("port", "must be 1–65535, got " + std::to_string(tcp->port));
    }
  } else {
    const auto& rtu = std::get<RtuEndpoint>(c.endpoint);
    if (rtu.device.empty()) return fail("device", "is empty");
    if (rtu.baud <= 0) return fail("baud", "must be positive, got " + std::to_string(rtu.baud));
    if (rtu.parity != 'N' && rtu.parity != 'E' && rtu.parity != 'O') {
      return fail("parity", std::string("must be N, E or O, got ") + rtu.parity);
    }
    if (rtu.data_bits < 5 || rtu.data_bits > 8) return fail("data_bits", "must be 5–8");
    if (rtu.stop_bits != 1 && rtu.stop_bits != 2) return fail("stop_bits", "must be 1 or 2");
  }
  if (c.response_timeout.count() <= 0) return fail("response_timeout", "must be positive");
  if (c.timeout_retries < 0) return fail("timeout_retries", "must be 0 or more");
  if (c.busy_window.count() < 0) return fail("busy_window", "must not be negative");
  if (c.busy_backoff_max < c.busy_backoff) {
    return fail("busy_backoff_max", "must not be shorter than busy_backoff");
  }
  if (c.garbled_retries < 0) return fail("garbled_retries", "must be 0 or more");
  if (c.reconnect_attempts < 1) return fail("reconnect_attempts", "must be 1 or more");
  if (c.busy_backoff.count() < 0 || c.reconnect_backoff.count() < 0 || c.rtu_drain.count() < 0) {
    return fail("busy_backoff/reconnect_backoff/rtu_drain", "must not be negative");
  }
  return Status::Ok();
}

std::string DescribeBus(const BusConfig& c) {
  if (const auto* tcp = std::get_if<TcpEndpoint>(&c.endpoint)) {
    return "Modbus TCP " + tcp->host + ":" + std::to_string(tcp->port);
  }
  const auto& rtu = std::get<RtuEndpoint>(c.endpoint);
  return "Modbus RTU " + rtu.device + " (" + std::to_string(rtu.baud) + " " +
         std::to_string(rtu.data_bits) + rtu.parity + std::to_string(rtu.stop_bits) + ")";
}

ModbusBus::ModbusBus(BusConfig config)
    : config_(std::move(config)), description_(DescribeBus(config_)) {}

ModbusBus::~ModbusBus() {
  Close();
}

Status ModbusBus::Open(const CallContext& ctx) {
  MutexLock lifecycle(lifecycle_mu_);
  if (open_.load()) return Status::Ok();
  {
    MutexLock l(mu_);
    running_ = true;
    stopping_ = false;
  }
  thread_ = std::thread([this] { Run(); });
  auto job = std::make_shared<Job>();
  job->kind = Job::Kind::kConnect;
  auto result = Submit(job, ctx, BusPriority::kNormal);
  if (!result.ok()) {
    StopThread();
    return result.status();
  }
  open_.store(true);
  return Status::Ok();
}

void ModbusBus::Close() {
  MutexLock lifecycle(lifecycle_mu_);
  open_.store(false);
  StopThread();
}

void ModbusBus::StopThread() {
  {
    MutexLock l(mu_);
    if (!running_) return;
    stopping_ = true;
  }
  cv_.NotifyAll();
  if (thread_.joinable()) thread_.join();
  MutexLock l(mu_);
  running_ = false;
}

Result<std::vector<std::uint16_t>> ModbusBus::ReadRegisters(int unit, std::uint16_t address,
                                                            int count, const CallContext& ctx,
                                                            BusPriority priority) {
  if (count < 1 || count > MODBUS_MAX_READ_REGISTERS) {
    return Internal(description_ + ": read of " + std::to_string(count) +
                    " registers; Modbus allows 1–125 per request");
  }
  auto job = std::make_shared<Job>();
  job->kind = Job::Kind::kRead;
  job->unit = unit;
  job->address = address;
  job->count = count;
  return Submit(job, ctx, priority);
}

Status ModbusBus::WriteRegisters(int unit, std::uint16_t address, std::vector<std::uint16_t> values,
                                 const CallContext& ctx, BusPriority priority) {
  if (values.empty() || values.size() > MODBUS_MAX_WRITE_REGISTERS) {
    return Internal(description_ + ": write of " + std::to_string(values.size()) +
                    " registers; Modbus allows 1–123 per request");
  }
  auto job = std::make_shared<Job>();
  job->kind = Job::Kind::kWrite;
  job->unit = unit;
  job->address = address;
  job->values = std::move(values);
  return Submit(job, ctx, priority).status();
}

Result<std::vector<std::uint16_t>> ModbusBus::Submit(const std::shared_ptr<Job>& job,
                                                     const CallContext& ctx, BusPriority priority) {
  if (ctx.cancelled()) {
    return Cancelled(description_ + " " + job->What() + ": cancelled (" + ctx.cancel().reason() +
                     ")");
  }
  job->cancel = ctx.cancel();
  job->deadline = SteadyClock::now() + ctx.remaining();
  {
    MutexLock l(mu_);
    if (!running_ || stopping_) {
      return Disconnected(description_ + " " + job->What() +
                          ": the bus is not open; call Connect first");
    }
    if (priority == BusPriority::kUrgent) {
      queue_.push_front(job);
    } else {
      queue_.push_back(job);
    }
  }
  cv_.NotifyAll();

  MutexLock l(job->mu);
  while (!job->done) {
    if (ctx.cancelled()) {
      job->abandoned.store(true);
      return Cancelled(description_ + " " + job->What() + ": cancelled (" + ctx.cancel().reason() +
                       ")");
    }
    if (ctx.expired()) {
      job->abandoned.store(true);
      return Timeout(description_ + " " + job->What() +
                     ": no answer before the call's deadline; the bus may be busy or the drive "
                     "silent");
    }
    // Short slices: the caller's clock may be scaled, and cancel tokens cannot wake this wait.
    job->cv.WaitFor(job->mu, milliseconds(2));
  }
  if (!job->status.ok()) return job->status;
  return std::move(job->data);
}

void ModbusBus::Run() {
  Link link(config_, description_, stopping_);
  while (true) {
    std::shared_ptr<Job> job;
    {
      MutexLock l(mu_);
      cv_.Wait(mu_, [&]() REQUIRES(mu_) { return stopping_ || !queue_.empty(); });
      if (stopping_) break;
      job = queue_.front();
      queue_.pop_front();
    }
    if (job->abandoned.load()) continue;
    Status status =
        job->kind == Job::Kind::kConnect ? link.Connect(*job, true) : link.Execute(*job);
    {
      MutexLock jl(job->mu);
      job->status = std::move(status);
      job->done = true;
    }
    job->cv.NotifyAll();
  }
  link.Destroy();
  std::deque<std::shared_ptr<Job>> left;
  {
    MutexLock l(mu_);
    left.swap(queue_);
  }
  for (auto& job : left) {
    {
      MutexLock jl(job->mu);
      job->status = Disconnected(description_ + " " + job->What() + ": the bus was closed");
      job->done = true;
    }
    job->cv.NotifyAll();
  }
}

}  // namespace brdf::drivers::stage
