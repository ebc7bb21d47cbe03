#include "daemon/api/stream_readings_fanout.h"

#include <algorithm>
#include <utility>

namespace brdf::daemon {

ReadingFanout::ReadingFanout(ReadPage read, std::size_t capacity)
    : read_(std::move(read)), capacity_(std::max<std::size_t>(capacity, 1)) {}

void ReadingFanout::Join(std::int64_t session) {
  MutexLock lock(mu_);
  ++sessions_[session].followers;
}

void ReadingFanout::Leave(std::int64_t session) {
  MutexLock lock(mu_);
  auto it = sessions_.find(session);
  if (it != sessions_.end() && --it->second.followers <= 0) sessions_.erase(it);
}

void ReadingFanout::Committed(std::int64_t session, std::int64_t reading_id) {
  std::vector<std::function<void()>> woken;
  {
    MutexLock lock(mu_);
    auto it = sessions_.find(session);
    if (it == sessions_.end()) return;  // nobody follows it
    Followed& f = it->second;
    f.committed = std::max(f.committed, reading_id);
    auto newer = [&](const auto& n) { return n.first < f.committed; };
    for (auto& n : f.notified) {
      if (newer(n)) woken.push_back(std::move(n.second));
    }
    f.notified.erase(std::remove_if(f.notified.begin(), f.notified.end(), newer), f.notified.end());
  }
  cv_.NotifyAll();
  for (const std::function<void()>& wake : woken) wake();
}

void ReadingFanout::Notify(std::int64_t session, std::int64_t after_id,
                           std::function<void()> wake) {
  {
    MutexLock lock(mu_);
    auto it = sessions_.find(session);
    if (it != sessions_.end() && it->second.committed <= after_id) {
      it->second.notified.emplace_back(after_id, std::move(wake));
      return;
    }
  }
  wake();  // a newer reading was committed already (or the session has no follower: look)
}

bool ReadingFanout::Wait(std::int64_t session, std::int64_t after_id,
                         std::chrono::steady_clock::duration d) {
  MutexLock lock(mu_);
  const std::uint64_t wakes = wakes_;
  auto newer = [&]() REQUIRES(mu_) {
    auto it = sessions_.find(session);
    return it != sessions_.end() && it->second.committed > after_id;
  };
  cv_.WaitFor(mu_, d, [&]() REQUIRES(mu_) { return newer() || wakes_ != wakes; });
  return newer();
}

void ReadingFanout::Wake() {
  std::vector<std::function<void()>> woken;
  {
    MutexLock lock(mu_);
    ++wakes_;
    for (auto& [session, f] : sessions_) {
      for (auto& n : f.notified) woken.push_back(std::move(n.second));
      f.notified.clear();
    }
  }
  cv_.NotifyAll();
  for (const std::function<void()>& wake : woken) wake();
}

std::optional<std::vector<storage::ReadingRecord>> ReadingFanout::TakeLocked(const Followed& f,
                                                                             std::int64_t after_id,
                                                                             int limit) const {
  if (f.floor.has_value() && after_id < *f.floor) return std::nullopt;  // fell behind
  std::vector<storage::ReadingRecord> out;
  for (const storage::ReadingRecord& r : f.held) {
    if (static_cast<int>(out.size()) == limit) break;
    if (r.id > after_id) out.push_back(r);
  }
  return out;
}

Result<std::optional<std::vector<storage::ReadingRecord>>> ReadingFanout::After(
    std::int64_t session, std::int64_t after_id, int limit) {
  using Answer = std::optional<std::vector<storage::ReadingRecord>>;
  for (int pass = 0; pass < 2; ++pass) {
    {
      MutexLock lock(mu_);
      auto it = sessions_.find(session);
      if (it == sessions_.end()) return Answer();
      const Followed& f = it->second;
      // Nothing newer than what is held (or, before the first fill, than the asker's last) was
      // committed since Join: what is held is all there is.
      const std::int64_t known = f.through.value_or(after_id);
      if (f.committed <= known) return TakeLocked(f, after_id, limit);
      // More was committed than one fill holds: the follower reads the store.
      if (pass == 1) return Answer();
    }
    BRDF_RETURN_IF_ERROR(Fill(session, after_id));
  }
  return Answer();  // not reached
}

Status ReadingFanout::Fill(std::int64_t session, std::int64_t after_id) {
  MutexLock filling(fill_mu_);
  std::int64_t from = after_id;
  {
    MutexLock lock(mu_);
    auto it = sessions_.find(session);
    if (it == sessions_.end()) return Status::Ok();
    if (it->second.through.has_value()) {
      if (it->second.committed <= *it->second.through) return Status::Ok();  // another filled
      from = *it->second.through;
    }
  }
  Result<std::vector<storage::ReadingRecord>> page =
      read_(session, from, static_cast<int>(capacity_));
  if (!page.ok()) return page.status();
  MutexLock lock(mu_);
  ++store_reads_;
  auto it = sessions_.find(session);
  if (it == sessions_.end()) return Status::Ok();
  Followed& f = it->second;
  if (!f.through.has_value()) f.floor = from;
  std::int64_t through = from;
  for (storage::ReadingRecord& r : *page) {
    through = std::max(through, r.id);
    f.held.push_back(std::move(r));
  }
  f.through = through;
  while (f.held.size() > capacity_) {
    f.floor = f.held.front().id;
    f.held.pop_front();
  }
  return Status::Ok();
}

std::uint64_t ReadingFanout::store_reads() const {
  MutexLock lock(mu_);
  return store_reads_;
}

}  // namespace brdf::daemon
