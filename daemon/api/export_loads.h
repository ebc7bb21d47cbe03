// The sessions Data.Export has loaded, shared by the exports running at the same time (issue 40):
// an export holds its session's readings (spectra and all) for as long as it streams, and a
// hundred analysts exporting one session, or a hundred exports left unread, would otherwise hold a
// hundred copies. Load() hands out the copy an export in flight already holds when the store has
// no reading past its last one (one indexed query of at most one record), else loads anew. Copies
// are kept only while an export holds them (weak references): nothing stays once the exports end.
// The same for a shared session's derived samples (reflectance or BRDF: Derived), which the
// readings CSV writes row by row.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <tuple>

#include "core/export/session_data.h"
#include "core/mutex.h"
#include "core/readings/reading.h"
#include "core/status.h"
#include "storage/session_reader.h"

namespace brdf::daemon {

class SharedSessionLoads {
 public:
  // The session with every reading (storage::LoadSessionReadings), shared when current; `loaded`
  // (optional) is set to true when this call read it from the store. Errors: LoadSessionReadings'
  // (kNotFound for an unknown session) and the reader's.
  Result<std::shared_ptr<const SessionReadings>> Load(storage::SessionReader& reader,
                                                      std::int64_t session_id,
                                                      bool* loaded = nullptr);

  // exports::DeriveSamples(*session, quantity, {exclude_flagged}), shared by the exports of the
  // same copy of the session that ask for the same; `derived_here` (optional) is set to true when
  // this call derived them.
  Result<std::shared_ptr<const exports::DerivedSamples>> Derived(
      const std::shared_ptr<const SessionReadings>& session, exports::Quantity quantity,
      bool exclude_flagged, bool* derived_here = nullptr);

  // The readings' memory, roughly (spectra, u and the budgets' loaded form): what an export of
  // `session` holds.
  static std::uint64_t BytesOf(const SessionReadings& session);

 private:
  Mutex mu_;
  std::map<std::int64_t, std::weak_ptr<const SessionReadings>> held_ GUARDED_BY(mu_);
  // By the copy of the session (alive while its weak reference is), quantity and exclusion.
  struct HeldDerivation {
    std::weak_ptr<const SessionReadings> session;
    std::weak_ptr<const exports::DerivedSamples> derived;
  };
  std::map<std::tuple<const SessionReadings*, int, bool>, HeldDerivation> derived_ GUARDED_BY(mu_);
};

}  // namespace brdf::daemon
