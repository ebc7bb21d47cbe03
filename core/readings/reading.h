// The lab's vocabulary for what the meter measured: a reading (sample I, white reference I0 or
// dark D) with its pose, directions and spectrum, and a session's readings as one list. storage/
// keeps them as ReadingRecords; the daemon's index, the exports, the fits and the tools all take
// these plain values (storage/session_readings.h converts). Pure: no I/O.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"
#include "core/spectrum.h"

namespace brdf {

namespace uncertainty {
struct LoadedBudget;  // core/uncertainty/loaded_budget.h
}  // namespace uncertainty

// What a reading measured: the sample I, the white standard I0, or the dark (ambient) D.
enum class ReadingKind { kSample, kReference, kDark };
const char* ReadingKindName(ReadingKind kind);  // "sample", "reference", "dark"

// One reading as the session took it.
struct Reading {
  std::int64_t id = 0;
  ReadingKind kind = ReadingKind::kSample;
  Pose pose;               // the pose reached (stage readings, degrees)
  Directions directions;   // θi φi θo φo in the sample frame (degrees)
  Spectrum spectrum;       // radiance as the meter reported it, W·m⁻²·sr⁻¹·nm⁻¹
  int quality_code = 0;    // the meter's quality code (0 = OK)
  bool flagged = false;    // kept but flagged by the quality policy
  int integration_ms = 0;  // 0 = adaptive
  // How the meter changed the integration time to take it (IntegrationNoteOf its stored note);
  // empty when it used the plan's.
  std::string integration_note;
  std::optional<std::int64_t> reference_id;  // the I0 this reading is divided by
  std::optional<std::int64_t> dark_id;       // the D subtracted, when measured
  // The standard uncertainty (k = 1, sr⁻¹) of the reading's BRDF per band: its stored budget's
  // combined (docs/uncertainty.md). Empty when not estimated (darks, references, readings stored
  // before budgets existed).
  std::vector<double> brdf_u;
  // The part of brdf_u the reflectance R = (I − D) / (I0 − D) carries too: without the white
  // standard's and the reference pose's terms, which scale the BRDF only; u(R) = this · R / f.
  std::vector<double> brdf_u_of_ratio;
  // What the exports read of the stored budget of the BRDF (null when not estimated, not of the
  // BRDF, or not loaded): its blend form, which an interpolated value's measurement part blends
  // (core/uncertainty/interpolated.h), shared terms correlated, and its white standard's
  // contribution. Set by storage's LoadSessionReadings, one BlendBudgetMaker for the session.
  std::shared_ptr<const uncertainty::LoadedBudget> budget;
};

// A session's readings, with what the derivation needs of the session itself.
struct SessionReadings {
  std::int64_t id = 0;
  std::string name;
  // ρw of the white standard; nullopt: the paper's RS-3, kWhiteStandardReflectance (0.99).
  std::optional<double> white_reflectance;
  // ρw(λ) from the plan's sample block; when set the BRDF uses it instead of the number.
  std::optional<Spectrum> white_reflectance_spectrum;
  std::vector<Reading> readings;  // in id order (the order they were taken)
};

// The clauses of a reading's stored note (the meter's and its quality policy's notes joined by
// "; ", storage ReadingRecord.note) that changed the integration time, joined by "; ", e.g.
// "quality 19 (overload): integration halved from 500 to 250 ms"; empty when none did.
std::string IntegrationNoteOf(std::string_view note);

// ρw as the session gives it, else kWhiteStandardReflectance.
double WhiteReflectanceOf(const SessionReadings& session);

// True when the sample readings were taken at more than one dial position γ: the session looks
// anisotropic, and an isotropic reduction (grid, MERL, fits) folds its azimuths together.
bool HasSeveralDialPositions(const SessionReadings& session);

}  // namespace brdf
