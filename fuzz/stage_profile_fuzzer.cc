// Fuzz target: a stage register profile file (drivers/stage/profile_file.h: ParseProfileText), the
// TOML a lab writes and names in [stage] profile_file.
//
// Promises checked: a refused file is kConfigurationError whose message names the file; an
// accepted profile passes ValidateProfile, its block constants are sorted by address, its
// operation block fits one FC16, and its ramp is finite and positive per unit.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "drivers/stage/profile_file.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {

int FuzzStageProfile(const std::uint8_t* data, std::size_t size) {
  using namespace brdf::drivers::stage;
  const std::string_view text = AsText(data, size);
  const Result<RegisterProfile> r = ParseProfileText(text, "fuzz.toml");
  if (!r.ok()) {
    BRDF_FUZZ_CHECK(r.status().code() == StatusCode::kConfigurationError,
                    "refusal is not kConfigurationError: " + r.status().ToString());
    BRDF_FUZZ_CHECK(r.status().message().find("fuzz.toml") != std::string::npos,
                    "refusal does not name the file: " + r.status().message());
    return 0;
  }
  const RegisterProfile& p = *r;
  BRDF_FUZZ_CHECK(ValidateProfile(p).ok(), "accepted profile fails ValidateProfile");
  for (std::size_t i = 1; i < p.block_constants.size(); ++i) {
    BRDF_FUZZ_CHECK(p.block_constants[i - 1].field.address <= p.block_constants[i].field.address,
                    "block constants not sorted by address");
  }
  const BlockSpan span = OperationBlockSpan(p);
  BRDF_FUZZ_CHECK(span.count >= 1 && span.count <= 123, "operation block does not fit one FC16");
  BRDF_FUZZ_CHECK(std::isfinite(p.ramp.per_unit) && p.ramp.per_unit > 0, "ramp per_unit unusable");
  BRDF_FUZZ_CHECK(std::isfinite(p.ramp.acceleration) && p.ramp.acceleration >= 0,
                  "ramp acceleration unusable");
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzStageProfile)
