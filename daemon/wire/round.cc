#include "daemon/wire/round.h"

#include <cstdint>

#include "core/geometry.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {

v1::AdaptiveRound ToProtoRound(const storage::ArchivedRound& round) {
  const storage::RoundRecord& r = round.record;
  v1::AdaptiveRound out;
  out.set_round(static_cast<std::uint32_t>(r.round));
  for (const storage::RoundPick& p : r.picks) {
    *out.add_poses() = ToProtoPose(p.pose);
    out.add_pose_gains(p.predicted_gain);
    const Directions d = PoseToDirections(p.pose);  // a pick's pose is in model angles
    v1::Directions* to = out.add_directions();
    to->set_theta_i(d.theta_i);
    to->set_phi_i(d.phi_i);
    to->set_theta_o(d.theta_o);
    to->set_phi_o(d.phi_o);
  }
  out.set_predicted_gain(r.predicted_gain);
  out.set_uncertainty_left(r.uncertainty_left);
  out.set_readings_used(static_cast<std::uint32_t>(r.readings_used));
  out.set_first_step(static_cast<std::uint32_t>(r.first_step));
  out.set_step_count(static_cast<std::uint32_t>(r.step_count));
  out.set_spent_rig_s(round.spent_rig_s);
  out.set_spent_prompts(static_cast<std::uint32_t>(round.spent_prompts));
  out.set_rig_s(round.rig_s);
  out.set_prompts(static_cast<std::uint32_t>(round.prompts));
  return out;
}

}  // namespace brdf::daemon
