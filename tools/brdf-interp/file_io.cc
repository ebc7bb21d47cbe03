#include "tools/brdf-interp/file_io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

namespace brdf::interp_tool {

Result<std::string> ReadFile(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    return InvalidArgument("cannot open " + path + ": " + std::strerror(errno));
  }
  std::string text;
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed) return IoError("cannot read " + path + ": " + std::strerror(err));
  return text;
}

Result<OutputFile> OutputFile::Open(const std::string& path) {
  OutputFile out;
  if (path.empty() || path == "-") {
    out.file_ = stdout;
    out.name_ = "standard output";
    return out;
  }
  out.path_ = path;
  out.tmp_path_ = path + ".tmp";
  out.name_ = path;
  out.file_ = std::fopen(out.tmp_path_.c_str(), "wb");
  if (out.file_ == nullptr) {
    return IoError("cannot create " + out.tmp_path_ + ": " + std::strerror(errno));
  }
  out.owned_ = true;
  return out;
}

OutputFile::OutputFile(OutputFile&& other) noexcept {
  *this = std::move(other);
}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  std::swap(file_, other.file_);
  std::swap(owned_, other.owned_);
  std::swap(path_, other.path_);
  std::swap(tmp_path_, other.tmp_path_);
  std::swap(name_, other.name_);
  return *this;
}

OutputFile::~OutputFile() {
  // Not closed: the output is incomplete, so it does not replace anything.
  if (owned_ && file_ != nullptr) {
    std::fclose(file_);
    std::remove(tmp_path_.c_str());
  }
}

Status OutputFile::Write(std::string_view text) {
  if (file_ == nullptr) return Internal("write to " + name_ + " after it was closed");
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size()) {
    return IoError("cannot write " + name_ + ": " + std::strerror(errno));
  }
  return Status::Ok();
}

Status OutputFile::Close() {
  if (file_ == nullptr) return Status::Ok();
  if (!owned_) {
    file_ = nullptr;
    if (std::fflush(stdout) != 0) return IoError("cannot write standard output");
    return Status::Ok();
  }
  const bool failed = std::fflush(file_) != 0;
  const int err = errno;
  std::fclose(file_);
  file_ = nullptr;
  if (failed) {
    std::remove(tmp_path_.c_str());
    return IoError("cannot write " + tmp_path_ + ": " + std::strerror(err));
  }
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0) {
    const int rename_err = errno;
    std::remove(tmp_path_.c_str());
    return IoError("cannot rename " + tmp_path_ + " to " + path_ + ": " +
                   std::strerror(rename_err));
  }
  return Status::Ok();
}

}  // namespace brdf::interp_tool
