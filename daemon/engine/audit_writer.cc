#include "daemon/engine/audit_writer.h"

#include <spdlog/spdlog.h>

#include <string>
#include <utility>

namespace brdf::daemon {

AuditWriter::AuditWriter(storage::SessionStore& store, std::function<storage::UnixSeconds()> now)
    : store_(store), now_(std::move(now)) {
  thread_ = std::thread([this] { Run(); });
}

AuditWriter::~AuditWriter() {
  {
    MutexLock lock(mu_);
    stopping_ = true;
  }
  cv_.NotifyAll();
  if (thread_.joinable()) thread_.join();
}

void AuditWriter::Write(storage::AuditRecord record) {
  Drain();  // records stay in the order of the calls
  Append(std::move(record));
}

void AuditWriter::Append(storage::AuditRecord record) {
  Status st = store_.AppendAudit(record);
  if (!st.ok() && record.session_id.has_value()) {  // e.g. no such session: keep it without
    record.detail = "session " + std::to_string(*record.session_id) + ": " + record.detail;
    record.session_id.reset();
    st = store_.AppendAudit(record);
  }
  if (!st.ok()) spdlog::warn("audit record {} not stored: {}", record.action, st.ToString());
}

void AuditWriter::WriteLater(storage::AuditRecord record) {
  if (record.at == 0) record.at = now_();
  {
    MutexLock lock(mu_);
    queue_.push_back(std::move(record));
  }
  cv_.NotifyAll();
}

void AuditWriter::Drain() {
  MutexLock lock(mu_);
  cv_.Wait(mu_, [this]() REQUIRES(mu_) { return queue_.empty() && !writing_; });
}

void AuditWriter::Run() {
  MutexLock lock(mu_);
  for (;;) {
    cv_.Wait(mu_, [this]() REQUIRES(mu_) { return !queue_.empty() || stopping_; });
    if (queue_.empty()) return;  // stopping, all written
    storage::AuditRecord record = std::move(queue_.front());
    queue_.pop_front();
    writing_ = true;
    lock.Unlock();
    Append(std::move(record));
    lock.Lock();
    writing_ = false;
    cv_.NotifyAll();  // Drain
  }
}

}  // namespace brdf::daemon
