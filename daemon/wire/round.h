// An adaptive session's round as the API shows it (brdf.v1.AdaptiveRound; docs/adaptive.md,
// "Every choice explained"), from the stored record and what the round meant for the budget: one
// mapping for brdfd (WatchSession's events and ListAdaptiveRounds from its store,
// engine/adaptive_rounds.h) and brdf-archive (ListAdaptiveRounds from the rounds its rigs
// shipped, storage/archive/reader.h), so both answer the same message for the same round.
#pragma once

#include "brdf/v1/brdf.pb.h"
#include "storage/ship_batch.h"

namespace brdf::daemon {

v1::AdaptiveRound ToProtoRound(const storage::ArchivedRound& round);

}  // namespace brdf::daemon
