#include "drivers/cs2000/options.h"

namespace brdf::drivers {

Status ValidateCs2000Options(const Cs2000Options& o) {
  BRDF_RETURN_IF_ERROR(ValidateLineMeterOptions(o, "CS-2000", "/dev/ttyUSB0"));
  auto bad = [](const std::string& what) { return LineMeterOptionError("CS-2000", what); };
  if (!(o.sync_frequency_hz >= 20 && o.sync_frequency_hz <= 200)) {
    return bad("sync_frequency_hz must be 20–200 Hz");
  }
  if (!InRangeMs(o.measure_start_timeout, 1, 120'000)) {
    return bad("measure_start_timeout must be 1–120000 ms");
  }
  return Status::Ok();
}

}  // namespace brdf::drivers
