// The "metadata" section of a BiRD file (writer.h, docs/bird-format.md): the session's
// provenance in the format's objects, and brdfd's own record of it in metadata.adhoc_section.
// `facts` is the report of what the data section will hold (readings, points, budgets, clamped
// values, skipped readings), known before the data are written. Pure.
#pragma once

#include <cstdint>
#include <string>

#include "core/export/bird/json_out.h"
#include "core/export/bird/writer.h"
#include "core/wavelength_grid.h"

namespace brdf::exports {

void WriteBirdMetadata(JsonOut& json, const BirdProvenance& provenance, const WavelengthGrid& grid,
                       const BirdReport& facts);

// Unix seconds as ISO 8601 UTC, "2026-12-06T11:10:03Z".
std::string BirdTimestamp(std::int64_t unix_seconds);

// How uBRDF was written (or why not), one sentence for the file's comments and the report.
std::string BirdUncertaintyNote(const BirdReport& facts);

}  // namespace brdf::exports
