// Whole-file reads and writes for brdf-interp. Errors name the path and the system's reason.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "core/status.h"

namespace brdf::interp_tool {

Result<std::string> ReadFile(const std::string& path);

// An output that is a file (written to "<path>.tmp" first, then renamed into place on Close) or
// standard output (path "" or "-").
class OutputFile {
 public:
  static Result<OutputFile> Open(const std::string& path);
  OutputFile(OutputFile&&) noexcept;
  OutputFile& operator=(OutputFile&&) noexcept;
  ~OutputFile();

  Status Write(std::string_view text);
  Status Close();
  const std::string& name() const { return name_; }

 private:
  OutputFile() = default;
  std::FILE* file_ = nullptr;
  bool owned_ = false;
  std::string path_;
  std::string tmp_path_;
  std::string name_;
};

}  // namespace brdf::interp_tool
