#include "daemon/api/export_bird.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/export/bird/metadata.h"
#include "core/export/bird/writer.h"
#include "core/plan/plan_json.h"

#ifndef BRDFD_VERSION
#define BRDFD_VERSION ""
#endif

namespace brdf::daemon {
namespace {

// Readings read per page while collecting the budgets (each page holds their spectra and every
// component of their budgets; only u_c is kept).
constexpr int kBudgetPage = 256;

// u_c per derived sample (empty: no budget), and u(ρw) as the first budget's white-standard
// component gives it: |u_white / f| · ρw, the median over bands.
struct StoredUncertainty {
  std::vector<std::vector<double>> combined;
  std::optional<double> white_u;
};

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

std::optional<double> WhiteUncertaintyOf(const uncertainty::ReadingBudget& budget,
                                         const exports::DerivedSample& sample, double rho_w) {
  const uncertainty::Component* white = budget.Find("white_standard");
  if (white == nullptr || white->contribution.size() != sample.values.size()) return std::nullopt;
  std::vector<double> relative;
  for (std::size_t b = 0; b < sample.values.size(); ++b) {
    if (sample.values[b] > 0)
      relative.push_back(std::abs(white->contribution[b] / sample.values[b]));
  }
  if (relative.empty()) return std::nullopt;
  return Median(std::move(relative)) * rho_w;
}

Result<StoredUncertainty> LoadStoredUncertainty(storage::SessionReader& reader,
                                                const exports::Session& session,
                                                const exports::DerivedSamples& derived) {
  std::unordered_map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < derived.samples.size(); ++i) index[derived.samples[i].reading_id] = i;
  StoredUncertainty out;
  out.combined.resize(derived.samples.size());
  const double rho_w = exports::WhiteReflectanceOf(session);
  std::int64_t after = 0;
  while (true) {
    BRDF_ASSIGN_OR_RETURN(std::vector<storage::ReadingRecord> page,
                          reader.GetReadings(session.id, after, kBudgetPage));
    if (page.empty()) break;
    after = page.back().id;
    for (storage::ReadingRecord& r : page) {
      auto it = index.find(r.id);
      if (it == index.end() || !r.uncertainty.has_value() ||
          r.uncertainty->quantity != Quantity::kBrdf) {
        continue;
      }
      if (!out.white_u.has_value() && !session.white_reflectance_spectrum.has_value()) {
        out.white_u = WhiteUncertaintyOf(*r.uncertainty, derived.samples[it->second], rho_w);
      }
      out.combined[it->second] = std::move(r.uncertainty->combined);
    }
  }
  return out;
}

std::string MeterModelOf(const std::vector<storage::DeviceRecord>& devices) {
  for (const storage::DeviceRecord& d : devices) {
    if (d.kind == "spectroradiometer" && !d.model.empty()) return d.model;
  }
  return "";
}

// The provenance from the session's record, its plan and its devices (the plan's sample block
// for the sample and the white standard).
Result<exports::BirdProvenance> ProvenanceOf(storage::SessionReader& reader,
                                             const exports::Session& session) {
  BRDF_ASSIGN_OR_RETURN(storage::SessionRecord record, reader.GetSession(session.id));
  BRDF_ASSIGN_OR_RETURN(std::vector<storage::DeviceRecord> devices,
                        reader.GetSessionDevices(session.id));
  exports::BirdProvenance p;
  p.session_id = record.id;
  p.session_name = record.name;
  p.session_uuid = record.uuid;
  p.rig = record.rig;
  p.measured_at = static_cast<std::int64_t>(record.started_at.value_or(record.created_at));
  p.plan_json = record.plan_json;
  p.meter_serial = record.meter_serial;
  p.meter_model = MeterModelOf(devices);
  p.white_reflectance = exports::WhiteReflectanceOf(session);
  p.white_reflectance_is_spectrum = session.white_reflectance_spectrum.has_value();
  p.software_version = BRDFD_VERSION;
  if (Result<v1::Plan> plan = plan::ParsePlanJson(record.plan_json); plan.ok()) {
    p.plan_name = plan->name();
    p.anisotropic = plan->anisotropic();
    p.averages = static_cast<int>(std::max<std::uint32_t>(1, plan->measurement().averages()));
    const v1::Sample& s = plan->sample();
    p.sample_id = s.id();
    p.sample_name = s.name();
    p.sample_material = s.material();
    p.sample_description = s.description().empty() ? plan->sample_description() : s.description();
    p.white_standard_id = s.white_standard_id();
    if (s.has_white_reflectance_uncertainty()) {
      p.white_reflectance_u = s.white_reflectance_uncertainty();
      p.white_reflectance_u_source = "the plan's sample block";
    }
  }
  return p;
}

}  // namespace

Status ExportBirdJson(const std::shared_ptr<const exports::Session>& session, bool exclude_flagged,
                      storage::SessionReader& reader, SharedSessionLoads& loads,
                      const std::function<void(double)>& progress, std::ostream& out,
                      v1::ExportReport* report) {
  BRDF_ASSIGN_OR_RETURN(std::shared_ptr<const exports::DerivedSamples> derived,
                        loads.Derived(session, Quantity::kBrdf, exclude_flagged));
  BRDF_ASSIGN_OR_RETURN(exports::BirdProvenance provenance, ProvenanceOf(reader, *session));
  BRDF_ASSIGN_OR_RETURN(StoredUncertainty stored,
                        LoadStoredUncertainty(reader, *session, *derived));
  if (!provenance.white_reflectance_u.has_value() && stored.white_u.has_value()) {
    provenance.white_reflectance_u = stored.white_u;
    provenance.white_reflectance_u_source =
        "the stored budgets (|white_standard contribution / BRDF| · ρw, median over bands)";
  }
  exports::BirdOptions options;
  options.progress = progress;
  BRDF_ASSIGN_OR_RETURN(exports::BirdReport bird,
                        exports::WriteBird(provenance, *derived, stored.combined, out, options));
  report->set_rows(bird.points);
  std::vector<exports::SkippedReading> skipped = derived->skipped;
  skipped.insert(skipped.end(), bird.skipped.begin(), bird.skipped.end());
  report->set_skipped_readings(skipped.size());
  if (!skipped.empty()) report->set_first_skip_reason(skipped.front().reason);
  report->set_summary(bird.Summary());
  if (!bird.ubrdf_written) report->add_warnings(exports::BirdUncertaintyNote(bird));
  return Status();
}

}  // namespace brdf::daemon
