// Fuzz target: brdfd's configuration file (daemon/config/config.h: ParseConfig), then what the
// daemon derives from it (ToRigDescription) and a small plan analysed against that rig, so that any
// configuration the parser accepts is one the rest of the daemon can use.
//
// Promises checked: a refused file is kConfigurationError with a message; an accepted one keeps
// the documented ranges (unit ids 1–247 and distinct, travel min < max, positive speeds,
// tokens of at least kMinTokenLength, ρw in (0, 1], standard baud rates) and yields a rig whose
// numbers are finite and positive where they must be.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>

#include "core/plan/analyze_plan.h"
#include "core/plan/plan_json.h"
#include "daemon/config/config.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {
namespace {

using namespace brdf::daemon;

constexpr std::string_view kDemoPlan = R"({
  "name": "fuzz",
  "sampleRotation": {
    "delta": { "start": 0, "stop": 45, "step": 22.5 },
    "alpha": { "start": 0, "stop": 40, "step": 20 },
    "beta": { "step": 45 }
  },
  "reference": { "perDetectorPosition": true },
  "measurement": { "integrationMs": 0, "averages": 1 }
})";

void CheckAxis(const char* name, const AxisSettings& a) {
  const std::string where = std::string("stage.axes.") + name;
  BRDF_FUZZ_CHECK(a.unit_id >= 1 && a.unit_id <= 247, where + ".unit_id out of 1-247");
  BRDF_FUZZ_CHECK(std::isfinite(a.min_deg) && std::isfinite(a.max_deg) && a.min_deg < a.max_deg,
                  where + ": empty or non-finite travel accepted");
  BRDF_FUZZ_CHECK(std::isfinite(a.speed_deg_s) && a.speed_deg_s > 0, where + ": bad speed");
  BRDF_FUZZ_CHECK(std::isfinite(a.counts_per_degree) && a.counts_per_degree > 0,
                  where + ": bad counts_per_degree");
  BRDF_FUZZ_CHECK(a.sign == 1 || a.sign == -1, where + ": sign is neither 1 nor -1");
  BRDF_FUZZ_CHECK(std::isfinite(a.zero_offset_deg), where + ": non-finite zero offset");
}

void CheckTravel(const char* name, const plan::AxisTravel& t) {
  BRDF_FUZZ_CHECK(t.min_deg < t.max_deg && t.speed_deg_s > 0 && std::isfinite(t.speed_deg_s),
                  std::string("rig travel of ") + name + " unusable");
}

}  // namespace

int FuzzConfig(const std::uint8_t* data, std::size_t size) {
  const Result<Config> config = ParseConfig(AsText(data, size), "fuzz.toml");
  if (!config.ok()) {
    BRDF_FUZZ_CHECK(config.status().code() == StatusCode::kConfigurationError,
                    "refused with the wrong code: " + config.status().ToString());
    BRDF_FUZZ_CHECK(!config.status().message().empty(), "refused without a message");
    return 0;
  }

  const Config& c = *config;
  const StageConfig& s = c.stage;
  std::set<int> units;
  for (const auto& [name, axis] : {std::pair{"alpha", &s.alpha}, std::pair{"beta", &s.beta},
                                   std::pair{"gamma", &s.gamma}, std::pair{"delta", &s.delta}}) {
    CheckAxis(name, *axis);
    if (axis->present) {
      BRDF_FUZZ_CHECK(units.insert(axis->unit_id).second,
                      std::string("two axes share unit id ") + std::to_string(axis->unit_id));
    }
  }
  BRDF_FUZZ_CHECK(s.parity == 'N' || s.parity == 'E' || s.parity == 'O', "bad parity accepted");
  BRDF_FUZZ_CHECK(s.transport == "tcp" || s.transport == "rtu", "bad transport accepted");
  BRDF_FUZZ_CHECK(s.transport != "rtu" || !s.device.empty(), "rtu without a device accepted");
  BRDF_FUZZ_CHECK(c.meter.baud > 0, "meter baud rate not positive");
  BRDF_FUZZ_CHECK(c.sample.white_reflectance > 0 && c.sample.white_reflectance <= 1,
                  "white reflectance outside (0, 1]");
  std::set<std::string> secrets;
  for (const TokenConfig& t : c.tokens) {
    BRDF_FUZZ_CHECK(t.token.size() >= kMinTokenLength, "a short token accepted");
    BRDF_FUZZ_CHECK(secrets.insert(t.token).second, "two tokens share a secret");
  }
  for (const auto& [code, rule] : c.meter.quality_overrides) {
    BRDF_FUZZ_CHECK(code >= 0 && code <= 99, "quality override for code outside 0-99");
  }

  const plan::RigDescription rig = ToRigDescription(c);
  CheckTravel("alpha", rig.alpha);
  CheckTravel("beta", rig.beta);
  CheckTravel("gamma", rig.gamma);
  CheckTravel("delta", rig.delta);
  BRDF_FUZZ_CHECK(std::isfinite(rig.meter_transfer_s) && rig.meter_transfer_s > 0,
                  "meter transfer time unusable");
  BRDF_FUZZ_CHECK(std::isfinite(rig.reading_overhead_s) && rig.reading_overhead_s > 0,
                  "reading overhead unusable");

  static const v1::Plan demo = [] {
    Result<v1::Plan> p = plan::ParsePlanJson(kDemoPlan);
    BRDF_FUZZ_CHECK(p.ok(), "the embedded demo plan does not parse: " + p.status().ToString());
    return *p;
  }();
  const plan::PlanAnalysis a = plan::AnalyzePlan(demo, rig);
  BRDF_FUZZ_CHECK(std::isfinite(a.summary.estimated_duration_s),
                  "a plan on an accepted rig has a non-finite duration");
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzConfig)
