#include "daemon/index/samples.h"

#include <utility>
#include <vector>

#include "core/geometry.h"
#include "storage/session_readings.h"

namespace brdf::daemon {

IndexSamples::IndexSamples(bool anisotropic, double white_reflectance,
                           std::optional<Spectrum> white_spectrum)
    : anisotropic_(anisotropic), deriver_(white_reflectance, std::move(white_spectrum)) {}

bool IndexSamples::Fold(const storage::ReadingRecord& record) {
  if (record.id <= working_.through_id) return false;
  working_.through_id = record.id;
  if (!first_grid_.has_value()) first_grid_ = record.grid;
  std::optional<SampleQuantities> derived = deriver_.Fold(storage::ToReading(record));
  if (!derived.has_value()) return true;  // a reference or a dark: kept for the samples after it
  const Directions& d = record.directions;
  std::vector<double> coords;
  if (anisotropic_) {
    coords = {d.theta_i, d.phi_i, d.theta_o, d.phi_o};
  } else {
    const IsoDirection iso = ToIsotropic(d);
    coords = {iso.theta_i, iso.theta_o, iso.phi};
  }
  for (int i = 0; i < kQuantityCount; ++i) {
    const Quantity q = static_cast<Quantity>(i);
    if (derived->has(q)) {
      Add(q, record, coords, derived->of(q));
    } else {
      Skip(q, derived->reason(q));
    }
  }
  return true;
}

void IndexSamples::Add(Quantity q, const storage::ReadingRecord& record,
                       std::span<const double> coords, const std::vector<double>& values) {
  const std::int64_t id = record.id;
  const int i = static_cast<int>(q);
  std::shared_ptr<interp::SampleSet>& set = grown_[i];
  if (!set) {
    const std::shared_ptr<const interp::SampleSet>& old = published_.sets[i];
    set = old ? std::make_shared<interp::SampleSet>(*old)
              : std::make_shared<interp::SampleSet>(dims(), static_cast<int>(values.size()));
    working_.sets[i] = set;
  }
  if (Status st = set->Add(id, coords, values); !st.ok()) {
    Skip(q, "reading " + std::to_string(id) + ": " + st.message());
    return;
  }
  if (q == Quantity::kBrdf) {
    // Only a budget of the BRDF blends with the BRDF; any other counts as not estimated. Kept
    // as the blend needs it (budgets.h: the whole budgets would be most of the session's memory).
    const bool of_brdf =
        record.uncertainty.has_value() && record.uncertainty->quantity == Quantity::kBrdf;
    working_.brdf_budgets.Add(of_brdf ? &*record.uncertainty : nullptr);
  }
}

void IndexSamples::Skip(Quantity q, const std::string& why) {
  const int i = static_cast<int>(q);
  if (working_.skipped[i]++ == 0) working_.skipped_detail[i] = why;
}

bool IndexSamples::Publish() {
  bool grew = false;
  for (std::shared_ptr<interp::SampleSet>& set : grown_) {
    if (set) grew = true;
    set.reset();
  }
  published_ = working_;
  return grew;
}

}  // namespace brdf::daemon
