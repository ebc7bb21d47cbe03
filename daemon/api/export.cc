// Data.Export (brdf.proto): a session exported to a file by core/export, streamed to the caller so
// that a remote client gets the file itself. The work runs on the handler's thread (and
// core/export's worker threads): the session is loaded from the store, the requested export is
// computed, and its bytes go out in ExportData chunks as the export writes them — a regular grid
// is streamed slice by slice and never sits in memory whole (a 1° grid of 101 bands is 1.2 GB).
// Progress messages are interleaved; a client that goes away, or the daemon stopping, cancels
// the export (its CancelToken) at the next progress report or chunk.
//
// The exports are the same code as brdf-export's (storage/session_readings.h: the session;
// data/cie_tables.h: the CIE tables; core/export: the formats;
// core/export/fill/session_interpolant.h: the interpolant behind the fill chain, and the RGL
// material), so a file from the daemon and one from the tool are the same bytes for the same
// session and options. Grids, MERL and RGL fill through the chain unless the request's fill is
// NONE, and the report counts each cell's provenance (ExportReport.fill).
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <streambuf>
#include <string>
#include <vector>

#include "core/call_context.h"
#include "core/export/fill/chain.h"
#include "core/export/fill/session_interpolant.h"
#include "core/export/fill/spectrum_source.h"
#include "core/export/fill/uncertain_chain.h"
#include "core/export/fill/uncertain_grid.h"
#include "core/export/fill/uncertainty_summary.h"
#include "core/export/grid/npy_writer.h"
#include "core/export/grid/regular_grid.h"
#include "core/export/grid/text.h"
#include "core/export/merl/writer.h"
#include "core/export/readings_csv.h"
#include "core/export/rgl/writer.h"
#include "core/export/run_control.h"
#include "core/export/session_data.h"
#include "core/export/spectral_rgb.h"
#include "core/session_state.h"
#include "daemon/api/export_bird.h"
#include "daemon/api/export_cache.h"
#include "daemon/api/export_loads.h"
#include "daemon/api/export_session.h"
#include "daemon/api/export_wire.h"
#include "data/cie_tables.h"
#include "storage/session_readings.h"

namespace brdf::daemon {
namespace {

// ExportRequest.chunk_bytes: default and largest (a chunk must stay under a client's default
// 4 MiB receive limit together with its framing). The default is small (issue 40): an export
// whose client reads nothing waits in a write holding one chunk once the client's window is full
// (the message and its serialized copy until issue 41 built the message in place, export_wire.h);
// at 1 MiB, 60 of the bench's 100 unread exports held ~2 MB each so on a quiet machine. A client
// that wants larger messages asks for them.
constexpr std::uint32_t kDefaultExportChunkBytes = 128 * 1024;
constexpr std::uint32_t kMaxExportChunkBytes = 4 * 1024 * 1024 - 1024;
// The most bands a session holds: the CS-2000/3000's 380–780 nm every 1 nm
// (docs/cs2000-protocol.md).
constexpr std::size_t kMostBands = 401;
// Exports have no deadline of their own beyond the client's; this caps a client without one.
constexpr std::chrono::hours kLongestExport{24};
// The first data message holds at most this much; each one the client takes doubles the next, up
// to the request's chunk_bytes. A client that never reads so leaves at most this much waiting in
// brdfd, not a whole chunk_bytes (issue 40).
constexpr std::size_t kFirstExportChunkBytes = 32 * 1024;
// A progress message goes out when the fraction moved by this much (or the stage changed).
constexpr double kProgressStep = 0.005;
// RGL: the largest θi slice count and warped-square resolution a request may ask (the file is
// built in memory: 4 · slices · nodes² · bands bytes of spectra).
constexpr std::uint32_t kMaxRglThetaI = 90;
constexpr std::uint32_t kMaxRglResolution = 128;

// The stream of one Export call: progress messages, the file's bytes in chunks of at most
// `chunk_bytes`, the report. Used from the handler's thread only (core/export calls progress on
// its calling thread). A failed Write means the client went away: the export is cancelled.
class ExportStream {
 public:
  ExportStream(grpc::ServerContext& context, ExportWriter& writer, StreamRegistry::Slot& slot,
               const StopSignal& stopping, std::size_t chunk_bytes, CancelToken cancel)
      : context_(context),
        writer_(writer),
        slot_(slot),
        stopping_(stopping),
        chunk_bytes_(chunk_bytes),
        next_chunk_bytes_(std::min(chunk_bytes, kFirstExportChunkBytes)),
        cancel_(std::move(cancel)) {}

  void Progress(const std::string& stage, double fraction) {
    CheckCancelled();
    fraction = std::clamp(fraction, last_fraction_, 1.0);
    if (stage == last_stage_ && fraction < last_fraction_ + kProgressStep && fraction < 1.0) {
      return;
    }
    if (stage == last_stage_ && fraction == last_fraction_ && fraction > 0) return;
    last_stage_ = stage;
    last_fraction_ = fraction;
    v1::ExportChunk chunk;
    chunk.mutable_progress()->set_stage(stage);
    chunk.mutable_progress()->set_fraction(fraction);
    Send(chunk);
  }

  // Buffers `n` bytes of the file (part "") or of a companion part (ExportData.part), sending
  // full chunks. False once the stream is broken.
  bool Append(const std::string& part, const char* data, std::size_t n) {
    CheckCancelled();
    Part& p = parts_.try_emplace(part, part).first->second;
    while (n > 0 && !broken_) {
      if (p.message.capacity() == 0) p.message.Reset(next_chunk_bytes_);
      const std::size_t took = p.message.Append(data, n);
      data += took;
      n -= took;
      if (p.message.full()) SendBuffer(p);
    }
    return !broken_;
  }

  // Sends what is buffered, of every part. False once the stream is broken.
  bool Flush() {
    for (auto& [name, p] : parts_) {
      if (p.message.size() > 0 && !broken_) SendBuffer(p);
    }
    return !broken_;
  }

  // Sends the report with the file's size and each of its parts' (report.parts by name).
  bool SendReport(v1::ExportReport report) {
    if (!Flush()) return false;
    report.set_bytes(SentOf(""));
    for (v1::ExportPart& part : *report.mutable_parts()) part.set_bytes(SentOf(part.name()));
    v1::ExportChunk chunk;
    *chunk.mutable_report() = std::move(report);
    Send(chunk);
    return !broken_;
  }

  bool broken() const { return broken_; }

 private:
  struct Part {
    explicit Part(const std::string& name) : message(name) {}
    ExportDataMessage message;  // the next data message, being filled
    std::uint64_t offset = 0;   // bytes sent
  };

  std::uint64_t SentOf(const std::string& part) const {
    const auto it = parts_.find(part);
    return it == parts_.end() ? 0 : it->second.offset;
  }

  void CheckCancelled() {
    if (cancel_.cancelled()) return;
    if (broken_ || context_.IsCancelled()) {
      cancel_.Cancel("Export: the client went away");
    } else if (stopping_.stopped()) {
      cancel_.Cancel("Export: the daemon is shutting down; ask again once it is back");
    }
  }

  // The message's bytes go to gRPC as they are (export_wire.h: no serialization copy, none kept
  // here while the write waits), and the next chunk may be twice as large once this one was
  // taken. gRPC frees the message once it is sent; the next chunk's buffer is allocated when the
  // export appends again, after the wait for its next work permit (Send).
  void SendBuffer(Part& p) {
    const std::uint64_t offset = p.offset;
    p.offset += p.message.size();
    grpc::ByteBuffer message = p.message.Take(offset);
    Write(&message);
    next_chunk_bytes_ = std::min(chunk_bytes_, 2 * next_chunk_bytes_);
  }

  void Send(const v1::ExportChunk& chunk) {
    grpc::ByteBuffer message = SerializeExportChunk(chunk);
    Write(&message);
  }

  // `message` is emptied before the wait for a work permit (Slot::WriteAndRelease): a hundred
  // exports waiting their turn then hold no chunk each (issue 40: up to chunk_bytes apiece).
  void Write(grpc::ByteBuffer* message) {
    if (broken_) return;
    if (!slot_.WriteAndRelease(&writer_, message)) {
      broken_ = true;
      CheckCancelled();
    }
  }

  grpc::ServerContext& context_;
  ExportWriter& writer_;
  StreamRegistry::Slot& slot_;
  const StopSignal& stopping_;
  const std::size_t chunk_bytes_;
  std::size_t next_chunk_bytes_;  // the next data message's size, ≤ chunk_bytes_
  CancelToken cancel_;
  std::map<std::string, Part> parts_;  // "": the file
  bool broken_ = false;
  std::string last_stage_;
  double last_fraction_ = 0;
};

// An ostream's buffer that hands everything to an ExportStream, so that core/export's writers
// (which take a std::ostream) stream straight to the client. A broken stream makes the writes
// fail, which the writers report as kIoError.
class ExportStreamBuf : public std::streambuf {
 public:
  // `part`: "" for the file, else the companion part it writes (ExportData.part).
  explicit ExportStreamBuf(ExportStream& stream, std::string part = "")
      : stream_(stream), part_(std::move(part)) {}

 protected:
  int_type overflow(int_type ch) override {
    if (traits_type::eq_int_type(ch, traits_type::eof())) return traits_type::not_eof(ch);
    const char c = traits_type::to_char_type(ch);
    return stream_.Append(part_, &c, 1) ? ch : traits_type::eof();
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    return stream_.Append(part_, s, static_cast<std::size_t>(n)) ? n : 0;
  }
  int sync() override { return stream_.Flush() ? 0 : -1; }

 private:
  ExportStream& stream_;
  std::string part_;
};

// What the request asks for, checked.
struct ExportSettings {
  std::int64_t session_id = 0;
  v1::ExportFormat format = v1::EXPORT_FORMAT_UNSPECIFIED;
  exports::Quantity quantity = exports::Quantity::kBrdf;
  interp::Method method = interp::Method::kOctant;
  interp::Options options;
  double steps[3] = {1, 1, 1};
  bool nodes = false;
  bool exclude_flagged = false;
  std::size_t chunk_bytes = kDefaultExportChunkBytes;
  exports::FillPolicy fill = exports::FillPolicy::kChain;
  bool rgb = false;                // RGL
  bool float32 = false;            // grid .npy: '<f4'
  bool uncertainty = false;        // grid .npy, MERL, RGL: the cells' u as parts of the stream
  exports::SessionRglOptions rgl;  // RGL: θi slices and resolution (rgb weights added later)
  // Where BuildInterpolator finds the session's interpolants (set once the session is loaded).
  struct Interpolants {
    std::shared_ptr<const exports::Session> session;  // the copy the export holds
    SharedSessionLoads* loads = nullptr;              // its derived samples, shared
    ExportInterpolants* kept = nullptr;               // kept per snapshot (export_cache.h)
  } interpolants;
};

grpc::Status ParseFillField(v1::ExportFill fill, exports::FillPolicy* out) {
  switch (fill) {
    case v1::EXPORT_FILL_UNSPECIFIED:
    case v1::EXPORT_FILL_CHAIN:
      *out = exports::FillPolicy::kChain;
      return grpc::Status::OK;
    case v1::EXPORT_FILL_NONE:
      *out = exports::FillPolicy::kNone;
      return grpc::Status::OK;
    default:
      return InvalidField("fill", "give NONE or CHAIN, or leave it unset for the chain (got " +
                                      std::to_string(fill) + ")");
  }
}

grpc::Status ParseRglFields(const v1::ExportRequest& r, ExportSettings* out) {
  const bool rgl = r.format() == v1::EXPORT_FORMAT_RGL_BSDF;
  if (!rgl && (r.rgb() || r.rgl_theta_i_count() != 0 || r.rgl_resolution() != 0)) {
    return InvalidField(r.rgb()                      ? "rgb"
                        : r.rgl_theta_i_count() != 0 ? "rgl_theta_i_count"
                                                     : "rgl_resolution",
                        "is for RGL exports (format RGL_BSDF); leave it unset for this format");
  }
  out->rgb = r.rgb();
  if (r.rgl_theta_i_count() != 0) {
    if (r.rgl_theta_i_count() < 2 || r.rgl_theta_i_count() > kMaxRglThetaI) {
      return InvalidField("rgl_theta_i_count", "give 2 to " + std::to_string(kMaxRglThetaI) +
                                                   " θi slices, or 0 for 24 (got " +
                                                   std::to_string(r.rgl_theta_i_count()) + ")");
    }
    out->rgl.theta_i_count = r.rgl_theta_i_count();
  }
  if (r.rgl_resolution() != 0) {
    if (r.rgl_resolution() < 2 || r.rgl_resolution() > kMaxRglResolution) {
      return InvalidField("rgl_resolution", "give 2 to " + std::to_string(kMaxRglResolution) +
                                                " nodes per side, or 0 for 48 (got " +
                                                std::to_string(r.rgl_resolution()) + ")");
    }
    out->rgl.sample_res = r.rgl_resolution();
  }
  return grpc::Status::OK;
}

// A grid's steps, checked before the export starts streaming: a refusal then reaches the
// caller as the call's status (a browser's HTTP status), naming the request's field.
grpc::Status CheckGridSteps(const ExportSettings& s) {
  if (s.format != v1::EXPORT_FORMAT_GRID_NPY && s.format != v1::EXPORT_FORMAT_GRID_CSV) {
    return grpc::Status::OK;
  }
  static constexpr const char* kFields[3] = {"step_theta_i", "step_theta_o", "step_phi"};
  for (int k = 0; k < 3; ++k) {
    double alone[3] = {1.0, 1.0, 1.0};
    alone[k] = s.steps[k];
    Result<exports::RegularGrid> grid = exports::MakeRegularGrid(
        alone[0], alone[1], alone[2], exports::GridPlacement::kCellCentres);
    if (!grid.ok()) return InvalidField(kFields[k], grid.status().message());
  }
  return grpc::Status::OK;
}

grpc::Status ParseUncertaintyField(const v1::ExportRequest& r, ExportSettings* out) {
  out->uncertainty = r.include_uncertainty();
  if (!r.include_uncertainty() || r.format() == v1::EXPORT_FORMAT_GRID_NPY ||
      r.format() == v1::EXPORT_FORMAT_MERL_BINARY || r.format() == v1::EXPORT_FORMAT_RGL_BSDF) {
    return grpc::Status::OK;
  }
  return InvalidField("include_uncertainty",
                      "is for GRID_NPY, MERL_BINARY and RGL_BSDF; the readings CSV has its "
                      "u_<λ> columns and the BiRD file its uBRDF always, and a grid as CSV has no "
                      "room for it (export it as .npy); leave it unset");
}

grpc::Status ParseRequest(const v1::ExportRequest& r, ExportSettings* out) {
  Result<SessionId> id = ParseSessionId(r.session_id(), "session_id");
  if (!id.ok()) return ToGrpcStatus(id.status());
  out->session_id = static_cast<std::int64_t>(*id);
  switch (r.format()) {
    case v1::EXPORT_FORMAT_READINGS_CSV:
    case v1::EXPORT_FORMAT_GRID_NPY:
    case v1::EXPORT_FORMAT_GRID_CSV:
    case v1::EXPORT_FORMAT_MERL_BINARY:
    case v1::EXPORT_FORMAT_RGL_BSDF:
    case v1::EXPORT_FORMAT_BIRD_JSON:
      out->format = r.format();
      break;
    default:
      return InvalidField("format",
                          "give one of READINGS_CSV, GRID_NPY, GRID_CSV, MERL_BINARY, RGL_BSDF, "
                          "BIRD_JSON (got " +
                              std::to_string(r.format()) + ")");
  }
  if (grpc::Status st = ParseQuantityField(r.quantity(), &out->quantity); !st.ok()) return st;
  if (r.format() == v1::EXPORT_FORMAT_MERL_BINARY && out->quantity != exports::Quantity::kBrdf) {
    return InvalidField("quantity", "a MERL file holds the BRDF; leave quantity unset or BRDF");
  }
  if (r.format() == v1::EXPORT_FORMAT_RGL_BSDF && out->quantity != exports::Quantity::kBrdf) {
    return InvalidField("quantity", "an RGL file holds the BRDF; leave quantity unset or BRDF");
  }
  if (r.format() == v1::EXPORT_FORMAT_BIRD_JSON && out->quantity != exports::Quantity::kBrdf) {
    return InvalidField("quantity", "a BiRD file holds the BRDF; leave quantity unset or BRDF");
  }
  if (grpc::Status st = ParseFillField(r.fill(), &out->fill); !st.ok()) return st;
  if (grpc::Status st = ParseRglFields(r, out); !st.ok()) return st;
  if (r.float32() && r.format() != v1::EXPORT_FORMAT_GRID_NPY) {
    return InvalidField("float32",
                        "is for grids as .npy (format GRID_NPY): a MERL file is float64 by its "
                        "format, an RGL file float32 already, CSV text; leave it unset");
  }
  out->float32 = r.float32();
  if (grpc::Status st = ParseUncertaintyField(r, out); !st.ok()) return st;
  if (grpc::Status st = ParseMethodField(r.method(), &out->method); !st.ok()) return st;
  const v1::InterpolationOptions& o = r.options();
  if (o.axis_scale_size() != 0 && o.axis_scale_size() != 3) {
    return InvalidField("options.axis_scale",
                        "exports are isotropic: give 3 values (θi, θo, φ) or none, got " +
                            std::to_string(o.axis_scale_size()));
  }
  for (int i = 0; i < o.axis_scale_size(); ++i) {
    if (!std::isfinite(o.axis_scale(i)) || o.axis_scale(i) <= 0) {
      return InvalidField(
          "options.axis_scale[" + std::to_string(i) + "]",
          "must be a finite number > 0 (got " + std::to_string(o.axis_scale(i)) + ")");
    }
  }
  out->options.axis_scale.assign(o.axis_scale().begin(), o.axis_scale().end());
  out->options.mirror_phi = o.mirror_phi();
  out->options.reciprocity = o.reciprocity();
  if (grpc::Status st = ParseCoordinatesField(o.coordinates(), &out->options.coordinates);
      !st.ok()) {
    return st;
  }
  if (grpc::Status st = ParseTrendField(o.trend(), &out->options.trend); !st.ok()) return st;
  // 0 means the default 1°; MakeRegularGrid checks the rest and names the axis.
  const double steps[3] = {r.step_theta_i(), r.step_theta_o(), r.step_phi()};
  for (int k = 0; k < 3; ++k) out->steps[k] = steps[k] == 0 ? 1.0 : steps[k];
  if (grpc::Status st = CheckGridSteps(*out); !st.ok()) return st;
  out->nodes = r.grid_nodes();
  out->exclude_flagged = r.exclude_flagged();
  if (r.chunk_bytes() > kMaxExportChunkBytes) {
    return InvalidField("chunk_bytes", "at most " + std::to_string(kMaxExportChunkBytes) +
                                           " (got " + std::to_string(r.chunk_bytes()) +
                                           "); 0 means 128 KiB");
  }
  if (r.chunk_bytes() > 0) out->chunk_bytes = r.chunk_bytes();
  return grpc::Status::OK;
}

// The client's deadline (capped), with the export's own cancel token.
Result<CallContext> ExportContext(const grpc::ServerContext& context, CancelToken cancel) {
  const auto remaining = context.deadline() - std::chrono::system_clock::now();
  if (remaining <= std::chrono::system_clock::duration::zero()) {
    return Timeout("Export: the client's deadline passed before it started");
  }
  const auto timeout = std::min<std::chrono::steady_clock::duration>(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(remaining), kLongestExport);
  return CallContext::WithTimeout(timeout, std::move(cancel));
}

std::string FileName(const ExportSettings& s) {
  const std::string base = "session-" + std::to_string(s.session_id);
  const std::string q = exports::QuantityName(s.quantity);
  switch (s.format) {
    case v1::EXPORT_FORMAT_READINGS_CSV:
      return base + "-readings-" + q + ".csv";
    case v1::EXPORT_FORMAT_GRID_NPY:
      return base + "-grid-" + q + ".npy";
    case v1::EXPORT_FORMAT_GRID_CSV:
      return base + "-grid-" + q + ".csv";
    case v1::EXPORT_FORMAT_RGL_BSDF:
      return base + (s.rgb ? "-rgb" : "") + ".bsdf";
    case v1::EXPORT_FORMAT_BIRD_JSON:
      return base + "-bird.json";
    default:
      return base + ".binary";
  }
}

void AddSkipped(const std::vector<exports::SkippedReading>& skipped, v1::ExportReport* report) {
  report->set_skipped_readings(skipped.size());
  if (!skipped.empty()) report->set_first_skip_reason(skipped.front().reason);
}

// The session's interpolant over the derived quantity behind the fill chain (as brdf-export
// builds it: core/export/fill/session_interpolant.h), kept for the next export of this snapshot
// of the session with the same settings (export_cache.h), its derived samples shared with the
// exports of the same copy (export_loads.h).
Result<exports::SessionInterpolant> BuildInterpolator(const exports::Session& session,
                                                      exports::Quantity quantity,
                                                      const ExportSettings& s,
                                                      const CallContext& ctx) {
  const ExportSettings::Interpolants& from = s.interpolants;
  if (from.kept == nullptr || from.session.get() != &session) {
    BRDF_ASSIGN_OR_RETURN(exports::DerivedSamples derived,
                          exports::DeriveSamples(session, quantity, {s.exclude_flagged}));
    return exports::BuildSessionInterpolant(std::move(derived), s.method, s.options, s.fill, ctx);
  }
  const ExportInterpolants::Settings settings{quantity, s.method, s.options, s.fill,
                                              s.exclude_flagged};
  return from.kept->Get(from.session, settings, [&]() -> Result<exports::SessionInterpolant> {
    BRDF_ASSIGN_OR_RETURN(std::shared_ptr<const exports::DerivedSamples> derived,
                          from.loads->Derived(from.session, quantity, s.exclude_flagged));
    return exports::BuildSessionInterpolant(std::move(derived), s.method, s.options, s.fill, ctx);
  });
}

// The cell counts of a MERL or RGL table (unfilled: by the interpolation's why).
void AddTableCounts(std::size_t cells, std::size_t filled,
                    const std::map<interp::InterpStatus, std::size_t>& unfilled,
                    std::size_t below_horizon, std::size_t clamped, v1::ExportReport* report) {
  report->set_cells(cells);
  report->set_filled_cells(filled);
  std::size_t unfilled_total = 0;
  for (const auto& [status, count] : unfilled) {
    (*report->mutable_unfilled_by_status())[interp::InterpStatusName(status)] = count;
    unfilled_total += count;
  }
  report->set_unfilled_cells(unfilled_total);
  report->set_below_horizon_cells(below_horizon);
  report->set_clamped_cells(clamped);
}

void AddFill(const exports::FillTally& tally, v1::ExportReport* report) {
  v1::ExportFillCounts* fill = report->mutable_fill();
  fill->set_policy(exports::FillPolicyName(tally.policy));
  fill->set_interpolated(tally.interpolated);
  fill->set_fallback(tally.fallback);
  fill->set_model(tally.model);
  fill->set_empty(tally.empty);
  fill->set_model_fraction(tally.model_fraction());
}

// Each export writes its file to `out` (through the stream) and fills the report; progress runs
// from `base` to 1 across the export's own work.
// Reflectance and BRDF from the derivation the exports of this copy of the session share
// (export_loads.h); radiance straight from the readings.
Status ExportReadingsCsv(const std::shared_ptr<const exports::Session>& session,
                         const ExportSettings& s, SharedSessionLoads& loads, ExportStream& stream,
                         std::ostream& out, v1::ExportReport* report) {
  stream.Progress("writing readings", 0.1);
  Result<exports::ReadingsCsvReport> csv = Internal("unset");
  if (s.quantity == exports::Quantity::kRadiance) {
    csv = exports::WriteReadingsCsv(*session, s.quantity, out, {s.exclude_flagged});
  } else {
    Result<std::shared_ptr<const exports::DerivedSamples>> derived =
        loads.Derived(session, s.quantity, s.exclude_flagged);
    if (!derived.ok()) return derived.status();
    csv = exports::WriteDerivedReadingsCsv(*session, s.quantity, **derived, out);
  }
  if (!csv.ok()) return csv.status();
  report->set_rows(csv->rows);
  AddSkipped(csv->skipped, report);
  report->set_summary(std::to_string(csv->rows) + " rows (" + exports::QuantityName(s.quantity) +
                      "), " + std::to_string(csv->skipped.size()) + " sample readings left out");
  return Status();
}

// The grid's uncertainty arrays (include_uncertainty): one .npy writer per array
// (exports::kUncertaintyArrays), each streamed as a part of its own (ExportData.part "u",
// "u_measurement", "u_interpolation").
class GridUncertaintyParts {
 public:
  GridUncertaintyParts(ExportStream& stream, const std::string& file, exports::NpyType type)
      : files_(exports::UncertaintyFiles(file)) {
    for (std::size_t i = 0; i < files_.size(); ++i) {
      buffers_[i] = std::make_unique<ExportStreamBuf>(
          stream, exports::UncertainPlaneName(exports::kUncertaintyArrays[i]));
      outs_[i] = std::make_unique<std::ostream>(buffers_[i].get());
      writers_[i] = std::make_unique<exports::NpyGridWriter>(*outs_[i], type);
    }
  }
  std::array<exports::GridSink*, 3> Sinks() const {
    return {writers_[0].get(), writers_[1].get(), writers_[2].get()};
  }
  // Each part in the report (its bytes are set as the report is sent).
  void AddTo(v1::ExportReport* report) const {
    for (const exports::UncertaintyFile& f : files_) {
      v1::ExportPart* part = report->add_parts();
      part->set_name(exports::UncertainPlaneName(f.plane));
      part->set_file_name(f.file_name);
    }
  }

 private:
  std::vector<exports::UncertaintyFile> files_;
  std::array<std::unique_ptr<ExportStreamBuf>, 3> buffers_;
  std::array<std::unique_ptr<std::ostream>, 3> outs_;
  std::array<std::unique_ptr<exports::NpyGridWriter>, 3> writers_;
};

void AddGridCounts(const exports::GridReport& r, v1::ExportReport* report) {
  report->set_summary(r.Summary());
  report->set_cells(r.cells);
  report->set_filled_cells(r.filled);
  report->set_unfilled_cells(r.nan_cells);
  for (const auto& [status, count] : r.by_status) {
    if (status != interp::InterpStatus::kOk) {
      (*report->mutable_unfilled_by_status())[interp::InterpStatusName(status)] = count;
    }
  }
}

// A grid as .npy or CSV; with include_uncertainty (.npy only) the same pass through the
// uncertain fill chain also streams the three uncertainty arrays (fill/uncertain_grid.h).
Status ExportGrid(const exports::Session& session, const ExportSettings& s, const CallContext& ctx,
                  ExportStream& stream, std::ostream& out, v1::ExportReport* report) {
  BRDF_ASSIGN_OR_RETURN(exports::RegularGrid grid,
                        exports::MakeRegularGrid(s.steps[0], s.steps[1], s.steps[2],
                                                 s.nodes ? exports::GridPlacement::kNodes
                                                         : exports::GridPlacement::kCellCentres));
  BRDF_ASSIGN_OR_RETURN(exports::SessionInterpolant in,
                        BuildInterpolator(session, s.quantity, s, ctx));
  const WavelengthGrid bands = in.derived->grid;
  const exports::GridExportInfo info{session.id,
                                     session.name,
                                     s.quantity,
                                     interp::MethodName(s.method),
                                     in.derived->samples.size(),
                                     in.derived->skipped.size(),
                                     s.float32 ? "float32" : "float64"};
  const exports::NpyType type = s.float32 ? exports::NpyType::kFloat32 : exports::NpyType::kFloat64;
  exports::NpyGridWriter npy(out, type);
  exports::CsvGridWriter csv(out, info);
  const bool as_npy = s.format == v1::EXPORT_FORMAT_GRID_NPY;
  exports::GridSink& values = as_npy ? static_cast<exports::GridSink&>(npy) : csv;
  exports::RunControl control;
  control.threads = 0;  // every hardware thread: the executor waits on devices, not the CPU
  control.progress = [&stream](double f) { stream.Progress("resampling", 0.05 + 0.95 * f); };
  // With uncertainty: the same pass through the uncertain chain (fill/uncertain_grid.h).
  std::optional<GridUncertaintyParts> parts;
  exports::UncertainGrid u;
  if (s.uncertainty) {
    parts.emplace(stream, FileName(s), type);
    BRDF_ASSIGN_OR_RETURN(u, exports::ResampleWithUncertainty(in, grid, s.quantity, control, ctx,
                                                              values, parts->Sinks(), FileName(s)));
  } else {
    BRDF_ASSIGN_OR_RETURN(
        u.report, exports::ResampleOnGrid(in.chain->Source(), grid, bands, control, ctx, values));
    u.tally = in.chain->Tally();
  }
  const exports::GridReport& r = u.report;
  AddGridCounts(r, report);
  AddSkipped(in.derived->skipped, report);
  AddFill(u.tally, report);
  if (as_npy) {
    for (std::size_t n : {grid.theta_i.count, grid.theta_o.count, grid.phi.count}) {
      report->add_shape(n);
    }
    report->add_shape(bands.count);
    exports::InterpolantInfo how = in.Info();
    how.fill_json = u.tally.Json();
    if (parts) {
      parts->AddTo(report);
      for (std::string& w : u.warnings) report->add_warnings(std::move(w));
    }
    report->set_description_json(
        exports::GridDescriptionJson(grid, bands, info, r, how, u.uncertainty_json));
  }
  return Status();
}

// MERL and RGL with include_uncertainty: the per-band summary of the cells' u as the part
// "uncertainty" (fill/uncertainty_summary.h), since the formats cannot hold it.
Status SendUncertaintySummary(const exports::SessionInterpolant& in, const ExportSettings& s,
                              const char* format, const CallContext& ctx, ExportStream& stream,
                              v1::ExportReport* report) {
  if (!s.uncertainty) return Status();
  stream.Progress("summarising the uncertainty", 0.92);
  exports::RunControl control;
  control.threads = 0;
  BRDF_ASSIGN_OR_RETURN(std::string json,
                        exports::UncertaintySummaryJson(in, format, control, ctx));
  ExportStreamBuf buffer(stream, "uncertainty");
  std::ostream part(&buffer);
  part << json;
  part.flush();
  if (!part) return IoError("Export: sending the uncertainty summary failed");
  v1::ExportPart* named = report->add_parts();
  named->set_name("uncertainty");
  named->set_file_name(exports::CompanionFileName(FileName(s), "uncertainty", ".json"));
  return Status();
}

Status ExportMerl(const exports::Session& session, const ExportSettings& s, const CallContext& ctx,
                  ExportStream& stream, std::ostream& out, v1::ExportReport* report) {
  BRDF_ASSIGN_OR_RETURN(data::CieTables cie, data::LoadCieTables(data::kDefaultColordDir));
  BRDF_ASSIGN_OR_RETURN(exports::SessionInterpolant in,
                        BuildInterpolator(session, exports::Quantity::kBrdf, s, ctx));
  const WavelengthGrid bands = in.derived->grid;
  BRDF_ASSIGN_OR_RETURN(exports::SpectralRgbWeights rgb,
                        exports::SpectralRgbWeights::Make(bands, cie.d65, cie.cmf));
  exports::RunControl control;
  control.threads = 0;
  control.progress = [&stream](double f) {
    stream.Progress("building the MERL table", 0.05 + 0.85 * f);
  };
  BRDF_ASSIGN_OR_RETURN(exports::MerlExport table,
                        exports::BuildMerlTable(in.chain->Source(), bands, rgb, control, ctx));
  stream.Progress("sending", 0.9);
  if (Status st = exports::WriteMerl(table.table, out); !st.ok()) return st;
  BRDF_RETURN_IF_ERROR(SendUncertaintySummary(in, s, "merl", ctx, stream, report));
  const exports::MerlReport& m = table.report;
  report->set_summary(m.Summary());
  AddTableCounts(m.cells, m.filled, m.unfilled, m.below_horizon, m.clamped, report);
  AddSkipped(in.derived->skipped, report);
  AddFill(in.chain->Tally(), report);
  return Status();
}

Status ExportRgl(const exports::Session& session, const ExportSettings& s, const CallContext& ctx,
                 ExportStream& stream, std::ostream& out, v1::ExportReport* report) {
  exports::SessionRglOptions options = s.rgl;
  BRDF_ASSIGN_OR_RETURN(exports::SessionInterpolant in,
                        BuildInterpolator(session, exports::Quantity::kBrdf, s, ctx));
  if (s.rgb) {
    BRDF_ASSIGN_OR_RETURN(data::CieTables cie, data::LoadCieTables(data::kDefaultColordDir));
    BRDF_ASSIGN_OR_RETURN(exports::SpectralRgbWeights rgb,
                          exports::SpectralRgbWeights::Make(in.derived->grid, cie.d65, cie.cmf));
    options.rgb = rgb;
  }
  exports::RunControl control;
  control.threads = 0;
  control.progress = [&stream](double f) {
    stream.Progress("building the RGL tables", 0.05 + 0.85 * f);
  };
  BRDF_ASSIGN_OR_RETURN(exports::RglExport table,
                        exports::BuildSessionRgl(session, in, options, control, ctx));
  stream.Progress("sending", 0.9);
  if (Status st = exports::WriteRgl(table.fields, out); !st.ok()) return st;
  BRDF_RETURN_IF_ERROR(SendUncertaintySummary(in, s, "rgl", ctx, stream, report));
  const exports::RglReport& g = table.report;
  report->set_summary(g.Summary());
  AddTableCounts(g.cells, g.interpolated + g.fallback, g.unfilled, g.below_horizon, g.clamped,
                 report);
  AddSkipped(in.derived->skipped, report);
  AddFill(in.chain->Tally(), report);
  return Status();
}

// What an export holds besides its session's readings, bytes (for the memory budget,
// rpc/memory_budget.h), with `bands` values per spectrum: a few chunks; the interpolant's derived
// samples (about the readings' size again); a grid's window of slices, a MERL or RGL table.
std::uint64_t WorkingBytes(const ExportSettings& s, std::size_t bands, std::uint64_t readings) {
  constexpr std::uint64_t kMerlCells = 90ULL * 90 * 180;
  constexpr std::uint64_t kBatchCells = 16384;  // a batch of the fill chain, per thread
  const std::uint64_t chunks = 3ULL * s.chunk_bytes;
  const std::uint64_t spectrum = 8ULL * bands + 64;
  const std::uint64_t interpolant = readings + 2 * kBatchCells * spectrum;
  switch (s.format) {
    case v1::EXPORT_FORMAT_READINGS_CSV:
      return chunks;  // its derived samples are shared by the exports of the session
    case v1::EXPORT_FORMAT_BIRD_JSON:
      return chunks + readings;  // u_c per reading and band: about the spectra's size
    case v1::EXPORT_FORMAT_MERL_BINARY:
      return chunks + interpolant + kMerlCells * 3 * 8;
    case v1::EXPORT_FORMAT_RGL_BSDF: {
      const std::uint64_t nodes = s.rgl.sample_res;
      return chunks + interpolant + 2ULL * 4 * s.rgl.theta_i_count * nodes * nodes * bands;
    }
    default: {
      Result<exports::RegularGrid> grid = exports::MakeRegularGrid(
          s.steps[0], s.steps[1], s.steps[2],
          s.nodes ? exports::GridPlacement::kNodes : exports::GridPlacement::kCellCentres);
      const std::uint64_t cells =
          grid.ok() ? grid->theta_i.count * grid->theta_o.count * grid->phi.count : 0;
      return chunks + interpolant + std::min<std::uint64_t>(cells, 65536) * (spectrum + 32);
    }
  }
}

// The session, shared with the exports of it in flight (export_loads.h), and its memory reserved:
// the readings when this call loaded them, and what the export will hold (WorkingBytes).
grpc::Status LoadAndReserve(const ExportSettings& s, storage::SessionReader& reader,
                            SharedSessionLoads& loads, StreamRegistry::Slot& slot,
                            std::shared_ptr<const exports::Session>* session) {
  bool loaded = false;
  Result<std::shared_ptr<const exports::Session>> got = loads.Load(reader, s.session_id, &loaded);
  if (!got.ok()) return ToGrpcStatus(got.status());
  const std::uint64_t readings = SharedSessionLoads::BytesOf(**got);
  // A session without readings has no grid yet: reserved as for the finest one brdfd records.
  const std::size_t bands =
      (*got)->readings.empty() ? kMostBands : (*got)->readings.front().spectrum.values.size();
  if (grpc::Status st = slot.Reserve((loaded ? readings : 0) + WorkingBytes(s, bands, readings));
      !st.ok()) {
    return st;
  }
  *session = *std::move(got);
  return grpc::Status::OK;
}

// Whether this export's interpolants are worth keeping for the next: only for a session that
// has ended. A session still recording (or paused, queued) gains readings, and each new reading
// makes a new copy that misses the cache, so keeping them would buy nothing and hold memory
// (daemon_soak_short's RSS floor rose ~40 MB over its last half with them kept).
bool KeepsInterpolants(storage::SessionReader& reader, std::int64_t session) {
  Result<storage::SessionRecord> record = reader.GetSession(session);
  return record.ok() && IsTerminal(record->state);
}

}  // namespace

grpc::Status ExportSession(grpc::ServerContext& context, const v1::ExportRequest& request,
                           ExportWriter& writer, const Authenticator& auth, StreamRegistry& streams,
                           const StopSignal& stopping, storage::SessionReader& reader,
                           SharedSessionLoads& loads, ExportInterpolants& kept) {
  Caller caller;
  if (grpc::Status st = auth.CallerOf(context, &caller); !st.ok()) return st;
  std::unique_ptr<StreamRegistry::Slot> slot;
  if (grpc::Status st = streams.Open(context, &caller, "Export", &slot, /*computes=*/true);
      !st.ok())
    return st;
  ExportSettings settings;
  if (grpc::Status st = ParseRequest(request, &settings); !st.ok()) return st;
  // The chunks first: refused before anything is loaded when the budget is spent.
  if (grpc::Status st = slot->Reserve(3ULL * settings.chunk_bytes); !st.ok()) return st;

  CancelToken cancel;
  Result<CallContext> ctx = ExportContext(context, cancel);
  if (!ctx.ok()) return ToGrpcStatus(ctx.status());
  ExportStream stream(context, writer, *slot, stopping, settings.chunk_bytes, cancel);
  ExportStreamBuf buffer(stream);
  std::ostream out(&buffer);

  stream.Progress("loading readings", 0);
  std::shared_ptr<const exports::Session> session;
  if (grpc::Status st = LoadAndReserve(settings, reader, loads, *slot, &session); !st.ok()) {
    return st;
  }
  stream.Progress("loading readings", 0.05);
  settings.interpolants = {session, &loads,
                           KeepsInterpolants(reader, settings.session_id) ? &kept : nullptr};

  v1::ExportReport report;
  report.set_file_name(FileName(settings));
  if (settings.format != v1::EXPORT_FORMAT_READINGS_CSV &&
      settings.format != v1::EXPORT_FORMAT_BIRD_JSON &&
      exports::HasSeveralDialPositions(*session)) {
    report.add_warnings("session " + request.session_id() +
                        " was measured at several dial positions γ (anisotropic); this export "
                        "uses the isotropic reduction (θi, θo, φ) and folds them together");
  }
  Status st;
  switch (settings.format) {
    case v1::EXPORT_FORMAT_READINGS_CSV:
      st = ExportReadingsCsv(session, settings, loads, stream, out, &report);
      break;
    case v1::EXPORT_FORMAT_MERL_BINARY:
      st = ExportMerl(*session, settings, *ctx, stream, out, &report);
      break;
    case v1::EXPORT_FORMAT_RGL_BSDF:
      st = ExportRgl(*session, settings, *ctx, stream, out, &report);
      break;
    case v1::EXPORT_FORMAT_BIRD_JSON:
      stream.Progress("writing the BiRD file", 0.1);
      st = ExportBirdJson(
          session, settings.exclude_flagged, reader, loads,
          [&stream](double f) { stream.Progress("writing the BiRD file", 0.1 + 0.9 * f); }, out,
          &report);
      break;
    default:
      st = ExportGrid(*session, settings, *ctx, stream, out, &report);
      break;
  }
  if (st.ok()) out.flush();
  if (stream.broken() || (st.ok() && !out)) {
    return grpc::Status(grpc::StatusCode::CANCELLED,
                        "Export: the client went away before the file was sent; ask again");
  }
  if (!st.ok()) return ToGrpcStatus(st.WithContext("Export of session " + request.session_id()));
  stream.Progress("done", 1.0);
  if (!stream.SendReport(std::move(report))) {
    return grpc::Status(grpc::StatusCode::CANCELLED,
                        "Export: the client went away before the report was sent");
  }
  return grpc::Status::OK;
}

}  // namespace brdf::daemon
