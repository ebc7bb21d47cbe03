// Small helpers for tests that need the operating system: a free TCP port and a temporary
// directory that cleans up after itself.
#pragma once

#include <filesystem>
#include <string>

#include "core/status.h"

namespace brdf::testing {

// A TCP port on 127.0.0.1 that was free a moment ago (bound to port 0, then released). Another
// process may take it before the caller binds it; prefer asking a server for port 0 when it can
// tell which port it got (brdf-sim can: --modbus-port 0).
Result<int> FreeTcpPort();

// A fresh directory under $TMPDIR (or /tmp), removed with everything in it on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "brdf-test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  // Empty if the directory could not be created (see error()).
  const std::filesystem::path& path() const { return path_; }
  const std::string& error() const { return error_; }
  // path() / name
  std::filesystem::path file(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
  std::string error_;
};

}  // namespace brdf::testing
