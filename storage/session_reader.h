// SessionReader: reading a recorded session -- its record, its steps and its readings a page at a
// time -- whatever holds it. The rig's SQLite store (session_store.h) is one; the lab archive in
// PostgreSQL (archive_reader.h) is another. What answers from a session's data (the daemon's
// index cache, hence Interpolate and InterpolateBatch) reads through this interface, so the rig
// and brdf-archive answer with the same code from the same records, bit for bit.
//
// Contract, for every implementation:
//   - ids are the reader's own session ids (positive); readings keep the ids they were recorded
//     with, and a reading's reference_reading_id / dark_reading_id name readings of the same
//     session by those ids;
//   - events keep the ids they were recorded with on the rig;
//   - GetReadings pages in ascending reading id: up to `limit` (> 0) readings with id > after_id;
//     readings are append-only, so paging never skips or repeats one;
//   - GetReadingPoints pages exactly as GetReadings, the same readings, without reading their
//     spectra (a 50,000-reading session's spectra are 40 MB a plot of it does not need);
//   - kNotFound for an unknown session; kIoError (or kDisconnected) when the data cannot be read.
// Thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include "core/status.h"
#include "storage/records.h"

namespace brdf::storage {

class SessionReader {
 public:
  virtual ~SessionReader() = default;

  virtual Result<SessionRecord> GetSession(std::int64_t session) = 0;
  virtual Result<std::vector<StepRecord>> GetSteps(std::int64_t session) = 0;
  virtual Result<std::vector<ReadingRecord>> GetReadings(std::int64_t session,
                                                         std::int64_t after_id, int limit) = 0;
  virtual Result<std::vector<ReadingPointRecord>> GetReadingPoints(std::int64_t session,
                                                                   std::int64_t after_id,
                                                                   int limit) = 0;
  // The session's history of states: one event when it was created and one per change of its
  // state or reason, in the order they happened (ascending event id).
  virtual Result<std::vector<SessionEventRecord>> ListSessionEvents(std::int64_t session) = 0;
  // The devices recorded with the session (the meter's model and serial), oldest first. The
  // default, for a reader that keeps none: an empty list (the BiRD export then says "not
  // recorded").
  virtual Result<std::vector<DeviceRecord>> GetSessionDevices(std::int64_t session) {
    (void)session;
    return std::vector<DeviceRecord>{};
  }
};

}  // namespace brdf::storage
