// The shipped profile files (deploy/stage-profiles/*.toml), embedded at build time: CMake writes
// builtin_profiles.cc into the build tree from the files, so the files are the only source of
// the built-in register maps.
#pragma once

#include <span>
#include <string_view>

namespace brdf::drivers::stage {

struct BuiltinProfileFile {
  std::string_view name;  // file name without .toml
  std::string_view text;
};

// In file-name order.
std::span<const BuiltinProfileFile> BuiltinProfileFiles();

}  // namespace brdf::drivers::stage
