#include "daemon/api/export_cache.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <iterator>
#include <utility>

#include "core/export/number_text.h"
#include "daemon/api/export_loads.h"
#include "daemon/index/build.h"

namespace brdf::daemon {
namespace {

std::int64_t LastReadingId(const SessionReadings& session) {
  return session.readings.empty() ? 0 : session.readings.back().id;
}

}  // namespace

ExportInterpolants::ExportInterpolants(MemoryBudget& budget, Options options)
    : budget_(budget),
      max_entries_(std::max<std::size_t>(1, options.max_entries)),
      max_bytes_(options.max_bytes != 0 ? options.max_bytes : budget.budget_bytes() / 2) {}

std::string ExportInterpolants::KeyOf(const Settings& s) {
  std::string key = std::to_string(static_cast<int>(s.quantity)) + "/" +
                    interp::MethodName(s.method) + "/" + exports::FillPolicyName(s.fill) + "/" +
                    (s.exclude_flagged ? "x" : "-") + (s.options.mirror_phi ? "m" : "-") +
                    (s.options.reciprocity ? "r" : "-") + "/" +
                    interp::CoordinatesName(s.options.coordinates) + "/" +
                    interp::TrendName(s.options.trend) + "/";
  // The scales as their shortest round-trip text: equal doubles, equal keys.
  for (const double scale : s.options.axis_scale) key += exports::FormatNumber(scale) + ",";
  return key;
}

std::uint64_t ExportInterpolants::DerivedBytes(const exports::DerivedSamples& derived) {
  std::uint64_t bytes = sizeof(exports::DerivedSamples);
  for (const exports::DerivedSample& s : derived.samples) {
    bytes += sizeof(s) + (s.values.capacity() + s.u.capacity()) * sizeof(double);
  }
  return bytes;
}

std::uint64_t ExportInterpolants::OwnBytesOf(const exports::SessionInterpolant& in) {
  if (!in.samples) return 0;
  // The chosen index and the fallback, each with its copies and images of the samples.
  std::uint64_t bytes = SetBytes(*in.samples);
  if (in.interpolator) bytes += in.interpolator->HeapBytes();
  if (in.fallback) bytes += in.fallback->HeapBytes();
  return bytes;
}

Result<exports::SessionInterpolant> ExportInterpolants::Get(
    const std::shared_ptr<const SessionReadings>& session, const Settings& settings,
    const Build& build, bool* built) {
  if (built != nullptr) *built = false;
  const std::string key = KeyOf(settings);
  MutexLock lock(mu_);
  Entries::iterator at;
  for (;;) {
    at = Find(session.get(), key);
    if (at == entries_.end()) break;
    if (at->built) {
      at->used = ++tick_;
      ++stats_.hits;
      return exports::ShareSessionInterpolant(*at->built);
    }
    landed_.Wait(mu_);  // another caller is building it
  }
  at = entries_.insert(entries_.end(), Entry{session, key, nullptr, ++tick_, nullptr});
  ++stats_.builds;
  lock.Unlock();
  Result<exports::SessionInterpolant> made = build();
  lock.Lock();
  if (built != nullptr) *built = true;
  if (!made.ok()) {
    entries_.erase(at);
    landed_.NotifyAll();
    return made.status();
  }
  auto shared = std::make_shared<const exports::SessionInterpolant>(std::move(*made));
  Keep(at, shared);
  landed_.NotifyAll();
  return exports::ShareSessionInterpolant(*shared);
}

ExportInterpolants::Entries::iterator ExportInterpolants::Find(const SessionReadings* session,
                                                               const std::string& key) {
  return std::find_if(entries_.begin(), entries_.end(),
                      [&](const Entry& e) { return e.session.get() == session && e.key == key; });
}

void ExportInterpolants::Keep(Entries::iterator at,
                              std::shared_ptr<const exports::SessionInterpolant> in) {
  const std::uint64_t own = OwnBytesOf(*in);
  const std::uint64_t session_bytes =
      parts_.contains(at->session.get()) ? 0 : SharedSessionLoads::BytesOf(*at->session);
  const std::uint64_t derived_bytes =
      parts_.contains(in->derived.get()) ? 0 : DerivedBytes(*in->derived);
  const std::uint64_t needed = own + session_bytes + derived_bytes;
  std::unique_ptr<MemoryBudget::Reservation> reservation;
  // Asked only when it should fit, so that the budget's refusals count the calls it refused.
  const bool fits =
      needed <= max_bytes_ && budget_.reserved_bytes() + needed <= budget_.budget_bytes() &&
      budget_.Reserve("Export cache", own, &reservation).ok() &&
      ReservePart(at->session, session_bytes) && ReservePart(in->derived, derived_bytes);
  if (!fits) {
    entries_.erase(at);
    ReleaseParts();
    return;
  }
  at->built = std::move(in);
  at->reservation = std::move(reservation);
  ++stats_.kept;
  Evict(at);
  std::size_t kept = 0;
  for (const Entry& e : entries_) kept += e.built ? 1 : 0;
  spdlog::debug("export cache: kept session {}'s interpolant ({:.1f} MB); {} kept of {}, {:.1f} MB",
                at->session->id, static_cast<double>(needed) / (1 << 20), kept, max_entries_,
                static_cast<double>(KeptBytes()) / (1 << 20));
}

bool ExportInterpolants::ReservePart(const std::shared_ptr<const void>& part, std::uint64_t bytes) {
  if (parts_.contains(part.get())) return true;
  std::unique_ptr<MemoryBudget::Reservation> reservation;
  if (!budget_.Reserve("Export cache", bytes, &reservation).ok()) return false;
  parts_[part.get()] = std::move(reservation);
  return true;
}

void ExportInterpolants::ReleaseParts() {
  for (auto it = parts_.begin(); it != parts_.end();) {
    const bool held = std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) {
      return e.built && (e.session.get() == it->first || e.built->derived.get() == it->first);
    });
    it = held ? std::next(it) : parts_.erase(it);
  }
}

std::uint64_t ExportInterpolants::KeptBytes() const {
  std::uint64_t bytes = 0;
  for (const Entry& e : entries_) {
    if (e.built) bytes += e.reservation->bytes();
  }
  for (const auto& [part, reservation] : parts_) bytes += reservation->bytes();
  return bytes;
}

void ExportInterpolants::Evict(Entries::iterator keep) {
  const SessionReadings& current = *keep->session;
  for (auto it = entries_.begin(); it != entries_.end();) {
    const bool older_copy = it != keep && it->built && it->session->id == current.id &&
                            it->session.get() != &current &&
                            LastReadingId(*it->session) <= LastReadingId(current);
    if (older_copy) {
      it = entries_.erase(it);
      ++stats_.evictions;
    } else {
      ++it;
    }
  }
  for (;;) {
    ReleaseParts();
    std::size_t count = 0;
    auto oldest = entries_.end();
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      if (!it->built) continue;
      ++count;
      if (it != keep && (oldest == entries_.end() || it->used < oldest->used)) oldest = it;
    }
    if ((count <= max_entries_ && KeptBytes() <= max_bytes_) || oldest == entries_.end()) return;
    entries_.erase(oldest);
    ++stats_.evictions;
  }
}

ExportInterpolants::Options ExportInterpolantsOptionsFrom(const Config& config) {
  ExportInterpolants::Options options;
  options.max_entries = static_cast<std::size_t>(config.exports.max_entries);
  options.max_bytes = static_cast<std::uint64_t>(config.exports.max_mb) << 20;
  return options;
}

ExportInterpolants::Stats ExportInterpolants::stats() const {
  MutexLock lock(mu_);
  Stats s = stats_;
  for (const Entry& e : entries_) s.entries += e.built ? 1 : 0;
  s.bytes = KeptBytes();
  return s;
}

}  // namespace brdf::daemon
