#include "core/plan/plan_json.h"

#include <google/protobuf/util/json_util.h>

#include <optional>
#include <string>

#include "core/plan/json_locator.h"

namespace brdf::plan {
namespace {

std::string Where(const std::optional<TextPosition>& at) {
  if (!at) return "plan JSON";
  return "plan JSON, line " + std::to_string(at->line) + ", column " + std::to_string(at->column);
}

// protobuf reports "(sample_rotation.alpha.step): invalid value …" or
// "(sample_rotation) alpa: Cannot find field."; rewrite it with JSON paths and a position.
Status DescribeParseError(std::string_view json, const std::string& protobuf_message) {
  const JsonLocator locator(json);
  if (locator.error()) {
    return InvalidArgument(Where(locator.error()->at) + ": " + locator.error()->message +
                           "; fix the JSON syntax");
  }
  std::string path;
  std::string rest = protobuf_message;
  if (!rest.empty() && rest.front() == '(') {
    const std::size_t close = rest.find(')');
    if (close != std::string::npos) {
      path = ToJsonPath(rest.substr(1, close - 1));
      rest = rest.substr(close + 1);
    }
  }
  while (!rest.empty() && (rest.front() == ' ' || rest.front() == ':')) rest.erase(0, 1);
  const std::string kUnknown = ": Cannot find field.";
  if (rest.size() > kUnknown.size() &&
      rest.compare(rest.size() - kUnknown.size(), kUnknown.size(), kUnknown) == 0) {
    const std::string name = rest.substr(0, rest.size() - kUnknown.size());
    const std::string parent = path;
    path = parent.empty() ? ToJsonPath(name) : parent + "." + ToJsonPath(name);
    return InvalidArgument(Where(locator.Find(path)) + " (" + path + "): unknown field \"" + name +
                           "\" in " + (parent.empty() ? std::string("the plan") : parent) +
                           "; check the spelling against proto/brdf/v1/plan.proto");
  }
  const std::optional<TextPosition> at = path.empty() ? std::nullopt : locator.Find(path);
  return InvalidArgument(Where(at) + (path.empty() ? "" : " (" + path + ")") + ": " + rest +
                         "; fix the value's type or spelling");
}

}  // namespace

Result<v1::Plan> ParsePlanJson(std::string_view json) {
  if (json.size() > kMaxPlanJsonBytes) {
    return InvalidArgument("plan JSON is " + std::to_string(json.size()) +
                           " bytes, more than the cap of " + std::to_string(kMaxPlanJsonBytes) +
                           "; split the plan");
  }
  v1::Plan plan;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto status =
      google::protobuf::util::JsonStringToMessage(std::string(json), &plan, options);
  if (!status.ok()) return DescribeParseError(json, std::string(status.message()));
  return plan;
}

Result<std::string> PlanToJson(const v1::Plan& plan) {
  std::string out;
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  const auto status = google::protobuf::util::MessageToJsonString(plan, &out, options);
  if (!status.ok()) {
    return Internal("printing a plan as JSON failed: " + std::string(status.message()));
  }
  return out;
}

}  // namespace brdf::plan
