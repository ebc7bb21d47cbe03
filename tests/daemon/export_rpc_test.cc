// Data.Export over gRPC against a real brdfd and brdf-sim (processes): one small session is
// measured once for the suite, then exported in each format. The checks are on the bytes the
// client receives, parsed independently of the daemon's report (the CSV's rows, the .npy header
// and its NaN cells, the MERL file's size and missing cells, the RGL file against brdf-export's
// on the same database, the fill counts), and on the stream's contract:
// progress that never decreases and ends at 1, data chunks in order without gaps and no larger
// than asked, the report last with the byte count received.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/export/merl/layout.h"
#include "core/export/merl/reader.h"
#include "core/export/rgl/reader.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"
#include "tests/support/process_launcher.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// Two detector positions, three tilts, β every 10° within 40° of the normal: a small cloud of
// (θi, θo, φ) readings, with a reference and a dark per detector position.
const std::string kExportPlan = plans::InterpolationGrid().Name("export session").Retry(2, 0);

// Everything one Export call delivered.
struct ExportResult {
  grpc::Status status;
  std::vector<v1::ExportProgress> progress;
  std::string file;
  std::map<std::string, std::string> parts;  // ExportData.part's bytes by name
  std::size_t chunks = 0;
  std::size_t largest_chunk = 0;
  std::optional<v1::ExportReport> report;
  std::vector<std::string> contract_errors;  // order, offsets, messages after the report
};

std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class ExportRpcTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    rig_ = new DaemonRig();
    if (Status st = rig_->StartSim({"--noise-scale", "0"}); !st.ok()) {
      error_ = new std::string("brdf-sim: " + st.ToString());
      return;
    }
    if (Status st = rig_->StartDaemon(); !st.ok()) {
      error_ = new std::string("brdfd: " + st.ToString());
      return;
    }
    Result<v1::Session> s = rig_->Submit(kExportPlan);
    if (!s.ok()) {
      error_ = new std::string("SubmitPlan: " + s.status().ToString());
      return;
    }
    session_id_ = new std::string(s->session_id());
    GrpcOperator op(*rig_, *session_id_);
    const v1::Session done = rig_->WaitForState(*session_id_, v1::SESSION_STATE_COMPLETED, 90s);
    op.Stop();
    if (done.state() != v1::SESSION_STATE_COMPLETED) {
      error_ = new std::string("the session did not complete: " + done.DebugString() +
                               "\nbrdfd's log:\n" + rig_->log());
    }
  }
  static void TearDownTestSuite() {
    if (rig_ != nullptr && rig_->daemon() != nullptr) (void)rig_->StopDaemon();
    delete rig_;
    rig_ = nullptr;
    delete error_;
    error_ = nullptr;
    delete session_id_;
    session_id_ = nullptr;
  }
  void SetUp() override {
    if (error_ != nullptr) GTEST_FAIL() << *error_;
  }

  static v1::ExportRequest Request(v1::ExportFormat format) {
    v1::ExportRequest r;
    r.set_session_id(*session_id_);
    r.set_format(format);
    return r;
  }

  // Runs the call to its end; `cancel_after` > 0 cancels it after that many messages.
  static ExportResult Export(const v1::ExportRequest& request,
                             const std::string& token = kAnalystToken, int cancel_after = 0) {
    ExportResult out;
    std::unique_ptr<grpc::ClientContext> context = DaemonRig::Context(token, 120s);
    std::unique_ptr<grpc::ClientReader<v1::ExportChunk>> reader =
        rig_->data().Export(context.get(), request);
    v1::ExportChunk chunk;
    double last_fraction = -1;
    int messages = 0;
    while (reader->Read(&chunk)) {
      if (out.report) out.contract_errors.push_back("a message after the report");
      if (chunk.has_progress()) {
        if (chunk.progress().fraction() < last_fraction) {
          out.contract_errors.push_back("progress went back to " +
                                        std::to_string(chunk.progress().fraction()));
        }
        last_fraction = chunk.progress().fraction();
        out.progress.push_back(chunk.progress());
      } else if (chunk.has_data()) {
        const std::string& part = chunk.data().part();
        std::string& into = part.empty() ? out.file : out.parts[part];
        if (chunk.data().offset() != into.size()) {
          out.contract_errors.push_back("chunk at offset " + std::to_string(chunk.data().offset()) +
                                        " after " + std::to_string(into.size()) + " bytes" +
                                        (part.empty() ? "" : " of part " + part));
        }
        into += chunk.data().content();
        ++out.chunks;
        out.largest_chunk = std::max(out.largest_chunk, chunk.data().content().size());
      } else if (chunk.has_report()) {
        out.report = chunk.report();
      }
      if (cancel_after > 0 && ++messages == cancel_after) context->TryCancel();
    }
    out.status = reader->Finish();
    return out;
  }

  // The contract every successful export keeps.
  static void ExpectCompleteStream(const ExportResult& r) {
    ASSERT_TRUE(r.status.ok()) << r.status.error_message() << "\nbrdfd's log:\n" << rig_->log();
    for (const std::string& e : r.contract_errors) ADD_FAILURE() << e;
    ASSERT_TRUE(r.report.has_value()) << "no report";
    EXPECT_EQ(r.report->bytes(), r.file.size());
    ASSERT_FALSE(r.progress.empty());
    EXPECT_EQ(r.progress.back().fraction(), 1.0);
  }

  // brdf-export run on the daemon's database for the suite's session with `args` (the command
  // and its options, without -o) and -o DIR/out.npy: every file it wrote, by name (out.npy,
  // out.npy.json, …), or why it failed.
  static Result<std::map<std::string, std::string>> ToolExportFiles(std::vector<std::string> args) {
    BRDF_ASSIGN_OR_RETURN(
        std::string tool,
        BuiltProgram("brdf-export", "tools/brdf-export/brdf-export", "BRDF_EXPORT_BINARY"));
    TempDir dir("brdf-export-rpc");
    std::vector<std::string> all = {"--db", rig_->database(), "--session", *session_id_, "--quiet"};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"-o", dir.file("out.npy").string()});
    BRDF_ASSIGN_OR_RETURN(CommandResult run,
                          RunToCompletion("brdf-export", tool, LaunchOptions(all), 120s));
    if (run.exit_code != 0) {
      return Internal("brdf-export exited " + std::to_string(run.exit_code) + ": " + run.err);
    }
    std::map<std::string, std::string> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
      std::ifstream in(entry.path(), std::ios::binary);
      files[entry.path().filename().string()] = std::string(std::istreambuf_iterator<char>(in), {});
    }
    return files;
  }

  // The same: the file it wrote.
  static Result<std::string> ToolExport(std::vector<std::string> args) {
    BRDF_ASSIGN_OR_RETURN(auto files, ToolExportFiles(std::move(args)));
    return files["out.npy"];
  }

  static std::size_t SampleReadings() {
    Result<std::vector<v1::Reading>> readings = rig_->Readings(*session_id_);
    EXPECT_TRUE(readings.ok()) << readings.status().ToString();
    if (!readings.ok()) return 0;
    return static_cast<std::size_t>(
        std::count_if(readings->begin(), readings->end(),
                      [](const v1::Reading& r) { return r.kind() == v1::READING_KIND_SAMPLE; }));
  }

  static DaemonRig* rig_;
  static std::string* error_;
  static std::string* session_id_;
};

DaemonRig* ExportRpcTest::rig_ = nullptr;
std::string* ExportRpcTest::error_ = nullptr;
std::string* ExportRpcTest::session_id_ = nullptr;

// An analyst may export; small chunks arrive in order; one row per sample reading (BRDF), one
// per reading of any kind (radiance), after a '#' header that names the unit.
TEST_F(ExportRpcTest, ReadingsCsvHasOneRowPerReadingInChunksOfTheAskedSize) {
  const std::size_t samples = SampleReadings();
  ASSERT_GT(samples, 10u);

  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_READINGS_CSV);
  request.set_chunk_bytes(1000);
  const ExportResult brdf = Export(request);
  ExpectCompleteStream(brdf);
  EXPECT_LE(brdf.largest_chunk, 1000u);
  EXPECT_GE(brdf.chunks, brdf.file.size() / 1000);
  EXPECT_EQ(brdf.report->file_name(), "session-" + *session_id_ + "-readings-brdf.csv");

  std::size_t comments = 0, rows = 0;
  bool unit_named = false;
  for (const std::string& line : SplitLines(brdf.file)) {
    if (line.rfind('#', 0) == 0) {
      ++comments;
      unit_named = unit_named || line.find("sr⁻¹") != std::string::npos;
    } else {
      ++rows;
    }
  }
  EXPECT_GT(comments, 0u);
  EXPECT_TRUE(unit_named) << "the header must name the BRDF's unit";
  // One column header line, then the rows.
  EXPECT_EQ(rows - 1, samples - brdf.report->skipped_readings());
  EXPECT_EQ(brdf.report->rows(), rows - 1);

  request.set_quantity(v1::QUANTITY_RADIANCE);
  request.set_chunk_bytes(0);
  const ExportResult radiance = Export(request);
  ExpectCompleteStream(radiance);
  Result<std::vector<v1::Reading>> all = rig_->Readings(*session_id_);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(radiance.report->rows(), all->size());
}

// The .npy has the shape the report gives, the byte size that shape implies, and exactly the
// reported number of NaN cells (every band NaN in each); the CSV form agrees cell for cell.
TEST_F(ExportRpcTest, GridNpyAndCsvHoldTheReportedShapeAndNanCells) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_GRID_NPY);
  request.set_step_theta_i(10);
  request.set_step_theta_o(10);
  request.set_step_phi(20);
  const ExportResult npy = Export(request);
  ExpectCompleteStream(npy);
  const v1::ExportReport& report = *npy.report;
  ASSERT_EQ(report.shape_size(), 4);
  EXPECT_EQ(report.shape(0), 9u);
  EXPECT_EQ(report.shape(1), 9u);
  EXPECT_EQ(report.shape(2), 9u);
  EXPECT_EQ(report.shape(3), 101u);
  EXPECT_EQ(report.cells(), 729u);
  EXPECT_EQ(report.filled_cells() + report.unfilled_cells(), report.cells());
  EXPECT_GT(report.filled_cells(), 0u);
  EXPECT_NE(report.description_json().find("sr"), std::string::npos);

  // NPY 1.0: magic, version, little-endian uint16 header length, the header, then the doubles.
  ASSERT_GT(npy.file.size(), 10u);
  ASSERT_EQ(npy.file.compare(0, 6, "\x93NUMPY"), 0);
  const std::size_t header_len =
      static_cast<unsigned char>(npy.file[8]) + 256u * static_cast<unsigned char>(npy.file[9]);
  const std::string header = npy.file.substr(10, header_len);
  EXPECT_NE(header.find("'shape': (9, 9, 9, 101)"), std::string::npos) << header;
  const std::size_t data_start = 10 + header_len;
  ASSERT_EQ(npy.file.size(), data_start + 729u * 101u * 8u);
  std::size_t nan_cells = 0;
  for (std::size_t cell = 0; cell < 729; ++cell) {
    std::size_t nan_bands = 0;
    for (std::size_t b = 0; b < 101; ++b) {
      double v = 0;
      std::memcpy(&v, npy.file.data() + data_start + (cell * 101 + b) * 8, 8);
      if (std::isnan(v)) ++nan_bands;
    }
    EXPECT_TRUE(nan_bands == 0 || nan_bands == 101) << "cell " << cell;
    if (nan_bands == 101) ++nan_cells;
  }
  EXPECT_EQ(nan_cells, report.unfilled_cells());
  std::uint64_t by_status = 0;
  for (const auto& [name, count] : report.unfilled_by_status()) by_status += count;
  EXPECT_EQ(by_status, report.unfilled_cells());

  request.set_format(v1::EXPORT_FORMAT_GRID_CSV);
  const ExportResult csv = Export(request);
  ExpectCompleteStream(csv);
  EXPECT_EQ(csv.report->unfilled_cells(), report.unfilled_cells());
  std::size_t rows = 0, nan_rows = 0;
  for (const std::string& line : SplitLines(csv.file)) {
    if (line.empty() || line[0] == '#' || line.rfind("theta_i", 0) == 0) continue;
    ++rows;
    if (line.find(",nan") != std::string::npos) ++nan_rows;
  }
  EXPECT_EQ(rows, 729u);
  EXPECT_EQ(nan_rows, report.unfilled_cells());
}

// The doubles of a .npy file (NPY 1.0, '<f8'), after its header.
std::vector<double> NpyDoubles(const std::string& npy) {
  if (npy.size() < 10 || npy.compare(0, 6, "\x93NUMPY") != 0) {
    ADD_FAILURE() << "not a .npy file";
    return {};
  }
  const std::size_t header_len =
      static_cast<unsigned char>(npy[8]) + 256u * static_cast<unsigned char>(npy[9]);
  std::vector<double> values((npy.size() - 10 - header_len) / 8);
  std::memcpy(values.data(), npy.data() + 10 + header_len, values.size() * 8);
  return values;
}

// A grid export with include_uncertainty by `method` (the fill chain behind it), its cells'
// u_interpolation compared with the Interpolate API's interpolation term at the same directions
// of the same (ended) session: the chain's chosen-method cells with `method`'s, its fallback
// cells with Delaunay's, to the API's float rounding. Counts the cells compared per method.
class GridUncertaintyCheck {
 public:
  static constexpr std::size_t kBands = 101, kCells = 9 * 9 * 9;

  GridUncertaintyCheck(DaemonRig& rig, const std::string& session, v1::ExportRequest request,
                       v1::InterpolationMethod method)
      : rig_(rig), session_(session), method_(method) {
    request.set_method(method);
    request.set_step_theta_i(10);
    request.set_step_theta_o(10);
    request.set_step_phi(20);
    request.set_include_uncertainty(true);
    request_ = request;
  }
  const v1::ExportRequest& request() const { return request_; }

  // `u_meas` (optional): the grid's u_measurement, which must be Interpolate's measurement part
  // bit for bit once rounded to the API's float (the same blend of the same budgets in the
  // blend's form, core/uncertainty/blend.h).
  void Compare(const std::vector<double>& values, const std::vector<double>& u_int,
               const std::vector<double>* u_meas = nullptr) {
    ASSERT_EQ(values.size(), kCells * kBands);
    ASSERT_EQ(u_int.size(), kCells * kBands);
    if (u_meas != nullptr) {
      ASSERT_EQ(u_meas->size(), kCells * kBands);
    }
    for (std::size_t cell = 0; cell < kCells; cell += 3) {
      if (std::isnan(values[cell * kBands])) continue;
      const v1::InterpolateResponse answer = Ask(cell);
      if (answer.result().status() != v1::INTERPOLATION_STATUS_OK) continue;  // a model cell
      const v1::InterpolationUncertainty& u = answer.result().uncertainty();
      ASSERT_EQ(u.interpolation_size(), static_cast<int>(kBands));
      ++compared[answer.result().method()];
      for (std::size_t b = 0; b < kBands; ++b) {
        const double want = u.interpolation(static_cast<int>(b));
        EXPECT_NEAR(u_int[cell * kBands + b], want, 0x1p-23 * std::abs(want))
            << "cell " << cell << ", band " << b << ", method " << answer.result().method();
        nonzero += want > 0;
        if (u_meas == nullptr || u.measurement_size() != static_cast<int>(kBands)) continue;
        const float m = static_cast<float>((*u_meas)[cell * kBands + b]);
        EXPECT_EQ(m, u.measurement(static_cast<int>(b)))
            << "cell " << cell << ", band " << b << ", method " << answer.result().method();
        measurement_compared += 1;
      }
      for (const std::string& n : u.not_estimated()) not_estimated.insert(n);
    }
  }

  std::map<v1::InterpolationMethod, std::size_t> compared;
  std::size_t nonzero = 0;
  std::size_t measurement_compared = 0;  // bands of u_measurement compared
  std::set<std::string> not_estimated;   // the API's, over the answers compared

 private:
  // Interpolate at cell's centre (θ 5°, 15°, …, 85°; φ 10°, 30°, …, 170°) in the chain's order:
  // the chosen method, then its Delaunay fallback.
  v1::InterpolateResponse Ask(std::size_t cell) {
    v1::InterpolateRequest ask;
    ask.set_session_id(session_);
    ask.set_include_uncertainty(true);
    v1::IsoDirection* at = ask.mutable_direction()->mutable_iso();
    at->set_theta_i(5.0 + 10.0 * static_cast<double>(cell / 81));
    at->set_theta_o(5.0 + 10.0 * static_cast<double>(cell / 9 % 9));
    at->set_phi(10.0 + 20.0 * static_cast<double>(cell % 9));
    v1::InterpolateResponse answer;
    for (v1::InterpolationMethod m : {method_, v1::INTERPOLATION_METHOD_DELAUNAY}) {
      ask.set_method(m);
      const grpc::Status st =
          rig_.interpolation().Interpolate(DaemonRig::Context(kAnalystToken).get(), ask, &answer);
      EXPECT_TRUE(st.ok()) << st.error_message();
      if (answer.result().status() == v1::INTERPOLATION_STATUS_OK) break;
    }
    return answer;
  }

  DaemonRig& rig_;
  std::string session_;
  v1::InterpolationMethod method_;
  v1::ExportRequest request_;
};

// With include_uncertainty a grid's u_interpolation is the Interpolate API's calibrated
// interpolation term at the same direction of the same (ended) session, to the API's float
// rounding, its u_measurement the API's measurement part bit for bit (as a float), and the sidecar
// says the term is calibrated and how; a second export of the snapshot (its kept interpolant and
// calibration) gives the same arrays. Delaunay: the suite's 24 readings give it held-out readings
// to calibrate on.
TEST_F(ExportRpcTest, GridUncertaintyIsInterpolatesCalibratedInterpolationTerm) {
  GridUncertaintyCheck check(*rig_, *session_id_, Request(v1::EXPORT_FORMAT_GRID_NPY),
                             v1::INTERPOLATION_METHOD_DELAUNAY);
  const ExportResult grid = Export(check.request());
  ExpectCompleteStream(grid);
  ASSERT_TRUE(grid.parts.contains("u_interpolation"));
  const std::string& sidecar = grid.report->description_json();
  EXPECT_NE(sidecar.find("\"interpolation_calibration\": {\"calibrated\": true"), std::string::npos)
      << sidecar;
  EXPECT_NE(sidecar.find("\"band_groups\": [{\"bands\": [0, 24], \"nm\": [380, 476], "
                         "\"scale\": "),
            std::string::npos)
      << sidecar;
  const std::vector<double> u_meas = NpyDoubles(grid.parts.at("u_measurement"));
  check.Compare(NpyDoubles(grid.file), NpyDoubles(grid.parts.at("u_interpolation")), &u_meas);
  EXPECT_GE(check.compared[v1::INTERPOLATION_METHOD_DELAUNAY], 20u);
  EXPECT_GT(check.nonzero, 0u);
  EXPECT_GE(check.measurement_compared, 20u * GridUncertaintyCheck::kBands);
  for (const std::string& n : check.not_estimated) {
    EXPECT_EQ(n.find("interpolation:"), std::string::npos) << "the API's term is calibrated: " << n;
  }

  const ExportResult again = Export(check.request());
  ExpectCompleteStream(again);
  EXPECT_EQ(again.parts, grid.parts);
}

// Where the term cannot be calibrated (the octant method predicts none of the suite's readings
// held out: each lies on the data's edge once left out), the grid's u_interpolation is the
// spread as it is, as the API's is (its not_estimated says so), and the sidecar says why; the
// chain's Delaunay fallback cells are calibrated, as Delaunay's answers are.
TEST_F(ExportRpcTest, GridUncertaintyNotCalibratedSaysWhyAndIsTheApisToo) {
  GridUncertaintyCheck check(*rig_, *session_id_, Request(v1::EXPORT_FORMAT_GRID_NPY),
                             v1::INTERPOLATION_METHOD_OCTANT);
  const ExportResult grid = Export(check.request());
  ExpectCompleteStream(grid);
  const std::string& sidecar = grid.report->description_json();
  EXPECT_NE(sidecar.find("\"interpolation_calibration\": {\"calibrated\": false"),
            std::string::npos)
      << sidecar;
  EXPECT_NE(sidecar.find("{\"stage\": \"interpolated\", \"method\": \"octant\", "
                         "\"calibrated\": false, \"held_out_readings\": 0, \"why\": \"0 "
                         "held-out readings predicted, fewer than 8\""),
            std::string::npos)
      << sidecar;
  EXPECT_NE(sidecar.find("{\"stage\": \"fallback\", \"method\": \"delaunay\", "
                         "\"calibrated\": true"),
            std::string::npos)
      << sidecar;
  bool warned = false;
  for (const std::string& w : grid.report->warnings()) {
    warned = warned || w.find("(octant) is not calibrated") != std::string::npos;
  }
  EXPECT_TRUE(warned);
  const std::vector<double> u_meas = NpyDoubles(grid.parts.at("u_measurement"));
  check.Compare(NpyDoubles(grid.file), NpyDoubles(grid.parts.at("u_interpolation")), &u_meas);
  EXPECT_GE(check.compared[v1::INTERPOLATION_METHOD_OCTANT], 3u);
  EXPECT_GE(check.compared[v1::INTERPOLATION_METHOD_DELAUNAY], 3u);
  EXPECT_TRUE(check.not_estimated.contains(
      "interpolation: not calibrated (0 held-out readings predicted, fewer than 8); the "
      "vertices' spread as it is"));
}

// brdf-export grid --uncertainty (the offline tool, on the daemon's database) writes the daemon's
// arrays: for the same session and options its OUT.u.npy, OUT.u_measurement.npy and
// OUT.u_interpolation.npy are the export's parts "u", "u_measurement" and "u_interpolation" byte
// for byte, its grid the export's file, and its .json the report's description (the files named
// as each names them). Delaunay, whose term is calibrated on the suite's readings; float32.
TEST_F(ExportRpcTest, GridUncertaintyArraysAreBrdfExportsByteForByte) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_GRID_NPY);
  request.set_step_theta_i(10);
  request.set_step_theta_o(10);
  request.set_step_phi(20);
  request.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  request.set_float32(true);
  request.set_include_uncertainty(true);
  const ExportResult rpc = Export(request);
  ExpectCompleteStream(rpc);
  ASSERT_EQ(rpc.parts.size(), 3u);

  Result<std::map<std::string, std::string>> tool = ToolExportFiles(
      {"grid", "--steps", "10,10,20", "--method", "delaunay", "--float32", "--uncertainty"});
  ASSERT_TRUE(tool.ok()) << tool.status().ToString();
  ASSERT_EQ(tool->size(), 5u) << "out.npy, its .json and three arrays";
  EXPECT_TRUE(tool->at("out.npy") == rpc.file) << "the grid differs";
  std::string description = rpc.report->description_json();
  for (const v1::ExportPart& part : rpc.report->parts()) {
    const std::string mine = "out." + part.name() + ".npy";
    ASSERT_TRUE(tool->contains(mine)) << mine;
    ASSERT_TRUE(rpc.parts.contains(part.name())) << part.name();
    EXPECT_FALSE(rpc.parts.at(part.name()).empty());
    EXPECT_TRUE(tool->at(mine) == rpc.parts.at(part.name())) << part.name() << " differs";
    for (std::size_t at = description.find(part.file_name()); at != std::string::npos;
         at = description.find(part.file_name(), at + 1)) {
      description.replace(at, part.file_name().size(), mine);
    }
  }
  EXPECT_NE(description.find("\"uncertainty\": {"), std::string::npos) << description;
  EXPECT_EQ(tool->at("out.npy.json"), description);

  // A grid as CSV has no room for the arrays: refused, naming the option.
  Result<std::map<std::string, std::string>> csv =
      ToolExportFiles({"grid", "--format", "csv", "--uncertainty"});
  ASSERT_FALSE(csv.ok());
  EXPECT_NE(csv.status().message().find("--uncertainty is for .npy grids"), std::string::npos)
      << csv.status().ToString();
}

// MERL's uncertainty summary (include_uncertainty) rests on the same calibrated term
// (Delaunay, as above).
TEST_F(ExportRpcTest, MerlUncertaintySummarySaysTheInterpolationTermIsCalibrated) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_MERL_BINARY);
  request.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  request.set_include_uncertainty(true);
  const ExportResult merl = Export(request);
  ExpectCompleteStream(merl);
  ASSERT_TRUE(merl.parts.contains("uncertainty"));
  const std::string& summary = merl.parts.at("uncertainty");
  EXPECT_NE(summary.find("\"interpolation_calibration\": {\"calibrated\": true"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("\"held_out_readings\": "), std::string::npos) << summary;
}

// The MERL file has MERL's size and dims, reads back with the reference reader's layout, and its
// missing cells (−1) are exactly those the report counts as below the horizon or unfilled.
TEST_F(ExportRpcTest, MerlFileHasMerlsSizeAndItsMissingCellsMatchTheReport) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_MERL_BINARY);
  request.mutable_options()->set_reciprocity(true);
  request.set_chunk_bytes(256 * 1024);
  const ExportResult merl = Export(request);
  ExpectCompleteStream(merl);
  ASSERT_EQ(merl.file.size(), 90u * 90u * 180u * 3u * 8u + 12u);
  EXPECT_LE(merl.largest_chunk, 256u * 1024u);
  std::int32_t dims[3] = {};
  std::memcpy(dims, merl.file.data(), sizeof dims);
  EXPECT_EQ(dims[0], 90);
  EXPECT_EQ(dims[1], 90);
  EXPECT_EQ(dims[2], 180);
  Result<exports::MerlTable> table = exports::ParseMerl(merl.file);
  ASSERT_TRUE(table.ok()) << table.status().ToString();
  std::size_t missing = 0;
  for (std::size_t i = 0; i < exports::kMerlCells; ++i) {
    if (table->stored[i] < 0) ++missing;
  }
  const v1::ExportReport& report = *merl.report;
  EXPECT_EQ(report.cells(), exports::kMerlCells);
  EXPECT_EQ(missing, report.below_horizon_cells() + report.unfilled_cells());
  EXPECT_EQ(report.filled_cells(), exports::kMerlCells - missing);
  EXPECT_GT(report.filled_cells(), 0u);
  EXPECT_EQ(report.file_name(), "session-" + *session_id_ + ".binary");
  // The default fill is the chain: every cell above the horizon has a value.
  EXPECT_EQ(report.unfilled_cells(), 0u);
  EXPECT_EQ(missing, report.below_horizon_cells());
  ASSERT_TRUE(report.has_fill());
  EXPECT_EQ(report.fill().policy(), "chain");
  EXPECT_EQ(report.fill().empty(), 0u);
  EXPECT_EQ(report.fill().interpolated() + report.fill().fallback() + report.fill().model(),
            report.filled_cells());
}

// fill none leaves NaN cells on a grid and counts them as empty; the chain fills each of them
// (by Delaunay or the fitted model) and counts where the values came from.
TEST_F(ExportRpcTest, GridFillNoneLeavesHolesAndTheChainFillsThemAndCountsThem) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_GRID_NPY);
  request.set_step_theta_i(10);
  request.set_step_theta_o(10);
  request.set_step_phi(20);
  request.set_fill(v1::EXPORT_FILL_NONE);
  const ExportResult none = Export(request);
  ExpectCompleteStream(none);
  ASSERT_TRUE(none.report->has_fill());
  const v1::ExportFillCounts& holes = none.report->fill();
  EXPECT_EQ(holes.policy(), "none");
  EXPECT_GT(holes.empty(), 0u) << "this small session leaves the octant method holes";
  EXPECT_EQ(holes.empty(), none.report->unfilled_cells());
  EXPECT_EQ(holes.fallback() + holes.model(), 0u);
  EXPECT_NE(none.report->description_json().find("\"policy\": \"none\""), std::string::npos)
      << none.report->description_json();

  request.set_fill(v1::EXPORT_FILL_CHAIN);
  const ExportResult chain = Export(request);
  ExpectCompleteStream(chain);
  const v1::ExportFillCounts& filled = chain.report->fill();
  EXPECT_EQ(filled.policy(), "chain");
  EXPECT_EQ(chain.report->unfilled_cells(), 0u);
  EXPECT_EQ(filled.empty(), 0u);
  EXPECT_EQ(filled.interpolated(), holes.interpolated());
  EXPECT_EQ(filled.fallback() + filled.model(), holes.empty());
  EXPECT_DOUBLE_EQ(filled.model_fraction(), static_cast<double>(filled.model()) /
                                                static_cast<double>(chain.report->cells()));
  const std::size_t data_start = 10 + static_cast<unsigned char>(chain.file[8]) +
                                 256u * static_cast<unsigned char>(chain.file[9]);
  ASSERT_EQ(chain.file.size(), data_start + 729u * 101u * 8u);
  for (std::size_t i = 0; i < 729u * 101u; ++i) {
    double v = 0;
    std::memcpy(&v, chain.file.data() + data_start + i * 8, 8);
    ASSERT_TRUE(std::isfinite(v)) << "value " << i << " of the chain-filled grid";
  }
}

// A grid in half/difference coordinates (ExportRequest.options.coordinates) is brdf-export's
// --coordinates half-diff grid byte for byte, differs from the incidence grid, and its
// description (the .json sidecar) records the coordinates beside the symmetries and scales.
TEST_F(ExportRpcTest, GridInHalfDifferenceCoordinatesIsBrdfExportsAndSaysSo) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_GRID_NPY);
  request.set_step_theta_i(10);
  request.set_step_theta_o(10);
  request.set_step_phi(20);
  request.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  const ExportResult incidence = Export(request);
  ExpectCompleteStream(incidence);
  EXPECT_NE(incidence.report->description_json().find("\"coordinates\": \"incidence\""),
            std::string::npos)
      << incidence.report->description_json();

  request.mutable_options()->set_coordinates(v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE);
  request.mutable_options()->set_mirror_phi(true);
  const ExportResult half = Export(request);
  ExpectCompleteStream(half);
  const std::string& json = half.report->description_json();
  EXPECT_NE(json.find("\"coordinates\": \"half_difference\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"mirror_phi\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"axis_scale\": null"), std::string::npos) << json;
  ASSERT_EQ(half.file.size(), incidence.file.size());
  EXPECT_NE(half.file, incidence.file);

  Result<std::string> tool = ToolExport({"grid", "--steps", "10,10,20", "--method", "delaunay",
                                         "--mirror-phi", "--coordinates", "half-diff"});
  ASSERT_TRUE(tool.ok()) << tool.status().ToString();
  EXPECT_TRUE(*tool == half.file) << "brdf-export's grid differs from the RPC's";
}

// An RGL export over gRPC is brdf-export's file for the same session and options, byte for byte
// (spectral and RGB); it reads back as a material whose BRDF has a value at every direction
// above the surface, and the report counts the fill.
TEST_F(ExportRpcTest, RglIsBrdfExportsFileByteForByteAndHasNoHoles) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_RGL_BSDF);
  request.mutable_options()->set_reciprocity(true);  // brdf-export rgl's default
  request.set_rgl_theta_i_count(6);
  request.set_rgl_resolution(16);
  request.set_chunk_bytes(64 * 1024);
  const ExportResult rgl = Export(request);
  ExpectCompleteStream(rgl);
  EXPECT_EQ(rgl.report->file_name(), "session-" + *session_id_ + ".bsdf");
  Result<std::string> tool = ToolExport({"rgl", "--theta-i", "6", "--resolution", "16"});
  ASSERT_TRUE(tool.ok()) << tool.status().ToString();
  ASSERT_EQ(rgl.file.size(), tool->size());
  EXPECT_TRUE(rgl.file == *tool) << "the daemon's .bsdf differs from brdf-export's";

  const v1::ExportReport& report = *rgl.report;
  EXPECT_EQ(report.cells(), 6u * 16u * 16u);
  EXPECT_EQ(report.unfilled_cells(), 0u);
  EXPECT_EQ(report.filled_cells() + report.below_horizon_cells(), report.cells());
  ASSERT_TRUE(report.has_fill());
  EXPECT_EQ(report.fill().policy(), "chain");
  EXPECT_EQ(report.fill().empty(), 0u);
  EXPECT_EQ(report.fill().interpolated() + report.fill().fallback() + report.fill().model(),
            report.filled_cells());

  Result<exports::RglMaterial> material = exports::RglMaterial::Parse(rgl.file);
  ASSERT_TRUE(material.ok()) << material.status().ToString();
  EXPECT_FALSE(material->rgb());
  EXPECT_EQ(material->channels(), 101u);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> theta(0, 40), phi(0, 360);
  for (int k = 0; k < 200; ++k) {
    const Directions d{theta(random), phi(random), theta(random), phi(random)};
    const std::vector<double> f = material->Brdf(d);
    double mean = 0;
    for (double v : f) mean += v / static_cast<double>(f.size());
    ASSERT_TRUE(std::isfinite(mean) && mean > 0)
        << "no value at θi " << d.theta_i << ", φi " << d.phi_i << ", θo " << d.theta_o << ", φo "
        << d.phi_o;
  }

  request.set_rgb(true);
  const ExportResult rgb = Export(request);
  ExpectCompleteStream(rgb);
  EXPECT_EQ(rgb.report->file_name(), "session-" + *session_id_ + "-rgb.bsdf");
  Result<std::string> tool_rgb =
      ToolExport({"rgl", "--rgb", "--theta-i", "6", "--resolution", "16"});
  ASSERT_TRUE(tool_rgb.ok()) << tool_rgb.status().ToString();
  EXPECT_TRUE(rgb.file == *tool_rgb) << "the daemon's RGB .bsdf differs from brdf-export's";
  Result<exports::RglMaterial> rgb_material = exports::RglMaterial::Parse(rgb.file);
  ASSERT_TRUE(rgb_material.ok()) << rgb_material.status().ToString();
  EXPECT_TRUE(rgb_material->rgb());
}

TEST_F(ExportRpcTest, BadRequestsFailWithTheCodeAndNameTheField) {
  const ExportResult no_format = Export(Request(v1::EXPORT_FORMAT_UNSPECIFIED));
  EXPECT_EQ(no_format.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(no_format.status.error_message().find("format"), std::string::npos);

  v1::ExportRequest steps = Request(v1::EXPORT_FORMAT_GRID_NPY);
  steps.set_step_theta_i(7);  // does not divide 90°
  const ExportResult bad_steps = Export(steps);
  EXPECT_EQ(bad_steps.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
      << bad_steps.status.error_message();
  EXPECT_NE(bad_steps.status.error_message().find("step_theta_i"), std::string::npos)
      << bad_steps.status.error_message();
  // Refused before anything streams (the web gateway then answers with the HTTP status).
  EXPECT_TRUE(bad_steps.progress.empty());
  EXPECT_TRUE(bad_steps.file.empty());

  v1::ExportRequest merl_radiance = Request(v1::EXPORT_FORMAT_MERL_BINARY);
  merl_radiance.set_quantity(v1::QUANTITY_RADIANCE);
  EXPECT_EQ(Export(merl_radiance).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  v1::ExportRequest rgl_radiance = Request(v1::EXPORT_FORMAT_RGL_BSDF);
  rgl_radiance.set_quantity(v1::QUANTITY_RADIANCE);
  EXPECT_EQ(Export(rgl_radiance).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  v1::ExportRequest rgb_grid = Request(v1::EXPORT_FORMAT_GRID_NPY);
  rgb_grid.set_rgb(true);
  const ExportResult bad_rgb = Export(rgb_grid);
  EXPECT_EQ(bad_rgb.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(bad_rgb.status.error_message().find("rgb"), std::string::npos);
  v1::ExportRequest huge = Request(v1::EXPORT_FORMAT_RGL_BSDF);
  huge.set_rgl_resolution(100000);
  const ExportResult bad_resolution = Export(huge);
  EXPECT_EQ(bad_resolution.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(bad_resolution.status.error_message().find("rgl_resolution"), std::string::npos);
  v1::ExportRequest bad_fill = Request(v1::EXPORT_FORMAT_GRID_NPY);
  bad_fill.set_fill(static_cast<v1::ExportFill>(42));
  const ExportResult fill_42 = Export(bad_fill);
  EXPECT_EQ(fill_42.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(fill_42.status.error_message().find("fill"), std::string::npos);

  v1::ExportRequest unknown = Request(v1::EXPORT_FORMAT_READINGS_CSV);
  unknown.set_session_id("987654");
  EXPECT_EQ(Export(unknown).status.error_code(), grpc::StatusCode::NOT_FOUND);

  EXPECT_EQ(Export(Request(v1::EXPORT_FORMAT_READINGS_CSV), "").status.error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
}

// A client that goes away mid-export stops it; the daemon keeps serving exports.
TEST_F(ExportRpcTest, ACancelledExportEndsAndTheNextOneWorks) {
  v1::ExportRequest request = Request(v1::EXPORT_FORMAT_MERL_BINARY);
  const ExportResult cancelled = Export(request, kAnalystToken, /*cancel_after=*/2);
  EXPECT_EQ(cancelled.status.error_code(), grpc::StatusCode::CANCELLED)
      << cancelled.status.error_message();
  EXPECT_FALSE(cancelled.report.has_value());

  const ExportResult next = Export(Request(v1::EXPORT_FORMAT_READINGS_CSV));
  ExpectCompleteStream(next);
}

}  // namespace
}  // namespace brdf::testing
