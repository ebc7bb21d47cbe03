// SessionCatalogue: the sessions a server reads, whoever keeps them. The read side of the API
// (Control's GetSession, ListSessions and ListSessionEvents; Data's streams and Export) is written
// once over it; brdfd plugs in its session manager and store (rig/catalogue.h), brdf-archive the
// lab archive (archive/catalogue.h).
//
// Session ids are the catalogue's own: brdfd's store ids, the archive's archive ids (the same
// session has another id there; its uuid and rig are the same everywhere).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "brdf/v1/brdf.pb.h"
#include "core/session_state.h"
#include "core/status.h"
#include "daemon/sessions/session_id.h"
#include "storage/session_reader.h"

namespace brdf::daemon {

class StopSignal;

// ListSessions' catalogue filters (ListSessionsRequest fields 4-9), checked (api/control.cc):
// brdfd applies them to its sessions with Matches, brdf-archive in its SQL
// (storage/archive/reader.h), with the same meaning. Timestamps as Unix seconds.
struct CatalogueFilter {
  std::vector<SessionState> states;  // ListSessionsRequest.states (Matches leaves them out)
  std::string rig;
  std::string sample;    // the sample's id, or its name ignoring case
  std::string material;  // ignoring case
  std::string tag;
  std::optional<double> created_after;   // created_at ≥
  std::optional<double> created_before;  // created_at <
  bool Matches(const v1::Session& session) const;
};

// One page of ListSessions.
struct SessionPage {
  std::vector<v1::Session> sessions;  // newest first, without their plans
  std::string next_page_token;        // empty: the last page
};

// How a stream that follows a session (StreamReadings with follow) learns that it ended and
// waits for more.
struct SessionFollow {
  // Asked BEFORE each page: true when the session will get no reading after what the next page
  // reads (so a short page then ends the stream).
  std::function<Result<bool>()> ended;
  // After a short page of a session not ended (the stream's last reading id `last_id`): waits
  // until a newer reading may be there, or a while, or until `stopping`. True when stopping.
  std::function<bool(const StopSignal& stopping, std::int64_t last_id)> wait;
  // After a wait: the readings after `after_id` (at most `limit`, in id order) when the catalogue
  // holds them for all its followers (api/stream_readings_fanout.h), nullopt when the stream must
  // read the store itself. Empty: always the store.
  std::function<Result<std::optional<std::vector<storage::ReadingRecord>>>(std::int64_t after_id,
                                                                           int limit)>
      recent;
  // For a stream served without a thread of its own (api/pumped_stream.h), instead of `wait`:
  // calls `wake` once a reading newer than `last_id` is committed (at once when one already was;
  // from the committing thread: it must not block). Empty: such a stream looks again every
  // second, as `wait` would.
  std::function<void(std::int64_t last_id, std::function<void()> wake)> notify;
};

class SessionCatalogue {
 public:
  virtual ~SessionCatalogue() = default;

  // One session with its plan. kNotFound naming it when there is no such session.
  virtual Result<v1::Session> GetSession(SessionId session) = 0;

  // A page of the sessions that match `filter`, newest first, at most `page_size` (> 0), after
  // the page `page_token` ended (empty: the first page). A token this catalogue did not give
  // out: kInvalidArgument naming page_token.
  virtual Result<SessionPage> ListSessions(const CatalogueFilter& filter,
                                           const std::string& page_token,
                                           std::uint32_t page_size) = 0;

  // Where sessions, steps, readings and histories are read (ListSessionEvents, the streams,
  // Export). Outlives the catalogue's users.
  virtual storage::SessionReader& reader() = 0;

  // For a stream that follows `session` (which exists): see SessionFollow. Used by one stream,
  // on its thread, while the stream lasts.
  virtual SessionFollow Follow(SessionId session) = 0;

  // An adaptive session's rounds, oldest first, for a server without a rig (brdf-archive: the
  // rounds its rigs shipped, with the spend each rig computed); empty for a session without
  // rounds, kNotFound for no such session. A server with a rig answers from its RigPort instead;
  // a catalogue that keeps no rounds says kFailedPrecondition (the default).
  virtual Result<std::vector<v1::AdaptiveRound>> AdaptiveRounds(SessionId session) {
    return FailedPrecondition("session " + std::to_string(session) +
                              ": this server keeps no adaptive rounds; ask its rig's brdfd");
  }

  // The plan's averaging count (the meter's, the same for every reading of the session); 0 when
  // the plan does not say or cannot be read.
  virtual std::uint32_t Averages(SessionId session) = 0;
};

}  // namespace brdf::daemon
