// Shared by the storage tests: a scratch directory with real SQLite files, and plans and readings
// whose content is a known function of the step, so any mix-up shows.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "storage/records.h"
#include "storage/session_store.h"

namespace brdf::storage::testing {

// A fresh directory under $TMPDIR (or /tmp), removed with everything in it afterwards.
class TempDir {
 public:
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string tmpl = std::string(base != nullptr ? base : "/tmp") + "/brdf-storage-XXXXXX";
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    const char* made = mkdtemp(buf.data());
    EXPECT_NE(made, nullptr) << "mkdtemp " << tmpl;
    path_ = made != nullptr ? made : "/tmp";
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// Step i's kind in the standard test plan: a move every 10th step, a reference at 1, 11, 21, …,
// samples otherwise.
inline StepKind KindOfStep(int i) {
  if (i % 10 == 0) return StepKind::kMove;
  if (i % 10 == 1) return StepKind::kReference;
  return StepKind::kSample;
}

inline Pose PoseOfStep(int i) {
  return Pose{i * 0.5, -i * 0.25, 0, i % 14 * 11.25};
}

inline std::vector<StepRecord> MakeSteps(int n, std::function<StepKind(int)> kind = KindOfStep) {
  std::vector<StepRecord> steps(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    StepRecord& s = steps[static_cast<std::size_t>(i)];
    s.step_index = i;
    s.kind = kind(i);
    s.pose = PoseOfStep(i);
    s.label = "step " + std::to_string(i);
    if (s.kind != StepKind::kMove && s.kind != StepKind::kPrompt) {
      s.target = Directions{i * 0.1, 0, 45, 180};
    }
  }
  return steps;
}

inline NewSession MakeNewSession(const std::string& name = "paint sample") {
  NewSession s;
  s.name = name;
  s.plan_kind = "sample_rotation";
  s.plan_json = R"({"kind":"sample_rotation","delta_step":11.25})";
  s.created_by_role = "operator";
  s.white_reflectance = 0.99;
  s.meter_serial = "60954201";
  s.config_json = R"({"rig":"bench"})";
  return s;
}

// Value of band `b` of the reading of step `step`: distinct per step and band.
inline double SpectrumValue(int step, std::size_t b) {
  return 1e-3 * (step + 1) + std::sin(0.1 * static_cast<double>(b)) * 1e-5;
}

inline ReadingRecord MakeReading(int step, ReadingKind kind,
                                 WavelengthGrid grid = WavelengthGrid::Pr650()) {
  ReadingRecord r;
  r.kind = kind;
  r.pose = PoseOfStep(step);
  r.directions = Directions{step * 0.1, 0, 45, 180};
  r.grid = grid;
  r.spectrum.resize(grid.count);
  for (std::size_t b = 0; b < grid.count; ++b) r.spectrum[b] = SpectrumValue(step, b);
  r.quality_code = step % 3 == 0 ? 18 : 0;
  r.flagged = step % 3 == 0;
  r.integration_ms = 250;
  r.attempts = 1 + step % 2;
  r.note = step % 3 == 0 ? "low light, flagged" : "";
  r.meter_serial = "60954201";
  return r;
}

// An uncertainty budget for the sample reading of step `step`: distinct per step and band, one
// independent and one shared component (through reference `reference`), one term not estimated.
inline uncertainty::ReadingBudget MakeBudget(int step, const WavelengthGrid& grid,
                                             std::int64_t reference) {
  uncertainty::ReadingBudget b;
  b.quantity = step % 4 == 0 ? Quantity::kBrdf : Quantity::kReflectance;
  std::vector<double> own(grid.count), shared(grid.count);
  for (std::size_t i = 0; i < grid.count; ++i) {
    own[i] = 1e-4 * (step + 1) + 1e-7 * static_cast<double>(i);
    shared[i] = -2e-5 * (step + 1);
  }
  b.components = {
      {"sample_signal", {}, own},
      {"reference_signal", {uncertainty::Sharing::kReferenceReading, reference}, shared}};
  for (std::size_t i = 0; i < grid.count; ++i) {
    b.combined.push_back(std::hypot(own[i], shared[i]));
    b.independent.push_back(own[i]);
  }
  b.not_estimated = {"pose: the quantity's gradient over the pose is not known"};
  for (std::size_t i = 0; i < grid.count; ++i) b.value.push_back(0.01 * step + 1e-4 * i);
  return b;
}

// The reading kind that step i of the standard plan produces (kSample for moves: unused).
inline ReadingKind ReadingKindOfStep(int i) {
  return ReadingKindFor(KindOfStep(i)).value_or(ReadingKind::kSample);
}

// Runs `body` in a forked child that is not root (drops to nobody when the tests run as root, as
// in CI containers, where file permissions would otherwise not apply). Returns what the child
// wrote to `out` and its exit code.
struct ChildResult {
  int exit_code = -1;
  std::string output;
};
inline ChildResult RunUnprivileged(const std::function<int(std::string& out)>& body) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    int code = 0;
    std::string out;
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) {
      out = "could not drop privileges";
      code = 99;
    } else {
      code = body(out);
    }
    std::size_t off = 0;
    while (off < out.size()) {
      const ssize_t n = write(fds[1], out.data() + off, out.size() - off);
      if (n <= 0) break;
      off += static_cast<std::size_t>(n);
    }
    close(fds[1]);
    _exit(code);
  }
  close(fds[1]);
  ChildResult result;
  char buf[4096];
  ssize_t n;
  while ((n = read(fds[0], buf, sizeof buf)) > 0)
    result.output.append(buf, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace brdf::storage::testing
