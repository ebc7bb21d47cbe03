// Compares the lab archive with a rig's database, reading by reading.
#pragma once

#include <string>

#include "storage/session_store.h"

namespace brdf::storage::testing {

// Every session of `store` is in the archive (at `conninfo`) under `rig` with the same state,
// steps and counts, and every reading is there exactly once with the same id, step, kind, spectrum
// bytes, timestamp, reference, angles, flag, quality code and uncertainty budget (none: none);
// the archive holds no other reading
// of that rig; likewise each session's events (id, time, state, reason) and adaptive rounds (every
// field of the record, once each). Reports through gtest's EXPECT/ASSERT.
void ExpectArchiveHoldsExactly(const std::string& conninfo, SessionStore& store,
                               const std::string& rig);

}  // namespace brdf::storage::testing
