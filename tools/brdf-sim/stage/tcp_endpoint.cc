#include "tools/brdf-sim/stage/tcp_endpoint.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <span>
#include <utility>

namespace brdf::sim {

namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr std::size_t kMbapLength = 7;       // transaction, protocol, length, unit id
constexpr std::size_t kMbapHeaderBytes = 6;  // what the length field does not count
constexpr std::size_t kMinLength = 2;        // unit id + function code
constexpr std::size_t kMaxLength = 254;      // unit id + the 253-byte PDU maximum

}  // namespace

StageTcpEndpoint::~StageTcpEndpoint() {
  Stop();
}

bool StageTcpEndpoint::Start(const std::string& host, int port, std::string* error) {
  ctx_ = modbus_new_tcp(host.c_str(), port);
  if (ctx_ == nullptr) {
    *error = "stage simulator: cannot create a Modbus TCP context for " + host + ": " +
             modbus_strerror(errno);
    return false;
  }
  listen_fd_ = modbus_tcp_listen(ctx_, 16);
  if (listen_fd_ < 0) {
    *error = "stage simulator: cannot listen on " + host + ":" + std::to_string(port) + ": " +
             modbus_strerror(errno) + "; choose another --modbus-port (0 picks a free one)";
    modbus_free(ctx_);
    ctx_ = nullptr;
    return false;
  }
  host_ = host;
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  if (::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port_ = ntohs(addr.sin_port);
  }
  if (::pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0) {
    *error = std::string("stage simulator: cannot create a pipe: ") + std::strerror(errno);
    ::close(listen_fd_);
    listen_fd_ = -1;
    modbus_free(ctx_);
    ctx_ = nullptr;
    return false;
  }
  stopping_ = false;
  thread_ = std::thread([this] { Run(); });
  return true;
}

void StageTcpEndpoint::Stop() {
  if (thread_.joinable()) {
    stopping_ = true;
    const char byte = 1;
    [[maybe_unused]] const auto n = ::write(wake_[1], &byte, 1);
    thread_.join();
  }
  for (auto& [fd, client] : clients_) ::close(fd);
  clients_.clear();
  clients_count_ = 0;
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
  for (int& fd : wake_) {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  if (ctx_ != nullptr) {
    modbus_set_socket(ctx_, -1);
    modbus_free(ctx_);
    ctx_ = nullptr;
  }
}

void StageTcpEndpoint::Run() {
  while (!stopping_) {
    ListenAgainWhenDue();
    fd_set readable;
    FD_ZERO(&readable);
    if (listen_fd_ >= 0) FD_SET(listen_fd_, &readable);
    FD_SET(wake_[0], &readable);
    int max_fd = std::max(listen_fd_, wake_[0]);
    std::chrono::milliseconds wait(1000);
    const auto now = SteadyClock::now();
    if (listen_fd_ < 0) {
      wait = std::clamp(std::chrono::duration_cast<std::chrono::milliseconds>(refuse_until_ - now) +
                            std::chrono::milliseconds(1),
                        std::chrono::milliseconds(1), wait);
    }
    for (const auto& [fd, client] : clients_) {
      FD_SET(fd, &readable);
      max_fd = std::max(max_fd, fd);
      if (!client.queue.empty()) {
        wait = std::min(wait, std::max(std::chrono::milliseconds(0),
                                       std::chrono::duration_cast<std::chrono::milliseconds>(
                                           client.queue.front().due - now) +
                                           std::chrono::milliseconds(1)));
      }
    }
    timeval tv{static_cast<time_t>(wait.count() / 1000),
               static_cast<suseconds_t>((wait.count() % 1000) * 1000)};
    const int n = ::select(max_fd + 1, &readable, nullptr, nullptr, &tv);
    if (n < 0 && errno != EINTR) break;
    if (n > 0) {
      if (FD_ISSET(wake_[0], &readable)) {
        char drain[16];
        while (::read(wake_[0], drain, sizeof drain) > 0) {
        }
      }
      if (stopping_) break;
      if (listen_fd_ >= 0 && FD_ISSET(listen_fd_, &readable)) Accept();
      std::vector<int> ready;
      for (const auto& [fd, client] : clients_) {
        if (FD_ISSET(fd, &readable)) ready.push_back(fd);
      }
      for (int fd : ready) Receive(fd);
    }
    SendDue();
  }
}

void StageTcpEndpoint::Accept() {
  int listen_fd = listen_fd_;
  const int fd = modbus_tcp_accept(ctx_, &listen_fd);
  if (fd < 0) return;
  clients_[fd];
  clients_count_ = static_cast<int>(clients_.size());
}

void StageTcpEndpoint::RefuseUntil(SteadyClock::time_point until) {
  refuse_until_ = std::max(refuse_until_, until);
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
}

void StageTcpEndpoint::ListenAgainWhenDue() {
  if (listen_fd_ >= 0 || SteadyClock::now() < refuse_until_) return;
  // A context for the port first chosen (the first one may have asked for port 0).
  modbus_t* ctx = modbus_new_tcp(host_.c_str(), port_);
  if (ctx == nullptr) return;
  const int fd = modbus_tcp_listen(ctx, 16);
  if (fd < 0) {
    modbus_free(ctx);
    refuse_until_ = SteadyClock::now() + std::chrono::milliseconds(100);  // try again shortly
    return;
  }
  modbus_set_socket(ctx_, -1);
  modbus_free(ctx_);
  ctx_ = ctx;
  listen_fd_ = fd;
}

void StageTcpEndpoint::CloseClient(int fd) {
  ::close(fd);
  clients_.erase(fd);
  clients_count_ = static_cast<int>(clients_.size());
}

void StageTcpEndpoint::Receive(int fd) {
  Client& client = clients_[fd];
  std::uint8_t buffer[1024];
  const ssize_t n = ::recv(fd, buffer, sizeof buffer, MSG_DONTWAIT);
  if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
    CloseClient(fd);  // closed by the peer, or broken
    return;
  }
  if (n < 0) return;
  client.input.insert(client.input.end(), buffer, buffer + n);
  if (!ServeFramed(client)) CloseClient(fd);
}

bool StageTcpEndpoint::ServeFramed(Client& client) {
  std::size_t at = 0;
  bool keep = true;
  while (keep && client.input.size() - at >= kMbapLength) {
    const std::uint8_t* h = client.input.data() + at;
    const std::size_t length = static_cast<std::size_t>((h[4] << 8) | h[5]);
    if (length < kMinLength || length > kMaxLength) {
      keep = false;  // cannot be framed: no function code, or longer than any PDU
      break;
    }
    const std::size_t adu_size = kMbapHeaderBytes + length;
    if (client.input.size() - at < adu_size) break;  // the rest is still on its way
    const std::span<const std::uint8_t> adu(h, adu_size);
    at += adu_size;
    const std::uint16_t protocol = static_cast<std::uint16_t>((h[2] << 8) | h[3]);
    if (protocol != 0) continue;  // not Modbus: dropped without a reply (Modbus TCP spec)
    const StageReply reply =
        dispatcher_.Handle(adu[6], adu.subspan(kMbapLength), StageTransport::kTcp);
    switch (reply.kind) {
      case StageReply::Kind::kDrop:
        keep = false;
        if (reply.refuse_connections.count() > 0) {
          RefuseUntil(SteadyClock::now() + reply.refuse_connections);
        }
        break;
      case StageReply::Kind::kSilent:
        break;
      case StageReply::Kind::kReply: {
        std::vector<std::uint8_t> frame{adu[0], adu[1], 0, 0};  // transaction id, protocol 0
        const auto reply_length = static_cast<std::uint16_t>(reply.pdu.size() + 1);
        frame.push_back(static_cast<std::uint8_t>(reply_length >> 8));
        frame.push_back(static_cast<std::uint8_t>(reply_length & 0xFF));
        frame.push_back(adu[6]);  // unit id
        frame.insert(frame.end(), reply.pdu.begin(), reply.pdu.end());
        auto due = SteadyClock::now() + reply.delay;
        if (!client.queue.empty()) due = std::max(due, client.queue.back().due);
        client.queue.push_back({due, std::move(frame)});
        break;
      }
    }
  }
  client.input.erase(client.input.begin(), client.input.begin() + static_cast<std::ptrdiff_t>(at));
  return keep;
}

void StageTcpEndpoint::SendDue() {
  const auto now = SteadyClock::now();
  std::vector<int> broken;
  for (auto& [fd, client] : clients_) {
    while (!client.queue.empty() && client.queue.front().due <= now) {
      const std::vector<std::uint8_t> bytes = std::move(client.queue.front().bytes);
      client.queue.pop_front();
      const ssize_t sent = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
      if (sent != static_cast<ssize_t>(bytes.size())) {
        broken.push_back(fd);
        break;
      }
    }
  }
  for (int fd : broken) CloseClient(fd);
}

}  // namespace brdf::sim
