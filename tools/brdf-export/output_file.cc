#include "tools/brdf-export/output_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>

namespace brdf::export_tool {

Result<std::unique_ptr<OutputFile>> OutputFile::Open(const std::string& path) {
  std::unique_ptr<OutputFile> f(new OutputFile(path));
  if (path == "-") {
    f->to_stdout_ = true;
    return f;
  }
  f->partial_ = path + ".partial";
  f->file_.open(f->partial_, std::ios::binary | std::ios::trunc);
  if (!f->file_) {
    return IoError("cannot create " + f->partial_ + ": " + std::strerror(errno) +
                   "; check that the directory exists and is writable");
  }
  return f;
}

OutputFile::~OutputFile() {
  if (!to_stdout_ && !committed_) {
    file_.close();
    std::remove(partial_.c_str());
  }
}

std::ostream& OutputFile::stream() {
  if (to_stdout_) return std::cout;
  return file_;
}

Status OutputFile::Commit() {
  if (to_stdout_) {
    std::cout.flush();
    if (!std::cout) return IoError("writing to standard output failed");
    return Status::Ok();
  }
  file_.flush();
  const bool written = static_cast<bool>(file_);
  file_.close();
  if (!written || file_.fail()) {
    return IoError("writing " + partial_ + " failed: is the disk full?");
  }
  if (std::rename(partial_.c_str(), path_.c_str()) != 0) {
    return IoError("cannot rename " + partial_ + " to " + path_ + ": " + std::strerror(errno));
  }
  committed_ = true;
  return Status::Ok();
}

}  // namespace brdf::export_tool
