// Where an export goes. A file is written as PATH.partial and renamed to PATH only when the export
// finished: a failed, cancelled or interrupted export never leaves a truncated file under the
// name a user or a script will open. "-" is standard output (text exports).
#pragma once

#include <fstream>
#include <memory>
#include <ostream>
#include <string>

#include "core/status.h"

namespace brdf::export_tool {

class OutputFile {
 public:
  // kIoError naming the path when it cannot be created.
  static Result<std::unique_ptr<OutputFile>> Open(const std::string& path);
  ~OutputFile();  // removes PATH.partial unless committed
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  std::ostream& stream();
  const std::string& path() const { return path_; }
  // Flushes, closes and renames into place. kIoError when any of it fails.
  Status Commit();

 private:
  explicit OutputFile(std::string path) : path_(std::move(path)) {}
  std::string path_;
  std::string partial_;
  std::ofstream file_;
  bool to_stdout_ = false;
  bool committed_ = false;
};

}  // namespace brdf::export_tool
