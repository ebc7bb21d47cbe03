// What every harness in fuzz/ shares: an invariant check that turns a broken promise into a crash
// libFuzzer records (so the fuzzers find wrong answers, not only memory errors), and the entry
// point macro.
//
// Each harness defines `int brdf::fuzz::Fuzz<Target>(const std::uint8_t*, std::size_t)` and then
// BRDF_FUZZ_ENTRY(that function). In the fuzz build that becomes libFuzzer's
// LLVMFuzzerTestOneInput; tests/fuzz_regressions compiles the same harnesses with
// BRDF_FUZZ_NO_ENTRY defined and replays the checked-in corpus through them with the normal
// compiler, so every input that once crashed stays exercised in every build.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace brdf::fuzz {

// Prints what broke and where, then aborts (libFuzzer saves the input as crash-<sha1>).
[[noreturn]] inline void InvariantFailed(const char* expr, const char* file, int line,
                                         const std::string& detail) {
  std::fprintf(stderr, "fuzz invariant failed at %s:%d: %s\n  %s\n", file, line, expr,
               detail.c_str());
  std::fflush(stderr);
  std::abort();
}

inline std::string_view AsText(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Reads fuzzer-chosen values off the front of the input; past the end it yields zeros, so a
// harness never needs to check the length first.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t Byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t U16() {
    const std::uint16_t hi = Byte();
    return static_cast<std::uint16_t>((hi << 8) | Byte());
  }
  std::uint32_t U32() {
    const std::uint32_t hi = U16();
    return (hi << 16) | U16();
  }
  // Up to `n` bytes (fewer at the end of the input).
  std::string_view Take(std::size_t n) {
    const std::size_t k = n < size_ - pos_ ? n : size_ - pos_;
    std::string_view out(reinterpret_cast<const char*>(data_) + pos_, k);
    pos_ += k;
    return out;
  }
  std::string_view Rest() { return Take(size_ - pos_); }
  bool empty() const { return pos_ >= size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace brdf::fuzz

#define BRDF_FUZZ_CHECK(cond, detail)                                                \
  do {                                                                               \
    if (!(cond)) ::brdf::fuzz::InvariantFailed(#cond, __FILE__, __LINE__, (detail)); \
  } while (false)

#ifdef BRDF_FUZZ_NO_ENTRY
#define BRDF_FUZZ_ENTRY(fn)
#else
#define BRDF_FUZZ_ENTRY(fn)                                                           \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    return fn(data, size);                                                            \
  }
#endif
