#include "drivers/exclusive_open.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace brdf::drivers {

std::string DescribeProcess(int pid) {
  std::string text = "pid " + std::to_string(pid);
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
  std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!cmdline.empty() && cmdline.back() == '\0') cmdline.pop_back();
  if (cmdline.empty()) return text;
  for (char& c : cmdline) {
    if (c == '\0') c = ' ';
    if (static_cast<unsigned char>(c) < 0x20) c = '?';
  }
  constexpr size_t kMax = 160;
  if (cmdline.size() > kMax) cmdline = cmdline.substr(0, kMax) + "...";
  return text + " (" + cmdline + ")";
}

std::optional<int> LockHolder(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  // /proc/locks: "1: FLOCK  ADVISORY  WRITE 1234 00:05:3 0 EOF" (id, kind, mode, access, pid,
  // major:minor:inode of the file system and inode; "->" marks a waiter).
  std::ifstream in("/proc/locks");
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("->") != std::string::npos) continue;
    std::istringstream fields(line);
    std::string id, kind, mode, access, where;
    long pid = 0;
    if (!(fields >> id >> kind >> mode >> access >> pid >> where)) continue;
    unsigned int maj = 0, min = 0;
    unsigned long long inode = 0;
    if (std::sscanf(where.c_str(), "%x:%x:%llu", &maj, &min, &inode) != 3) continue;
    if (inode == st.st_ino && maj == major(st.st_dev) && min == minor(st.st_dev) && pid > 0) {
      return static_cast<int>(pid);
    }
  }
  return std::nullopt;
}

namespace {

Status InUse(const std::string& path, const std::string& how) {
  const std::optional<int> holder = LockHolder(path);
  const std::string who = holder ? DescribeProcess(*holder) : "another process";
  return FailedPrecondition("serial port " + path + " is in use by " + who + how +
                            ": stop that program (or that brdfd), or set [meter] port to the "
                            "meter's own port; brdfd keeps trying and takes the port once it "
                            "is free");
}

}  // namespace

Status LockDeviceExclusively(int fd, const std::string& path) {
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno == EWOULDBLOCK) return InUse(path, " (it holds the port's lock)");
    // A file system without flock: TIOCEXCL below still keeps other programs out.
  }
  if (::isatty(fd) && ::ioctl(fd, TIOCEXCL) != 0 && errno != ENOTTY && errno != EINVAL) {
    return FailedPrecondition("serial port " + path + ": cannot open it exclusively (TIOCEXCL: " +
                              std::strerror(errno) + ")");
  }
  return Status::Ok();
}

Status CheckDeviceFree(const std::string& path) {
  if (path.empty()) return Status::Ok();
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == EBUSY) return InUse(path, " (it opened the port exclusively)");
    return Status::Ok();
  }
  Status status = Status::Ok();
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK) {
    status = InUse(path, " (it holds the port's lock)");
  }
  ::close(fd);  // releases our probe's lock with it
  return status;
}

}  // namespace brdf::drivers
