#include "storage/session_readings.h"

#include <cmath>
#include <memory>

#include "core/plan/plan_json.h"
#include "core/plan/sample.h"
#include "core/uncertainty/loaded_budget.h"

namespace brdf::storage {
namespace {

// √(Σ uⱼ²) per band over the components that are not the BRDF's scale (docs/uncertainty.md: for
// the reflectance drop the white standard and the reference's cosine).
std::vector<double> RatioPartOf(const uncertainty::ReadingBudget& budget) {
  std::vector<double> sum(budget.combined.size(), 0.0);
  for (const uncertainty::Component& c : budget.components) {
    if (c.name == "white_standard" || c.name == "reference_pose") continue;
    for (std::size_t b = 0; b < sum.size() && b < c.contribution.size(); ++b) {
      sum[b] += c.contribution[b] * c.contribution[b];
    }
  }
  for (double& v : sum) v = std::sqrt(v);
  return sum;
}

}  // namespace

Reading ToReading(const ReadingRecord& r, uncertainty::BlendBudgetMaker* budgets) {
  Reading out;
  out.id = r.id;
  out.kind = r.kind;
  out.pose = r.pose;
  out.directions = r.directions;
  out.spectrum = Spectrum{r.grid, r.spectrum};
  out.quality_code = r.quality_code;
  out.flagged = r.flagged;
  out.integration_ms = r.integration_ms;
  out.integration_note = IntegrationNoteOf(r.note);
  out.reference_id = r.reference_reading_id;
  out.dark_id = r.dark_reading_id;
  if (r.uncertainty.has_value()) {
    out.brdf_u = r.uncertainty->combined;
    out.brdf_u_of_ratio = RatioPartOf(*r.uncertainty);
    if (budgets != nullptr && r.uncertainty->quantity == Quantity::kBrdf) {
      out.budget = std::make_shared<const uncertainty::LoadedBudget>(
          uncertainty::LoadBudget(*r.uncertainty, *budgets));
    }
  }
  return out;
}

namespace {

// The session's record as a SessionReadings without readings.
Result<SessionReadings> LoadSessionRecord(SessionReader& reader, std::int64_t session_id) {
  Result<SessionRecord> record = reader.GetSession(session_id);
  if (!record.ok()) {
    if (record.status().code() == StatusCode::kNotFound) {
      return NotFound("unknown session " + std::to_string(session_id) +
                      ": list the sessions with `brdfctl list`");
    }
    return record.status();
  }
  SessionReadings session;
  session.id = record->id;
  session.name = record->name;
  session.white_reflectance = record->white_reflectance;
  if (Result<v1::Plan> plan = plan::ParsePlanJson(record->plan_json); plan.ok()) {
    session.white_reflectance_spectrum = plan::WhiteReflectanceSpectrumOf(*plan);
  } else {
    return Internal("session " + std::to_string(session_id) +
                    ": its stored plan does not parse: " + plan.status().message());
  }
  return session;
}

// Readings asked of a SessionReader per page.
constexpr int kReadingsPerPage = 4096;

}  // namespace

Result<SessionReadings> LoadSessionReadings(SessionReader& reader, std::int64_t session_id) {
  BRDF_ASSIGN_OR_RETURN(SessionReadings session, LoadSessionRecord(reader, session_id));
  uncertainty::BlendBudgetMaker budgets;  // one list: the session's budgets blend together
  for (std::int64_t after = 0;;) {
    BRDF_ASSIGN_OR_RETURN(std::vector<ReadingRecord> page,
                          reader.GetReadings(session_id, after, kReadingsPerPage));
    for (const ReadingRecord& r : page) session.readings.push_back(ToReading(r, &budgets));
    if (page.size() < static_cast<std::size_t>(kReadingsPerPage)) break;
    after = page.back().id;
  }
  return session;
}

}  // namespace brdf::storage
