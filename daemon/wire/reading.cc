#include "daemon/wire/reading.h"

#include <algorithm>
#include <cmath>

#include "core/geometry.h"
#include "core/readings/reading.h"
#include "daemon/wire/enums.h"
#include "daemon/wire/values.h"

namespace brdf::daemon {
namespace {

double MicroDegrees(double degrees) {
  return std::round(degrees * 1e6) / 1e6;
}

v1::UncertaintySharing ToProtoSharing(uncertainty::Sharing sharing) {
  switch (sharing) {
    case uncertainty::Sharing::kIndependent:
      return v1::UNCERTAINTY_SHARING_INDEPENDENT;
    case uncertainty::Sharing::kReferenceReading:
      return v1::UNCERTAINTY_SHARING_REFERENCE_READING;
    case uncertainty::Sharing::kDarkReading:
      return v1::UNCERTAINTY_SHARING_DARK_READING;
    case uncertainty::Sharing::kWhiteStandard:
      return v1::UNCERTAINTY_SHARING_WHITE_STANDARD;
    case uncertainty::Sharing::kInstrument:
      return v1::UNCERTAINTY_SHARING_INSTRUMENT;
  }
  return v1::UNCERTAINTY_SHARING_UNSPECIFIED;
}

bool SharedThroughAReading(uncertainty::Sharing sharing) {
  return sharing == uncertainty::Sharing::kReferenceReading ||
         sharing == uncertainty::Sharing::kDarkReading;
}

}  // namespace

v1::ReadingUncertainty ToProtoUncertainty(const uncertainty::ReadingBudget& budget) {
  v1::ReadingUncertainty out;
  out.set_quantity(ToProtoQuantity(budget.quantity));
  out.mutable_value()->Add(budget.value.begin(), budget.value.end());
  out.mutable_combined()->Add(budget.combined.begin(), budget.combined.end());
  out.mutable_independent()->Add(budget.independent.begin(), budget.independent.end());
  for (const uncertainty::Component& c : budget.components) {
    v1::UncertaintyComponent* p = out.add_components();
    p->set_name(c.name);
    p->set_sharing(ToProtoSharing(c.shared.kind));
    if (SharedThroughAReading(c.shared.kind)) p->set_shared_id(c.shared.id);
    p->mutable_contribution()->Add(c.contribution.begin(), c.contribution.end());
  }
  for (const std::string& why : budget.not_estimated) out.add_not_estimated(why);
  return out;
}

v1::Reading ToProtoReading(const storage::ReadingRecord& r, const ReadingExtras& extras) {
  v1::Reading out;
  out.set_id(r.id);
  out.set_session_id(std::to_string(r.session_id));
  out.set_step_index(r.step_index);
  out.set_kind(ToProtoReadingKind(r.kind));
  *out.mutable_pose() = ToProtoPose(r.pose);
  *out.mutable_directions() = ToProtoDirections(r.directions);
  *out.mutable_iso() = ToProtoIso(ToIsotropic(r.directions));
  *out.mutable_grid() = ToProtoGrid(r.grid);
  out.mutable_radiance()->Add(r.spectrum.begin(), r.spectrum.end());
  out.set_quality_code(r.quality_code);
  out.set_flagged(r.flagged);
  if (r.flagged) out.set_flag_reason(r.note.empty() ? "flagged by the quality policy" : r.note);
  out.set_integration_ms(static_cast<std::uint32_t>(std::max(0, r.integration_ms)));
  out.set_integration_note(IntegrationNoteOf(r.note));
  out.set_averages(extras.averages);
  out.set_reference_id(r.reference_reading_id.value_or(0));
  out.set_dark_id(r.dark_reading_id.value_or(0));
  out.set_attempts(static_cast<std::uint32_t>(std::max(1, r.attempts)));
  *out.mutable_taken_at() = ToTimestamp(r.recorded_at);
  auto label = extras.step_labels.find(r.step_index);
  if (label != extras.step_labels.end()) out.set_label(label->second);
  if (r.uncertainty.has_value()) *out.mutable_uncertainty() = ToProtoUncertainty(*r.uncertainty);
  return out;
}

void AddReadingPoint(const storage::ReadingPointRecord& r, v1::ReadingPoints* points) {
  points->add_ids(r.id);
  points->add_alpha(MicroDegrees(r.pose.alpha));
  points->add_beta(MicroDegrees(r.pose.beta));
  points->add_delta(MicroDegrees(r.pose.delta));
  const IsoDirection iso = ToIsotropic(r.directions);
  points->add_theta_i(MicroDegrees(iso.theta_i));
  points->add_theta_o(MicroDegrees(iso.theta_o));
  points->add_phi(MicroDegrees(iso.phi));
  points->add_flagged(r.flagged);
}

}  // namespace brdf::daemon
