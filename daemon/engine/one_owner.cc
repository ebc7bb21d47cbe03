#include "daemon/engine/one_owner.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "drivers/exclusive_open.h"

namespace brdf::daemon {
namespace {

// The pid of the process that has socket inode `inode` open (scans /proc/*/fd; processes of other
// users are only visible to root).
std::optional<int> SocketOwner(unsigned long long inode) {
  const std::string target = "socket:[" + std::to_string(inode) + "]";
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return std::nullopt;
  std::optional<int> owner;
  while (dirent* entry = ::readdir(proc)) {
    const std::string name = entry->d_name;
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string fd_dir = "/proc/" + name + "/fd";
    DIR* fds = ::opendir(fd_dir.c_str());
    if (fds == nullptr) continue;
    while (dirent* fd = ::readdir(fds)) {
      char link[128];
      const std::string path = fd_dir + "/" + fd->d_name;
      const ssize_t n = ::readlink(path.c_str(), link, sizeof link - 1);
      if (n <= 0) continue;
      link[n] = '\0';
      if (target == link) {
        owner = std::stoi(name);
        break;
      }
    }
    ::closedir(fds);
    if (owner) break;
  }
  ::closedir(proc);
  return owner;
}

// The inode of a listening TCP socket on `port` in /proc/net/tcp or tcp6 (state 0A = LISTEN).
std::optional<unsigned long long> ListeningInode(int port) {
  for (const char* table : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream in(table);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout;
      unsigned long long inode = 0;
      if (!(fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >>
            timeout >> inode)) {
        continue;
      }
      const size_t colon = local.rfind(':');
      if (colon == std::string::npos || state != "0A") continue;
      if (std::stoi(local.substr(colon + 1), nullptr, 16) == port) return inode;
    }
  }
  return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<DatabaseLock>> DatabaseLock::Acquire(const std::string& database) {
  const std::string path = database + ".lock";
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0640);
  if (fd < 0) {
    return IoError("cannot create the database's lock file " + path + " (" + std::strerror(errno) +
                   "): the daemon's user must be able to write in " + "the database's directory");
  }
  struct flock lock {};
  lock.l_type = F_WRLCK;
  lock.l_whence = SEEK_SET;
  if (::fcntl(fd, F_SETLK, &lock) != 0) {
    const int err = errno;
    struct flock holder {};
    holder.l_type = F_WRLCK;
    holder.l_whence = SEEK_SET;
    const bool known = ::fcntl(fd, F_GETLK, &holder) == 0 && holder.l_type != F_UNLCK;
    ::close(fd);
    if (err != EACCES && err != EAGAIN) {
      return IoError("cannot lock " + path + " (" + std::strerror(err) + ")");
    }
    const std::string who =
        known ? drivers::DescribeProcess(static_cast<int>(holder.l_pid)) : "another process";
    return FailedPrecondition(
        "database " + database + " is in use by " + who +
        ": one daemon owns a database. Stop that daemon first (kill -TERM " +
        (known ? std::to_string(holder.l_pid) : std::string("<pid>")) +
        ", or systemctl stop brdfd), or give this one another [storage] database");
  }
  // For people: who owns it. Decided by the lock alone.
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd, pid.data(), pid.size(), 0);
  }
  return std::unique_ptr<DatabaseLock>(new DatabaseLock(fd, path));
}

DatabaseLock::~DatabaseLock() {
  ::close(fd_);
}

Status CheckListenAddressFree(const std::string& listen) {
  if (listen.rfind("unix:", 0) == 0) return Status::Ok();
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos) return Status::Ok();
  std::string host = listen.substr(0, colon);
  const std::string port_text = listen.substr(colon + 1);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  if (port_text.empty() || port_text == "0") return Status::Ok();
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.empty() ? nullptr : host.c_str(), port_text.c_str(), &hints, &found) !=
      0) {
    return Status::Ok();
  }
  bool in_use = false;
  for (addrinfo* a = found; a != nullptr && !in_use; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int on = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);  // as gRPC does
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 && errno == EADDRINUSE) in_use = true;
    ::close(fd);
  }
  ::freeaddrinfo(found);
  if (!in_use) return Status::Ok();
  std::string who = "another process";
  if (const auto inode = ListeningInode(std::stoi(port_text))) {
    if (const auto pid = SocketOwner(*inode)) who = drivers::DescribeProcess(*pid);
  }
  return FailedPrecondition("cannot listen on " + listen + ": the address is in use by " + who +
                            ". Stop it (a second brdfd there would answer some of the calls "
                            "meant for the first), or set [server] listen to a free address");
}

}  // namespace brdf::daemon
