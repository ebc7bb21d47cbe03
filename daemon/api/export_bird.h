// Data.Export's BiRD universal BRDF JSON (format BIRD_JSON; core/export/bird/writer.h,
// docs/bird-format.md): the session's sample readings as BRDF (the derivation the exports of
// the session share, export_loads.h), each reading's combined standard uncertainty u_c from its
// stored budget (read from the reader a page at a time; only u_c is kept), and the session's
// provenance from its record, its plan and the devices recorded with it. Defined in
// export_bird.cc; export.cc calls it.
#pragma once

#include <functional>
#include <memory>
#include <ostream>

#include "brdf/v1/brdf.pb.h"
#include "core/export/session_data.h"
#include "core/status.h"
#include "daemon/api/export_loads.h"
#include "storage/session_reader.h"

namespace brdf::daemon {

// Writes the file to `out` and fills `report` (rows: the points; skipped readings; a warning
// when uBRDF is left out). `progress` gets the fraction of the writing done. Errors: the
// derivation's, the reader's (naming the session), the writer's.
Status ExportBirdJson(const std::shared_ptr<const exports::Session>& session, bool exclude_flagged,
                      storage::SessionReader& reader, SharedSessionLoads& loads,
                      const std::function<void(double)>& progress, std::ostream& out,
                      v1::ExportReport* report);

}  // namespace brdf::daemon
