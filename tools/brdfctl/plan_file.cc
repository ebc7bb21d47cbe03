#include "tools/brdfctl/plan_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include "core/plan/plan_json.h"

namespace brdf::ctl {

Result<v1::Plan> ReadPlanFile(const std::string& path) {
  std::ostringstream text;
  if (path == "-") {
    text << std::cin.rdbuf();
  } else {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      return NotFound("plan file " + path + ": cannot open (" + std::strerror(errno) +
                      "); give the path of a plan JSON file, e.g. examples/plans/demo.json");
    }
    text << in.rdbuf();
  }
  Result<v1::Plan> plan = plan::ParsePlanJson(text.str());
  if (!plan.ok()) {
    return InvalidArgument((path == "-" ? std::string("<stdin>") : path) + ": " +
                           plan.status().message());
  }
  return plan;
}

}  // namespace brdf::ctl
