// How storage reads its rows back into records: the column lists of sessions, steps, readings,
// events and adaptive rounds, and the functions that turn a row (selected with those columns, in
// that order) into a record. Shared by SessionStore and its archive shipping
// (session_store_archive.cc); internal to storage/.
#pragma once

#include <string>
#include <string_view>

#include "core/status.h"
#include "storage/records.h"
#include "storage/sqlite.h"

namespace brdf::storage {

// A row whose enumeration text does not parse has been damaged outside brdfd (CHECK constraints
// keep brdfd's own writes valid).
template <typename T>
Result<T> FromColumn(Result<T> parsed, const std::string& path, const std::string& where) {
  if (parsed.ok()) return parsed;
  return IoError(where + " in " + path + " is damaged: " + parsed.status().message() +
                 "; run CheckSession or sqlite3 " + path + " 'PRAGMA integrity_check'");
}

extern const std::string_view kSessionColumns;  // select them FROM sessions (unaliased)
extern const std::string_view kStepColumns;
extern const std::string_view kReadingColumns;  // select them FROM kReadingsWithUncertainty
extern const std::string_view kReadingsWithUncertainty;  // readings LEFT JOIN reading_uncertainty
extern const std::string_view kEventColumns;             // session_events (v4)
extern const std::string_view kReadingPointColumns;      // readings, without the spectrum
extern const std::string_view kRoundColumns;             // adaptive_rounds (v6)

// A row whose enumeration text does not parse has been damaged outside brdfd: kIoError naming
// `path` and what to run.
Result<SessionRecord> ReadSession(const Statement& st, const std::string& path);
Result<StepRecord> ReadStep(const Statement& st, const std::string& path);
Result<ReadingRecord> ReadReading(const Statement& st, const std::string& path);
Result<ReadingPointRecord> ReadReadingPoint(const Statement& st, const std::string& path);
Result<SessionEventRecord> ReadEvent(const Statement& st, const std::string& path);
// kInvalidArgument naming the line when the picks do not read back (round_picks.h).
Result<RoundRecord> ReadRound(const Statement& st);

}  // namespace brdf::storage
