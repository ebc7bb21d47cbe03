// Writes a ShipBatch into the lab archive in ONE PostgreSQL transaction, with idempotent upserts
// keyed by the session's uuid and the step (archive-schema.md): sessions and steps take the rig's
// current row (ON CONFLICT DO UPDATE), readings, devices, audit entries and adaptive rounds are
// inserted once (ON CONFLICT DO NOTHING). Shipping the same batch twice leaves the archive as
// shipping it once.
#pragma once

#include <string>

#include "core/status.h"
#include "storage/archive/pg.h"
#include "storage/ship_batch.h"

namespace brdf::storage {

// `rig`: the shipping rig's name (sessions carry their own; devices and audit are keyed by it).
// Any error rolls the whole batch back; the caller keeps its marks and sends the batch again.
Status WriteToArchive(PgConnection& conn, const std::string& rig, const ShipBatch& batch);

}  // namespace brdf::storage
