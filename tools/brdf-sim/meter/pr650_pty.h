// A pseudo-terminal standing in for the PR-650's serial port: the simulator holds the master, a
// driver opens the slave path like any /dev/ttyUSB*. Raw mode (no echo, no line editing, no CR/LF
// translation) is set on the slave so the bytes arrive exactly as written.
//
// The pty number of a re-created pty is not guaranteed to be the same (the kernel reuses the
// lowest free number, and the old one stays taken while a driver still holds the old slave open),
// so a stable symlink (PtyLink) points at whichever pty is current; drivers are configured with
// the link.
#pragma once

#include <string>

#include "core/status.h"

namespace brdf::sim {

class Pr650Pty {
 public:
  Pr650Pty() = default;
  ~Pr650Pty() { Close(); }
  Pr650Pty(const Pr650Pty&) = delete;
  Pr650Pty& operator=(const Pr650Pty&) = delete;

  // Creates the pair (posix_openpt, grantpt, unlockpt, ptsname), makes the slave raw and keeps
  // one slave descriptor open so that the master does not see a hang-up whenever the driver
  // closes and reopens the port (as it does to drop RTS).
  Status Open();
  // Closes both ends: a driver holding the slave sees a hang-up (EIO), as when a USB adapter is
  // pulled.
  void Close();

  bool is_open() const { return master_ >= 0; }
  int master_fd() const { return master_; }
  const std::string& slave_path() const { return slave_path_; }

 private:
  int master_ = -1;
  int slave_keepalive_ = -1;
  std::string slave_path_;
};

// A symlink at a fixed path that points at the current pty slave.
class Pr650PtyLink {
 public:
  Pr650PtyLink() = default;
  ~Pr650PtyLink() { Remove(); }
  Pr650PtyLink(const Pr650PtyLink&) = delete;
  Pr650PtyLink& operator=(const Pr650PtyLink&) = delete;

  // `path` empty: a link named "pr650" in a new private directory under $TMPDIR (or /tmp),
  // removed again by Remove(). An existing symlink at `path` is replaced; any other file there is
  // an error.
  Status Create(const std::string& path);
  // Atomically (rename) points the link at `target`.
  Status PointAt(const std::string& target);
  // Removes the link itself (the port "vanishes") but keeps the path for PointAt.
  void Unlink();
  // Removes the link and the private directory, if one was made.
  void Remove();

  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string private_dir_;
};

// A meter's port as the endpoints handle it: the pty behind its stable link, which can be
// unplugged (the pty closed, the link removed: a driver holding it sees a hang-up) and plugged in
// again (a new pty, the link pointing at it). Not thread-safe: the endpoint's mutex guards it.
class PtyPort {
 public:
  // Creates the pty and the link at `link_path` (empty: a private temp directory).
  Status Open(const std::string& link_path);
  // Closes the pty and removes the link.
  void Close();
  void Unplug();
  // Best effort: a new pty and the link at it; the port stays away if either fails.
  void Replug();

  bool is_open() const { return pty_.is_open(); }
  int master_fd() const { return pty_.master_fd(); }
  const std::string& path() const { return link_.path(); }
  const std::string& slave_path() const { return pty_.slave_path(); }

 private:
  Pr650Pty pty_;
  Pr650PtyLink link_;
};

}  // namespace brdf::sim
