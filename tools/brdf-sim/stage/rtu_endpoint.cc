#include "tools/brdf-sim/stage/rtu_endpoint.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <span>

namespace brdf::sim {

namespace {

using SteadyClock = std::chrono::steady_clock;

std::string Errno(const char* what) {
  return std::string(what) + ": " + std::strerror(errno);
}

}  // namespace

StageRtuEndpoint::~StageRtuEndpoint() {
  Stop();
}

bool StageRtuEndpoint::Start(std::string* error) {
  auto fail = [&](const std::string& message) {
    *error = "stage simulator: RTU pty: " + message;
    Stop();
    return false;
  };
  master_fd_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_fd_ < 0) return fail(Errno("posix_openpt"));
  if (::grantpt(master_fd_) != 0) return fail(Errno("grantpt"));
  if (::unlockpt(master_fd_) != 0) return fail(Errno("unlockpt"));
  char name[128];
  if (::ptsname_r(master_fd_, name, sizeof name) != 0) return fail(Errno("ptsname_r"));
  path_ = name;
  keep_slave_fd_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (keep_slave_fd_ < 0) return fail(Errno("open slave"));
  termios tio{};
  if (::tcgetattr(keep_slave_fd_, &tio) == 0) {
    ::cfmakeraw(&tio);  // no echo, no line editing: bytes pass as they are
    ::tcsetattr(keep_slave_fd_, TCSANOW, &tio);
  }
  ::fcntl(master_fd_, F_SETFL, ::fcntl(master_fd_, F_GETFL) | O_NONBLOCK);
  if (::pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0) return fail(Errno("pipe2"));
  stopping_ = false;
  thread_ = std::thread([this] { Run(); });
  return true;
}

void StageRtuEndpoint::Stop() {
  if (thread_.joinable()) {
    stopping_ = true;
    const char byte = 1;
    [[maybe_unused]] const auto n = ::write(wake_[1], &byte, 1);
    thread_.join();
  }
  for (int* fd : {&master_fd_, &keep_slave_fd_, &wake_[0], &wake_[1]}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
  queue_.clear();
}

void StageRtuEndpoint::Run() {
  while (!stopping_) {
    pollfd fds[2] = {{master_fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    int wait_ms = 20;  // also the pace of expiring half frames
    if (!queue_.empty()) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(queue_.front().due -
                                                                              SteadyClock::now());
      wait_ms = static_cast<int>(std::clamp<long>(left.count() + 1, 0, wait_ms));
    }
    const int n = ::poll(fds, 2, wait_ms);
    if (n < 0 && errno != EINTR) break;
    if (stopping_) break;
    const auto now = SteadyClock::now();
    if (n > 0 && (fds[0].revents & POLLIN) != 0) {
      std::uint8_t buf[512];
      const ssize_t got = ::read(master_fd_, buf, sizeof buf);
      if (got > 0) splitter_.Feed(std::span(buf, static_cast<std::size_t>(got)), now);
    }
    splitter_.Expire(now);
    while (auto frame = splitter_.Next()) Serve(*frame);
    crc_errors_ = splitter_.crc_errors();
    SendDue();
  }
}

void StageRtuEndpoint::Serve(const std::vector<std::uint8_t>& frame) {
  const std::uint8_t unit = frame[0];
  if (unit == 0) return;  // broadcast: not used by the stage, never answered
  const StageReply reply =
      dispatcher_.Handle(unit, std::span(frame).subspan(1), StageTransport::kRtu);
  if (reply.kind != StageReply::Kind::kReply) return;
  std::vector<std::uint8_t> out;
  out.reserve(reply.pdu.size() + 3);
  out.push_back(unit);
  for (std::uint8_t b : reply.pdu) out.push_back(b);
  AppendCrc(out);
  auto due = SteadyClock::now() + reply.delay;
  if (!queue_.empty()) due = std::max(due, queue_.back().due);
  queue_.push_back({due, std::move(out)});
}

void StageRtuEndpoint::SendDue() {
  const auto now = SteadyClock::now();
  while (!queue_.empty() && queue_.front().due <= now) {
    const auto& bytes = queue_.front().bytes;
    std::size_t done = 0;
    int stalls = 0;  // nobody reads the line: give the frame up rather than block the endpoint
    while (done < bytes.size() && stalls < 50) {
      const ssize_t n = ::write(master_fd_, bytes.data() + done, bytes.size() - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
      } else if (n < 0 && errno != EAGAIN && errno != EINTR) {
        break;
      } else {
        ++stalls;
        pollfd p{master_fd_, POLLOUT, 0};
        ::poll(&p, 1, 10);
      }
    }
    queue_.pop_front();
  }
}

}  // namespace brdf::sim
