// A problem with a plan, named by the JSON path of the field it is about, so that an operator
// can find it in the plan file and a client can highlight it in a form. Validation collects
// every problem at once rather than stopping at the first.
//
// Paths use the proto JSON mapping's lowerCamelCase names with indexes:
// "sampleRotation.alpha.step", "sampleFixed.targets[3].thetaI", "poseList.poses[0].delta",
// "reference.everyMinutes". "method" names the method oneof (no method set); "" the plan as a whole
// (too many steps).
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace brdf::plan {

struct Problem {
  std::string field_path;
  std::string message;  // what is wrong and what to do
  friend bool operator==(const Problem&, const Problem&) = default;
};

// "sampleRotation.alpha.step: step must be > 0 (got -10); …" — one line per problem.
std::string FormatProblems(std::span<const Problem> problems);

// Collects problems. Add keeps every problem; AddOnce keeps the first problem per path and
// counts the others (a grid with 300 poses beyond a limit gives one problem, "… (and 299 more)").
class ProblemSink {
 public:
  void Add(std::string field_path, std::string message);
  void AddOnce(const std::string& field_path, std::string message);
  bool empty() const { return problems_.empty(); }
  // The problems in the order they were first added.
  std::vector<Problem> Take();

 private:
  std::vector<Problem> problems_;
  std::map<std::string, std::size_t> once_;        // path → index in problems_
  std::map<std::string, std::size_t> suppressed_;  // path → repeats not kept
};

}  // namespace brdf::plan
