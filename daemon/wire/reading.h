// Readings as the API shows them: a stored reading as a Reading (StreamReadings), where it was
// taken as a row of ReadingPoints' columns (StreamReadingPoints).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "brdf/v1/brdf.pb.h"
#include "storage/records.h"

namespace brdf::daemon {

// What a Reading message needs beyond the record: the step's label, and the plan's averaging
// (the meter's averaging count is a plan setting, the same for every reading of a session).
struct ReadingExtras {
  std::map<int, std::string> step_labels;
  std::uint32_t averages = 1;
};
v1::Reading ToProtoReading(const storage::ReadingRecord& record, const ReadingExtras& extras);
// A stored budget as the API shows it (Reading.uncertainty). Components shared through the
// session carry shared_id 0 (the reading's session_id names it).
v1::ReadingUncertainty ToProtoUncertainty(const uncertainty::ReadingBudget& budget);

// Appends one reading to the columns (id, pose, isotropic directions, flagged). The angles are
// for plotting and picking: rounded to a micro-degree, far below any stage's resolution (a
// computed direction's 17 digits, 59.999999999999993, become a few, 60, so the JSON the web
// gateway prints for 50,000 readings is about half as long). StreamReadings keeps exact values.
void AddReadingPoint(const storage::ReadingPointRecord& record, v1::ReadingPoints* points);

}  // namespace brdf::daemon
