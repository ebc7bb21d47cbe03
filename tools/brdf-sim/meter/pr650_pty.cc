#include "tools/brdf-sim/meter/pr650_pty.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace brdf::sim {

namespace {

Status Errno(const std::string& what) {
  return IoError("PR-650 simulator: " + what + " failed (" + std::strerror(errno) + ")");
}

}  // namespace

Status Pr650Pty::Open() {
  Close();
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0) return Errno("posix_openpt");
  char name[128];
  if (::grantpt(master) != 0 || ::unlockpt(master) != 0 ||
      ::ptsname_r(master, name, sizeof name) != 0) {
    const Status status = Errno("setting up the pty (grantpt/unlockpt/ptsname)");
    ::close(master);
    return status;
  }
  const int slave = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave < 0) {
    const Status status = Errno(std::string("opening the pty slave ") + name);
    ::close(master);
    return status;
  }
  termios t{};
  if (::tcgetattr(slave, &t) == 0) {
    ::cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD;
    ::cfsetispeed(&t, B9600);
    ::cfsetospeed(&t, B9600);
    ::tcsetattr(slave, TCSANOW, &t);
  }
  const int flags = ::fcntl(master, F_GETFL);
  if (flags >= 0) ::fcntl(master, F_SETFL, flags | O_NONBLOCK);
  master_ = master;
  slave_keepalive_ = slave;
  slave_path_ = name;
  return Status::Ok();
}

void Pr650Pty::Close() {
  if (slave_keepalive_ >= 0) ::close(slave_keepalive_);
  if (master_ >= 0) ::close(master_);
  slave_keepalive_ = -1;
  master_ = -1;
}

Status Pr650PtyLink::Create(const std::string& path) {
  Remove();
  if (path.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/brdf-sim-pr650-XXXXXX";
    if (::mkdtemp(templ.data()) == nullptr) return Errno("creating a directory for the port link");
    private_dir_ = templ;
    path_ = templ + "/pr650";
    return Status::Ok();
  }
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && !S_ISLNK(st.st_mode)) {
    return ConfigurationError("PR-650 simulator: " + path +
                              " exists and is not a symlink; choose another port link path");
  }
  path_ = path;
  return Status::Ok();
}

Status Pr650PtyLink::PointAt(const std::string& target) {
  const std::string temp = path_ + ".new";
  ::unlink(temp.c_str());
  if (::symlink(target.c_str(), temp.c_str()) != 0) return Errno("creating link " + temp);
  if (::rename(temp.c_str(), path_.c_str()) != 0) {
    const Status status = Errno("renaming " + temp + " to " + path_);
    ::unlink(temp.c_str());
    return status;
  }
  return Status::Ok();
}

void Pr650PtyLink::Unlink() {
  if (!path_.empty()) ::unlink(path_.c_str());
}

void Pr650PtyLink::Remove() {
  Unlink();
  if (!private_dir_.empty()) ::rmdir(private_dir_.c_str());
  private_dir_.clear();
  path_.clear();
}

Status PtyPort::Open(const std::string& link_path) {
  BRDF_RETURN_IF_ERROR(pty_.Open());
  Status status = link_.Create(link_path);
  if (status.ok()) status = link_.PointAt(pty_.slave_path());
  if (!status.ok()) Close();
  return status;
}

void PtyPort::Close() {
  pty_.Close();
  link_.Remove();
}

void PtyPort::Unplug() {
  pty_.Close();
  link_.Unlink();
}

void PtyPort::Replug() {
  if (pty_.Open().ok() && !link_.PointAt(pty_.slave_path()).ok()) pty_.Close();
}

}  // namespace brdf::sim
