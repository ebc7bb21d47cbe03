#include "daemon/api/export_loads.h"

#include <string>
#include <utility>
#include <vector>

#include "core/uncertainty/loaded_budget.h"
#include "storage/session_readings.h"

namespace brdf::daemon {
namespace {

// True when the store holds no reading of the session after `copy`'s last one.
bool Current(storage::SessionReader& reader, const SessionReadings& copy) {
  const std::int64_t last = copy.readings.empty() ? 0 : copy.readings.back().id;
  Result<std::vector<storage::ReadingRecord>> newer = reader.GetReadings(copy.id, last, 1);
  return newer.ok() && newer->empty();
}

// A reading's loaded budget's bytes; its not_estimated list too unless it is `last_notes` (the
// previous reading's, which consecutive readings share: counted once, with the first of them).
std::uint64_t LoadedBudgetBytes(const uncertainty::LoadedBudget& budget,
                                const std::vector<std::string>* last_notes) {
  return sizeof(budget) + budget.white_standard.capacity() * sizeof(double) +
         uncertainty::HeapBytes(budget.blend, budget.blend.not_estimated.get() != last_notes);
}

}  // namespace

Result<std::shared_ptr<const SessionReadings>> SharedSessionLoads::Load(
    storage::SessionReader& reader, std::int64_t session_id, bool* loaded) {
  if (loaded != nullptr) *loaded = false;
  std::shared_ptr<const SessionReadings> held;
  {
    MutexLock lock(mu_);
    auto it = held_.find(session_id);
    if (it != held_.end()) held = it->second.lock();
    // Forget the copies no export holds any more.
    for (auto at = held_.begin(); at != held_.end();) {
      at = at->second.expired() ? held_.erase(at) : std::next(at);
    }
  }
  if (held && Current(reader, *held)) return held;
  Result<SessionReadings> fresh = storage::LoadSessionReadings(reader, session_id);
  if (!fresh.ok()) return fresh.status();
  auto shared = std::make_shared<const SessionReadings>(*std::move(fresh));
  if (loaded != nullptr) *loaded = true;
  MutexLock lock(mu_);
  held_[session_id] = shared;
  return shared;
}

Result<std::shared_ptr<const exports::DerivedSamples>> SharedSessionLoads::Derived(
    const std::shared_ptr<const SessionReadings>& session, exports::Quantity quantity,
    bool exclude_flagged, bool* derived_here) {
  if (derived_here != nullptr) *derived_here = false;
  const auto key = std::make_tuple(session.get(), static_cast<int>(quantity), exclude_flagged);
  {
    MutexLock lock(mu_);
    for (auto at = derived_.begin(); at != derived_.end();) {
      at = at->second.session.expired() || at->second.derived.expired() ? derived_.erase(at)
                                                                        : std::next(at);
    }
    auto it = derived_.find(key);
    if (it != derived_.end()) {
      if (auto held = it->second.derived.lock()) return held;
    }
  }
  Result<exports::DerivedSamples> fresh =
      exports::DeriveSamples(*session, quantity, {exclude_flagged});
  if (!fresh.ok()) return fresh.status();
  auto shared = std::make_shared<const exports::DerivedSamples>(*std::move(fresh));
  if (derived_here != nullptr) *derived_here = true;
  MutexLock lock(mu_);
  derived_[key] = HeldDerivation{session, shared};
  return shared;
}

std::uint64_t SharedSessionLoads::BytesOf(const SessionReadings& session) {
  std::uint64_t bytes = sizeof(SessionReadings);
  const std::vector<std::string>* last_notes = nullptr;
  for (const Reading& r : session.readings) {
    bytes += sizeof(Reading) +
             (r.spectrum.values.capacity() + r.brdf_u.capacity() + r.brdf_u_of_ratio.capacity()) *
                 sizeof(double);
    if (r.budget) {
      bytes += LoadedBudgetBytes(*r.budget, last_notes);
      last_notes = r.budget->blend.not_estimated.get();
    }
  }
  return bytes;
}

}  // namespace brdf::daemon
