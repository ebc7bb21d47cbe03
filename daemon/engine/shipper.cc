#include "daemon/engine/shipper.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "daemon/engine/adaptive_rounds.h"
#include "daemon/sessions/session_plan.h"
#include "daemon/wire/values.h"
#include "storage/archive/pg.h"
#include "storage/archive/schema.h"
#include "storage/archive/writer.h"

namespace brdf::daemon {
namespace {

// Outbox entries (session and step changes) per batch.
constexpr int kMaxChanges = 2000;

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

const char* StateWord(v1::ArchiveState state) {
  switch (state) {
    case v1::ARCHIVE_STATE_OFF:
      return "off";
    case v1::ARCHIVE_STATE_CONNECTING:
      return "connecting";
    case v1::ARCHIVE_STATE_CAUGHT_UP:
      return "caught up";
    case v1::ARCHIVE_STATE_SHIPPING:
      return "shipping";
    case v1::ARCHIVE_STATE_UNREACHABLE:
      return "unreachable";
    case v1::ARCHIVE_STATE_REFUSED:
      return "refused";
    default:
      return "unknown";
  }
}

v1::ArchiveState FailureState(const Status& st) {
  return st.code() == StatusCode::kDisconnected || st.code() == StatusCode::kTimeout
             ? v1::ARCHIVE_STATE_UNREACHABLE
             : v1::ARCHIVE_STATE_REFUSED;
}

// The spend of each of the batch's rounds as ListAdaptiveRounds on this rig answers it
// (StoredRounds: the session's plan and stored steps, on the rig's description).
Status FillRoundSpends(storage::SessionStore& store, const plan::RigDescription& rig,
                       storage::ShipBatch& batch) {
  std::map<std::int64_t, std::vector<v1::AdaptiveRound>> by_session;
  for (storage::ArchivedRound& a : batch.rounds) {
    const std::int64_t id = a.record.session_id;
    auto it = by_session.find(id);
    if (it == by_session.end()) {
      BRDF_ASSIGN_OR_RETURN(storage::SessionRecord record, store.GetSession(id));
      BRDF_ASSIGN_OR_RETURN(SessionPlan plan, ParseSessionPlan(record));
      BRDF_ASSIGN_OR_RETURN(std::vector<v1::AdaptiveRound> rounds,
                            StoredRounds(store, id, plan.plan, rig));
      it = by_session.emplace(id, std::move(rounds)).first;
    }
    auto same = std::find_if(it->second.begin(), it->second.end(), [&a](const auto& r) {
      return static_cast<int>(r.round()) == a.record.round;
    });
    if (same == it->second.end()) {
      return Internal("round " + std::to_string(a.record.round) + " of session " +
                      std::to_string(id) + " is not among the session's stored rounds");
    }
    a.spent_rig_s = same->spent_rig_s();
    a.spent_prompts = static_cast<int>(same->spent_prompts());
    a.rig_s = same->rig_s();
    a.prompts = static_cast<int>(same->prompts());
  }
  return Status::Ok();
}

}  // namespace

v1::ArchiveStatus ArchiveOffStatus() {
  v1::ArchiveStatus s;
  s.set_state(v1::ARCHIVE_STATE_OFF);
  return s;
}

ArchiveShipper::ArchiveShipper(std::shared_ptr<storage::SessionStore> store, Options options)
    : store_(std::move(store)), options_(std::move(options)) {}

Result<std::unique_ptr<ArchiveShipper>> ArchiveShipper::Start(
    std::shared_ptr<storage::SessionStore> store, Options options) {
  BRDF_RETURN_IF_ERROR(store->SetArchiveShipping(true));
  std::unique_ptr<ArchiveShipper> shipper(new ArchiveShipper(std::move(store), std::move(options)));
  shipper->thread_ = std::thread([s = shipper.get()] { s->Run(); });
  return shipper;
}

ArchiveShipper::~ArchiveShipper() {
  Stop();
}

void ArchiveShipper::Stop() {
  {
    MutexLock lock(mu_);
    stopping_ = true;
  }
  cv_.NotifyAll();
  if (thread_.joinable()) thread_.join();
}

bool ArchiveShipper::Wait(std::chrono::milliseconds d) {
  MutexLock lock(mu_);
  cv_.WaitFor(mu_, d, [this]() REQUIRES(mu_) { return stopping_; });
  return !stopping_;
}

void ArchiveShipper::SetState(v1::ArchiveState state, const std::string& detail) {
  MutexLock lock(mu_);
  if (state != state_ || detail != detail_) {
    if (state == v1::ARCHIVE_STATE_UNREACHABLE || state == v1::ARCHIVE_STATE_REFUSED) {
      spdlog::warn("archive {}: {} (recording goes on; retrying every {} ms)", StateWord(state),
                   detail, options_.retry.count());
    } else if (state_ == v1::ARCHIVE_STATE_UNREACHABLE || state_ == v1::ARCHIVE_STATE_REFUSED ||
               state_ == v1::ARCHIVE_STATE_CONNECTING) {
      spdlog::info("archive {}", StateWord(state));
    }
  }
  state_ = state;
  detail_ = detail;
}

void ArchiveShipper::Run() {
  std::unique_ptr<storage::PgConnection> conn;
  while (true) {
    {
      MutexLock lock(mu_);
      if (stopping_) return;
    }
    if (conn == nullptr || !conn->healthy()) {
      conn.reset();
      Result<std::string> conninfo = storage::ReadConninfoFile(options_.credentials_path);
      Result<std::unique_ptr<storage::PgConnection>> opened =
          conninfo.ok() ? storage::PgConnection::Open(*conninfo)
                        : Result<std::unique_ptr<storage::PgConnection>>(conninfo.status());
      Status ready = opened.ok() ? storage::MigrateArchive(**opened) : opened.status();
      if (!ready.ok()) {
        SetState(conninfo.ok() ? FailureState(ready) : v1::ARCHIVE_STATE_REFUSED, ready.message());
        if (!Wait(options_.retry)) return;
        continue;
      }
      conn = std::move(*opened);
    }
    Result<storage::ShipBatch> batch = store_->NextShipBatch(options_.batch_readings, kMaxChanges);
    if (batch.ok()) {
      if (Status st = FillRoundSpends(*store_, options_.rig_description, *batch); !st.ok()) {
        batch = st;
      }
    }
    if (!batch.ok()) {
      SetState(v1::ARCHIVE_STATE_UNREACHABLE,
               "reading the rig's database: " + batch.status().message());
      if (!Wait(options_.retry)) return;
      continue;
    }
    if (batch->empty()) {
      SetState(v1::ARCHIVE_STATE_CAUGHT_UP, "");
      if (!Wait(options_.poll)) return;
      continue;
    }
    if (Status st = storage::WriteToArchive(*conn, options_.rig, *batch); !st.ok()) {
      conn.reset();  // whatever happened, start again on a fresh connection
      SetState(FailureState(st), st.message());
      if (!Wait(options_.retry)) return;
      continue;
    }
    if (Status st = store_->MarkShipped(*batch); !st.ok()) {
      // The archive has the batch; it will be sent again and change nothing.
      SetState(v1::ARCHIVE_STATE_SHIPPING, "recording the marks: " + st.message());
      if (!Wait(options_.retry)) return;
      continue;
    }
    {
      MutexLock lock(mu_);
      shipped_ += batch->readings.size();
      last_shipped_at_ = NowSeconds();
    }
    const bool full = static_cast<int>(batch->readings.size()) >= options_.batch_readings ||
                      static_cast<int>(batch->events.size()) >= options_.batch_readings;
    SetState(full ? v1::ARCHIVE_STATE_SHIPPING : v1::ARCHIVE_STATE_CAUGHT_UP, "");
  }
}

v1::ArchiveStatus ArchiveShipper::Snapshot() const {
  v1::ArchiveStatus s;
  {
    MutexLock lock(mu_);
    s.set_state(state_);
    s.set_detail(detail_);
    s.set_shipped_readings(shipped_);
    if (last_shipped_at_ > 0) *s.mutable_last_shipped_at() = ToTimestamp(last_shipped_at_);
  }
  if (Result<storage::ShipLag> lag = store_->ShippingLag(); lag.ok()) {
    s.set_lag_readings(static_cast<std::uint64_t>(lag->readings));
    if (lag->readings > 0) s.set_lag_seconds(std::max(0.0, NowSeconds() - lag->oldest_unshipped));
    if (s.state() == v1::ARCHIVE_STATE_CAUGHT_UP &&
        (lag->readings > 0 || lag->pending_changes > 0 || lag->events > 0)) {
      s.set_state(v1::ARCHIVE_STATE_SHIPPING);
    }
  }
  return s;
}

}  // namespace brdf::daemon
