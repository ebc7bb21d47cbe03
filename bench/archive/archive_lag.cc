// bench_archive_lag: how far the lab archive trails the rig while a session records.
//
// A real PostgreSQL (tests/support/pg/server.h, Debian's server in a temporary directory) and a
// real SQLite file; readings are committed through SessionStore::CompleteStepWithReading at a
// steady pace while the daemon's ArchiveShipper runs. Lag of a reading = when the archive's
// transaction holding it began (readings.archived_at, PostgreSQL's now()) − when the rig committed
// it (recorded_at); same machine, same clock. Baseline measured in the same run: the rig's own
// commit time per reading (the fsync'd SQLite transaction). Medians and p99 are printed, and the
// ratio of the lag's median to the commit's median.
//
// Then the catalogue at lab scale: --sessions sessions with --readings readings in all, generated
// inside PostgreSQL (generate_series), and the ListSessions-style catalogue query (filter by
// material and tag, newest first, a page of 100) timed --queries times: p50 and p99, against the
// same query without a filter as the baseline (SQL over libpq). Then the same through a
// brdf-archive server (daemon/api/server.h over daemon/archive/back_end.h, in this process, over
// gRPC on a loopback port):
// ListSessions with the filter against ListSessions without one, and the first Interpolate on a
// cold session (its 1,000 readings read from PostgreSQL, the index built) against the next
// Interpolate on the same session (warm), each over --cold sessions. Last, InterpolateBatch
// throughput of two clients on one brdf-archive against two clients on two replicas, with one
// client alone as the baseline.
#include <grpcpp/create_channel.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <vector>

#include "brdf/v1/brdf.grpc.pb.h"
#include "daemon/api/server.h"
#include "daemon/archive/back_end.h"
#include "daemon/engine/shipper.h"
#include "daemon/rpc/auth.h"
#include "storage/archive/pg.h"
#include "storage/archive/reader.h"
#include "storage/archive/schema.h"
#include "storage/session_store.h"
#include "tests/support/pg/server.h"

namespace {

using namespace std::chrono_literals;
using brdf::Result;
using brdf::Status;
namespace storage = brdf::storage;

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  return v[i];
}

double Ms(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

int Fail(const std::string& what, const Status& st) {
  std::fprintf(stderr, "bench_archive_lag: %s: %s\n", what.c_str(), st.ToString().c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("lag of the lab archive behind the rig, and the catalogue query at lab scale");
  int readings = 2000;
  int pace_ms = 5;
  int sessions = 1000;
  long total_readings = 1000000;
  int queries = 200;
  int cold = 10;
  app.add_option("--lag-readings", readings, "readings recorded while shipping");
  app.add_option("--pace-ms", pace_ms, "pause between readings (ms)");
  app.add_option("--sessions", sessions, "catalogue: sessions in the archive");
  app.add_option("--readings", total_readings, "catalogue: readings in the archive (0: skip)");
  app.add_option("--queries", queries, "catalogue: queries timed");
  app.add_option("--cold", cold, "brdf-archive: cold sessions interpolated");
  int batch = 4096;
  int batch_calls = 5;
  int rounds = 3;
  app.add_option("--batch", batch, "InterpolateBatch: directions per call");
  app.add_option("--batch-calls", batch_calls, "InterpolateBatch: calls per client and round");
  app.add_option("--rounds", rounds, "InterpolateBatch: rounds (medians)");
  CLI11_PARSE(app, argc, argv);

  if (std::string why = brdf::testing::PgServer::Unavailable(); !why.empty()) {
    std::fprintf(stderr, "bench_archive_lag: %s\n", why.c_str());
    return 2;
  }
  Result<std::unique_ptr<brdf::testing::PgServer>> pg = brdf::testing::PgServer::Start();
  if (!pg.ok()) return Fail("starting PostgreSQL", pg.status());
  const std::string dir = (*pg)->dir();

  // --- Lag while a session records ---------------------------------------------------------
  char tmpl[] = "/tmp/brdf-lag-XXXXXX";
  if (::mkdtemp(tmpl) == nullptr) return 1;
  const std::string work = tmpl;
  Result<std::unique_ptr<storage::SessionStore>> opened =
      storage::SessionStore::Open(work + "/rig.db");
  if (!opened.ok()) return Fail("opening the rig's database", opened.status());
  std::shared_ptr<storage::SessionStore> store = std::move(*opened);
  Result<std::string> cred =
      brdf::testing::PgServer::WriteCredentials(work + "/archive.conninfo", (*pg)->conninfo());
  brdf::daemon::ArchiveShipper::Options o;
  o.credentials_path = *cred;
  o.rig = "bench-rig";
  Result<std::unique_ptr<brdf::daemon::ArchiveShipper>> shipper =
      brdf::daemon::ArchiveShipper::Start(store, o);
  if (!shipper.ok()) return Fail("starting the shipper", shipper.status());

  storage::NewSession n;
  n.name = "lag";
  n.plan_kind = "pose_list";
  n.plan_json = "{}";
  n.rig = "bench-rig";
  std::vector<storage::StepRecord> steps(static_cast<std::size_t>(readings));
  for (int i = 0; i < readings; ++i) {
    steps[i].step_index = i;
    steps[i].kind = storage::StepKind::kSample;
    steps[i].target = brdf::Directions{10, 0, 20, 90};
  }
  Result<std::int64_t> id = store->CreateSession(n, steps);
  if (!id.ok()) return Fail("creating the session", id.status());
  if (Status st = store->SetSessionState(*id, brdf::SessionState::kRunning, ""); !st.ok()) {
    return Fail("starting the session", st);
  }
  std::vector<double> commit_ms;
  for (int i = 0; i < readings; ++i) {
    storage::ReadingRecord r;
    r.kind = brdf::ReadingKind::kSample;
    r.directions = brdf::Directions{10, 0, 20, 90};
    r.grid = brdf::WavelengthGrid::Pr650();
    r.spectrum.assign(r.grid.count, 1e-3 * (i + 1));
    const auto t0 = std::chrono::steady_clock::now();
    Result<std::int64_t> rid = store->CompleteStepWithReading(*id, i, r);
    commit_ms.push_back(Ms(std::chrono::steady_clock::now() - t0));
    if (!rid.ok()) return Fail("recording", rid.status());
    std::this_thread::sleep_for(std::chrono::milliseconds(pace_ms));
  }
  const auto deadline = std::chrono::steady_clock::now() + 120s;
  while ((*shipper)->Snapshot().lag_readings() > 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  (*shipper)->Stop();
  Result<std::unique_ptr<storage::PgConnection>> conn =
      storage::PgConnection::Open((*pg)->conninfo());
  if (!conn.ok()) return Fail("connecting", conn.status());
  Result<storage::PgResult> lags =
      (*conn)->Query("SELECT (extract(epoch FROM archived_at) - recorded_at) * 1000 FROM readings");
  if (!lags.ok()) return Fail("reading the lags", lags.status());
  std::vector<double> lag_ms;
  for (int i = 0; i < lags->rows(); ++i) lag_ms.push_back(lags->Double(i, 0));
  std::printf(
      "archive lag while recording (%d readings, one every %d ms + commit; shipper polls "
      "every %lld ms, batches of %d)\n",
      readings, pace_ms, static_cast<long long>(o.poll.count()), o.batch_readings);
  std::printf("  readings in the archive      %zu of %d\n", lag_ms.size(), readings);
  std::printf("  lag p50 / p99 / max          %.2f / %.2f / %.2f ms\n", Quantile(lag_ms, 0.5),
              Quantile(lag_ms, 0.99), Quantile(lag_ms, 1.0));
  std::printf("  rig commit p50 / p99         %.2f / %.2f ms (baseline)\n",
              Quantile(commit_ms, 0.5), Quantile(commit_ms, 0.99));
  std::printf("  lag p50 / commit p50         %.1f\n",
              Quantile(lag_ms, 0.5) / std::max(1e-9, Quantile(commit_ms, 0.5)));
  std::filesystem::remove_all(work);

  // --- The catalogue at lab scale ------------------------------------------------------------
  if (total_readings <= 0) return 0;
  const long per_session = std::max(1L, total_readings / sessions);
  const auto g0 = std::chrono::steady_clock::now();
  const std::string fill =
      "INSERT INTO sessions (uuid, rig, rig_session_id, name, plan_kind, plan_json, state, "
      "created_at, total_steps, done_steps, sample_id, sample_name, material, tags) "
      "SELECT gen_random_uuid(), 'rig-' || (s % 4), s, 'session ' || s, 'pose_list', '{}', "
      "'completed', 1.7e9 + s * 60, " +
      std::to_string(per_session) + ", " + std::to_string(per_session) +
      ", 'P-' || (s % 300), 'sample ' || (s % 300), "
      "(ARRAY['paint','fabric','metal','paper','plastic'])[1 + s % 5], "
      "ARRAY[(ARRAY['glossy','matte','red','blue','rough','smooth'])[1 + s % 6], "
      "(ARRAY['glossy','matte','red','blue','rough','smooth'])[1 + (s / 6) % 6]] "
      "FROM generate_series(1, " +
      std::to_string(sessions) +
      ") s;"
      "INSERT INTO steps (session_uuid, step_index, kind, alpha, beta, gamma, delta, state) "
      "SELECT uuid, i, 'sample', 0, 0, 0, 0, 'done' FROM sessions, generate_series(0, " +
      std::to_string(per_session - 1) +
      ") i WHERE rig_session_id > 0;"
      "INSERT INTO readings (session_uuid, step_index, rig_reading_id, kind, alpha, beta, gamma, "
      "delta, theta_i, phi_i, theta_o, phi_o, wl_start_nm, wl_step_nm, wl_count, spectrum, "
      "recorded_at) SELECT session_uuid, step_index, step_index + 1, 'sample', 0, 0, 0, 0, "
      "5 + (step_index % 8) * 10, 0, 5 + (step_index / 8 % 9) * 10, "
      "(step_index / 72 % 19) * 10 - 90, 380, 4, 101, "
      "decode(repeat('0000000000000040', 101), 'hex'), 1.7e9 "
      "FROM steps WHERE step_index >= 0 AND session_uuid IN "
      "(SELECT uuid FROM sessions WHERE rig <> 'bench-rig'); ANALYZE;";
  if (Status st = (*conn)->Exec("DELETE FROM readings; DELETE FROM steps; DELETE FROM sessions;");
      !st.ok()) {
    return Fail("clearing", st);
  }
  if (Status st = (*conn)->Exec(fill); !st.ok()) return Fail("filling the catalogue", st);
  Result<storage::PgResult> counts = (*conn)->Query(
      "SELECT (SELECT count(*) FROM sessions), (SELECT count(*) FROM readings), "
      "pg_size_pretty(pg_database_size(current_database()))");
  std::printf("catalogue: %s sessions, %s readings (%s), generated in %.1f s\n",
              std::string(counts->Text(0, 0)).c_str(), std::string(counts->Text(0, 1)).c_str(),
              std::string(counts->Text(0, 2)).c_str(),
              Ms(std::chrono::steady_clock::now() - g0) / 1000);
  auto time_query = [&](const std::string& sql, storage::PgParams params) {
    std::vector<double> ms;
    for (int q = 0; q < queries; ++q) {
      const auto t0 = std::chrono::steady_clock::now();
      Result<storage::PgResult> r = (*conn)->Query(sql, params);
      ms.push_back(Ms(std::chrono::steady_clock::now() - t0));
      if (!r.ok()) {
        std::fprintf(stderr, "%s\n", r.status().ToString().c_str());
        return std::vector<double>{};
      }
    }
    return ms;
  };
  const std::string page = " ORDER BY created_at DESC, uuid LIMIT 100";
  const std::string columns =
      "SELECT s.uuid, s.rig, s.name, s.state, s.created_at, s.total_steps, s.done_steps, "
      "s.sample_id, s.sample_name, s.material, s.tags FROM sessions s";
  std::vector<double> filtered = time_query(
      columns + " WHERE lower(material) = lower($1) AND $2 = ANY (tags) AND rig = $3" + page,
      storage::PgParams().Add("paint").Add("glossy").Add("rig-0"));
  std::vector<double> plain = time_query(columns + page, storage::PgParams());
  std::printf(
      "  catalogue query (material + tag + rig, page of 100), %d times: p50 %.3f ms, "
      "p99 %.3f ms\n",
      queries, Quantile(filtered, 0.5), Quantile(filtered, 0.99));
  std::printf(
      "  baseline: first page without a filter: p50 %.3f ms, p99 %.3f ms; ratio of "
      "medians %.2f\n",
      Quantile(plain, 0.5), Quantile(plain, 0.99),
      Quantile(filtered, 0.5) / std::max(1e-9, Quantile(plain, 0.5)));

  // --- The same through brdf-archive ----------------------------------------------------------
  Result<std::shared_ptr<storage::ArchiveReader>> reader =
      storage::ArchiveReader::Open((*pg)->conninfo());
  if (!reader.ok()) return Fail("opening the archive", reader.status());
  brdf::daemon::ServerConfig server_config;
  server_config.listen = "127.0.0.1:0";
  brdf::daemon::Authenticator auth({});
  brdf::daemon::ArchiveBackEnd back_end(*reader);
  Result<std::unique_ptr<brdf::daemon::Server>> server =
      brdf::daemon::Server::Start(server_config, back_end.Served(), auth);
  if (!server.ok()) return Fail("starting brdf-archive", server.status());
  auto channel = grpc::CreateChannel((*server)->address(), grpc::InsecureChannelCredentials());
  auto control = brdf::v1::Control::NewStub(channel);
  auto interpolation = brdf::v1::Interpolation::NewStub(channel);
  auto time_list = [&](const brdf::v1::ListSessionsRequest& request) {
    std::vector<double> ms;
    for (int q = 0; q < queries; ++q) {
      grpc::ClientContext context;
      brdf::v1::ListSessionsResponse response;
      const auto t0 = std::chrono::steady_clock::now();
      grpc::Status st = control->ListSessions(&context, request, &response);
      ms.push_back(Ms(std::chrono::steady_clock::now() - t0));
      if (!st.ok()) std::fprintf(stderr, "ListSessions: %s\n", st.error_message().c_str());
    }
    return ms;
  };
  brdf::v1::ListSessionsRequest filter;
  filter.set_material("paint");
  filter.set_tag("glossy");
  filter.set_rig("rig-0");
  const std::vector<double> listed = time_list(filter);
  const std::vector<double> all = time_list(brdf::v1::ListSessionsRequest());
  std::printf("brdf-archive on %s:\n", (*server)->address().c_str());
  std::printf(
      "  ListSessions (material + tag + rig), %d times: p50 %.3f ms, p99 %.3f ms\n"
      "  baseline: ListSessions without a filter (a page of 100): p50 %.3f ms, p99 %.3f ms; "
      "ratio of medians %.2f\n",
      queries, Quantile(listed, 0.5), Quantile(listed, 0.99), Quantile(all, 0.5),
      Quantile(all, 0.99), Quantile(listed, 0.5) / std::max(1e-9, Quantile(all, 0.5)));
  brdf::v1::ListSessionsRequest some;
  some.set_page_size(static_cast<std::uint32_t>(cold));
  brdf::v1::ListSessionsResponse sessions_page;
  {
    grpc::ClientContext context;
    if (!control->ListSessions(&context, some, &sessions_page).ok()) return 1;
  }
  std::vector<double> first_ms, warm_ms;
  int answered = 0;
  for (const brdf::v1::Session& s : sessions_page.sessions()) {
    brdf::v1::InterpolateRequest request;
    request.set_session_id(s.session_id());
    request.set_quantity(brdf::v1::QUANTITY_RADIANCE);
    request.mutable_direction()->mutable_iso()->set_theta_i(33);
    request.mutable_direction()->mutable_iso()->set_theta_o(41);
    request.mutable_direction()->mutable_iso()->set_phi(57);
    for (std::vector<double>* into : {&first_ms, &warm_ms}) {
      grpc::ClientContext context;
      brdf::v1::InterpolateResponse response;
      const auto t0 = std::chrono::steady_clock::now();
      grpc::Status st = interpolation->Interpolate(&context, request, &response);
      into->push_back(Ms(std::chrono::steady_clock::now() - t0));
      if (st.ok() && into == &first_ms) ++answered;
      if (!st.ok() && into == &first_ms) {
        std::fprintf(stderr, "Interpolate: %s\n", st.error_message().c_str());
      }
    }
  }
  std::printf(
      "  first Interpolate on a cold session (%zu sessions of %ld readings, %d answered): "
      "p50 %.1f ms, max %.1f ms\n"
      "  baseline: the next Interpolate on the same session (warm): p50 %.3f ms; ratio of "
      "medians %.0f\n",
      first_ms.size(), per_session, answered, Quantile(first_ms, 0.5), Quantile(first_ms, 1.0),
      Quantile(warm_ms, 0.5), Quantile(first_ms, 0.5) / std::max(1e-9, Quantile(warm_ms, 0.5)));

  // --- InterpolateBatch throughput, one replica and two ----------------------------------------
  // Two clients, each sending --batch-calls InterpolateBatch calls of --batch directions on one
  // session (warm on every replica first). One replica: both clients on the first server; two
  // replicas: one client each, on two brdf-archive servers over the same PostgreSQL (stateless,
  // each with its own reader and cache). Baseline in the same run: one client alone on one
  // replica. Rounds alternate the three layouts; medians of --rounds rounds.
  if (sessions_page.sessions().empty()) return 0;
  Result<std::shared_ptr<storage::ArchiveReader>> reader_b =
      storage::ArchiveReader::Open((*pg)->conninfo());
  if (!reader_b.ok()) return Fail("opening the archive for the second replica", reader_b.status());
  brdf::daemon::ArchiveBackEnd back_end_b(*reader_b);
  Result<std::unique_ptr<brdf::daemon::Server>> server_b =
      brdf::daemon::Server::Start(server_config, back_end_b.Served(), auth);
  if (!server_b.ok()) return Fail("starting the second brdf-archive", server_b.status());
  brdf::v1::InterpolateBatchRequest batch_request;
  batch_request.set_session_id(sessions_page.sessions(0).session_id());
  batch_request.set_quantity(brdf::v1::QUANTITY_RADIANCE);
  batch_request.set_chunk_size(1024);
  for (int i = 0; i < batch; ++i) {  // a fixed spread over the readings' range (θi, θo, φ)
    brdf::v1::IsoDirection* d = batch_request.add_directions()->mutable_iso();
    d->set_theta_i(10 + (i * 37 % 600) / 10.0);
    d->set_theta_o(10 + (i * 53 % 700) / 10.0);
    d->set_phi(std::fabs(-80 + (i * 71 % 1600) / 10.0));  // φ in [0, 180]
  }
  auto stub_for = [](const std::string& address) {
    return brdf::v1::Interpolation::NewStub(
        grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  };
  double ok_share = 0;  // of the last layout run: results with a spectrum (status OK)
  // Each client its own channel, so two clients on one replica are two connections.
  auto run_clients = [&](const std::vector<std::string>& addresses, int calls) -> double {
    std::vector<std::thread> clients;
    std::atomic<long> results{0};
    std::atomic<long> spectra{0};
    const auto t0 = std::chrono::steady_clock::now();
    for (const std::string& address : addresses) {
      clients.emplace_back([&, address] {
        auto stub = stub_for(address);
        for (int c = 0; c < calls; ++c) {
          grpc::ClientContext context;
          auto stream = stub->InterpolateBatch(&context, batch_request);
          brdf::v1::InterpolateBatchChunk chunk;
          while (stream->Read(&chunk)) {
            results += chunk.results_size();
            for (const brdf::v1::InterpolationResult& one : chunk.results()) {
              if (one.status() == brdf::v1::INTERPOLATION_STATUS_OK) ++spectra;
            }
          }
          if (grpc::Status st = stream->Finish(); !st.ok()) {
            std::fprintf(stderr, "InterpolateBatch: %s\n", st.error_message().c_str());
          }
        }
      });
    }
    for (std::thread& t : clients) t.join();
    const double seconds = Ms(std::chrono::steady_clock::now() - t0) / 1000;
    ok_share = static_cast<double>(spectra.load()) / std::max(1L, results.load());
    return results.load() / std::max(1e-9, seconds);
  };
  const std::string a = (*server)->address(), b = (*server_b)->address();
  run_clients({a, b}, 1);  // warm both replicas' caches (the cold load is measured above)
  std::vector<double> alone, one_replica, two_replicas;
  for (int r = 0; r < rounds; ++r) {
    alone.push_back(run_clients({a}, batch_calls));
    one_replica.push_back(run_clients({a, a}, batch_calls));
    two_replicas.push_back(run_clients({a, b}, batch_calls));
  }
  std::printf(
      "InterpolateBatch throughput (%d directions per call, %.0f %% answered with a spectrum, %d "
      "calls per client, %d rounds, medians):\n"
      "  two clients, one replica:    %.0f directions/s\n"
      "  two clients, two replicas:   %.0f directions/s (ratio to one replica %.2f)\n"
      "  baseline: one client alone:  %.0f directions/s (one replica, two clients / alone "
      "%.2f)\n"
      "  (both replicas run in this process on this machine's %u cores: the ratio shows what a\n"
      "   second replica adds when the cores are shared, not two machines' worth)\n",
      batch, 100 * ok_share, batch_calls, rounds, Quantile(one_replica, 0.5),
      Quantile(two_replicas, 0.5),
      Quantile(two_replicas, 0.5) / std::max(1e-9, Quantile(one_replica, 0.5)),
      Quantile(alone, 0.5), Quantile(one_replica, 0.5) / std::max(1e-9, Quantile(alone, 0.5)),
      std::thread::hardware_concurrency());
  (*server_b)->Shutdown(std::chrono::seconds(1));
  (*server)->Shutdown(std::chrono::seconds(1));
  (void)dir;
  return 0;
}
