#include "daemon/wire/values.h"

#include <google/protobuf/util/time_util.h>

#include <cmath>
#include <cstdint>

namespace brdf::daemon {

google::protobuf::Timestamp ToTimestamp(storage::UnixSeconds seconds) {
  const double whole = std::floor(seconds);
  google::protobuf::Timestamp t;
  t.set_seconds(static_cast<std::int64_t>(whole));
  t.set_nanos(static_cast<std::int32_t>(std::lround((seconds - whole) * 1e9) % 1000000000));
  return t;
}

google::protobuf::Timestamp ToTimestamp(std::chrono::system_clock::time_point at) {
  return google::protobuf::util::TimeUtil::NanosecondsToTimestamp(
      std::chrono::duration_cast<std::chrono::nanoseconds>(at.time_since_epoch()).count());
}

google::protobuf::Timestamp NowTimestamp() {
  return ToTimestamp(std::chrono::system_clock::now());
}

double ToUnixSeconds(const google::protobuf::Timestamp& at) {
  return static_cast<double>(at.seconds()) + at.nanos() * 1e-9;
}

v1::Pose ToProtoPose(const Pose& pose) {
  v1::Pose p;
  p.set_alpha(pose.alpha);
  p.set_beta(pose.beta);
  p.set_gamma(pose.gamma);
  p.set_delta(pose.delta);
  return p;
}

v1::Directions ToProtoDirections(const Directions& d) {
  v1::Directions p;
  p.set_theta_i(d.theta_i);
  p.set_phi_i(d.phi_i);
  p.set_theta_o(d.theta_o);
  p.set_phi_o(d.phi_o);
  return p;
}

v1::IsoDirection ToProtoIso(const IsoDirection& iso) {
  v1::IsoDirection p;
  p.set_theta_i(iso.theta_i);
  p.set_theta_o(iso.theta_o);
  p.set_phi(iso.phi);
  return p;
}

v1::WavelengthGrid ToProtoGrid(const WavelengthGrid& grid) {
  v1::WavelengthGrid g;
  g.set_start_nm(grid.start_nm);
  g.set_step_nm(grid.step_nm);
  g.set_count(static_cast<std::uint32_t>(grid.count));
  return g;
}

}  // namespace brdf::daemon
