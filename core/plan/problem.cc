#include "core/plan/problem.h"

#include <utility>

namespace brdf::plan {

std::string FormatProblems(std::span<const Problem> problems) {
  std::string out;
  for (const Problem& p : problems) {
    if (!out.empty()) out += "\n";
    out += (p.field_path.empty() ? std::string("plan") : p.field_path) + ": " + p.message;
  }
  return out;
}

void ProblemSink::Add(std::string field_path, std::string message) {
  problems_.push_back({std::move(field_path), std::move(message)});
}

void ProblemSink::AddOnce(const std::string& field_path, std::string message) {
  if (once_.count(field_path) != 0) {
    ++suppressed_[field_path];
    return;
  }
  once_[field_path] = problems_.size();
  problems_.push_back({field_path, std::move(message)});
}

std::vector<Problem> ProblemSink::Take() {
  for (const auto& [path, count] : suppressed_) {
    problems_[once_[path]].message += " (and " + std::to_string(count) + " more like it)";
  }
  suppressed_.clear();
  once_.clear();
  return std::exchange(problems_, {});
}

}  // namespace brdf::plan
