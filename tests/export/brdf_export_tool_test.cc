// brdf-export as users run it: a real SQLite database written through SessionStore (a synthetic
// paint-like session with reference and dark readings), read back by the executable; every
// export's file checked; errors exit 2 with a message that names what was wrong.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/export/merl/reader.h"
#include "core/export/rgl/reader.h"
#include "core/export/synthetic_session.h"
#include "core/uncertainty/budget.h"
#include "export_test_util.h"
#include "storage/session_store.h"

namespace brdf::exports {
namespace {

using testing::CsvRows;
using testing::ReadFile;

std::string Binary() {
  const char* dir = std::getenv("BRDF_BUILD_DIR");
  return std::string(dir != nullptr ? dir : BRDF_TEST_BUILD_DIR) + "/tools/brdf-export/brdf-export";
}

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

class BrdfExportTool : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char tmpl[] = "/tmp/brdf-export-test-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = new std::string(tmpl);
    db_ = new std::string(*dir_ + "/brdfd.sqlite");
    auto store = storage::SessionStore::Open(*db_);
    ASSERT_TRUE(store.ok()) << store.status().ToString();

    // The synthetic session's readings (reference, dark, samples on a reduced paper grid).
    SyntheticSessionOptions o;
    // A reduced rig grid keeps the database small (every reading is a committed transaction).
    o.poses.delta_stop_deg = 33.75;  // 4 detector positions
    o.poses.alpha_stop_deg = 40;
    o.poses.beta_step_deg = 10;
    Result<Session> synthetic = SyntheticSession(AnalyticBrdf::PaintLike(), o);
    ASSERT_TRUE(synthetic.ok());
    std::vector<storage::StepRecord> steps;
    for (std::size_t i = 0; i < synthetic->readings.size(); ++i) {
      const Reading& r = synthetic->readings[i];
      storage::StepRecord s;
      s.step_index = static_cast<int>(i);
      s.kind = r.kind == ReadingKind::kSample      ? storage::StepKind::kSample
               : r.kind == ReadingKind::kReference ? storage::StepKind::kReference
                                                   : storage::StepKind::kDark;
      s.pose = r.pose;
      s.target = r.directions;
      s.label = "step " + std::to_string(i);
      steps.push_back(s);
    }
    storage::NewSession ns;
    ns.name = "paint";
    ns.plan_kind = "sample_rotation";
    ns.plan_json = "{}";
    ns.created_by_role = "operator";
    ns.white_reflectance = 0.99;
    Result<std::int64_t> id = (*store)->CreateSession(ns, steps);
    ASSERT_TRUE(id.ok()) << id.status().ToString();
    session_ = *id;
    ASSERT_TRUE((*store)->SetSessionState(session_, SessionState::kRunning, "test").ok());
    std::map<std::int64_t, std::int64_t> stored_id;  // synthetic id → database id
    for (std::size_t i = 0; i < synthetic->readings.size(); ++i) {
      const Reading& r = synthetic->readings[i];
      storage::ReadingRecord rec;
      rec.kind = r.kind == ReadingKind::kSample      ? storage::ReadingKind::kSample
                 : r.kind == ReadingKind::kReference ? storage::ReadingKind::kReference
                                                     : storage::ReadingKind::kDark;
      rec.pose = r.pose;
      rec.directions = r.directions;
      rec.grid = r.spectrum.grid;
      rec.spectrum = r.spectrum.values;
      rec.integration_ms = 250;
      if (r.reference_id) rec.reference_reading_id = stored_id.at(*r.reference_id);
      if (r.dark_id) rec.dark_reading_id = stored_id.at(*r.dark_id);
      Result<std::int64_t> rid =
          (*store)->CompleteStepWithReading(session_, static_cast<int>(i), rec);
      ASSERT_TRUE(rid.ok()) << rid.status().ToString();
      stored_id[r.id] = *rid;
    }
    readings_ = synthetic->readings.size();

    // A second session that has not measured anything yet.
    Result<std::int64_t> empty = (*store)->CreateSession(ns, {steps.front()});
    ASSERT_TRUE(empty.ok());
    empty_session_ = *empty;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    std::filesystem::remove_all(*dir_, ec);
    delete dir_;
    delete db_;
  }

  static ToolRun Exec(const std::string& args) {
    const std::string out = *dir_ + "/stdout", err = *dir_ + "/stderr";
    const std::string cmd = Binary() + " " + args + " > " + out + " 2> " + err;
    const int status = std::system(cmd.c_str());
    ToolRun r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = ReadFile(out);
    r.err = ReadFile(err);
    return r;
  }
  static std::string SessionArgs() {
    return "--db " + *db_ + " --session " + std::to_string(session_) + " --quiet";
  }
  static std::string File(const std::string& name) { return *dir_ + "/" + name; }

  static std::string* dir_;
  static std::string* db_;
  static std::int64_t session_;
  static std::int64_t empty_session_;
  static std::size_t readings_;
};
std::string* BrdfExportTool::dir_ = nullptr;
std::string* BrdfExportTool::db_ = nullptr;
std::int64_t BrdfExportTool::session_ = 0;
std::int64_t BrdfExportTool::empty_session_ = 0;
std::size_t BrdfExportTool::readings_ = 0;

TEST_F(BrdfExportTool, CsvOfReadingsFromTheDatabase) {
  ToolRun r = Exec(SessionArgs() + " csv --quantity radiance -o " + File("radiance.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = ReadFile(File("radiance.csv"));
  EXPECT_EQ(CsvRows(text).size(), readings_ + 1);
  EXPECT_NE(text.find("W·m⁻²·sr⁻¹·nm⁻¹"), std::string::npos);
  EXPECT_NE(text.find("\"paint\""), std::string::npos);

  r = Exec(SessionArgs() + " csv -o " + File("brdf.csv"));  // brdf by default
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = CsvRows(ReadFile(File("brdf.csv")));
  ASSERT_EQ(rows.size(), readings_ - 2 + 1);  // samples only
  // The stored radiances turn back into the paint's BRDF.
  const auto& row = rows[10];
  const Directions d{std::stod(row[6]), std::stod(row[7]), std::stod(row[8]), std::stod(row[9])};
  const std::vector<double> truth =
      AnalyticBrdf::PaintLike().EvaluateSpectrum(d, WavelengthGrid::Pr650());
  EXPECT_NEAR(std::stod(row[16 + 50]), truth[50], 1e-9);
  EXPECT_EQ(row[12], "250");
}

TEST_F(BrdfExportTool, GridAsNpyWithDescriptionAndAsCsv) {
  ToolRun r = Exec(SessionArgs() + " grid --steps 10,10,20 --threads 2 -o " + File("grid.npy"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string npy = ReadFile(File("grid.npy"));
  ASSERT_GT(npy.size(), 128u);
  EXPECT_EQ(npy.compare(0, 6, "\x93NUMPY"), 0);
  EXPECT_NE(npy.find("'shape': (9, 9, 9, 101)"), std::string::npos);
  const std::size_t header =
      10 + (static_cast<unsigned char>(npy[8]) | static_cast<unsigned char>(npy[9]) << 8);
  EXPECT_EQ(npy.size(), header + 9u * 9 * 9 * 101 * 8);
  const std::string json = ReadFile(File("grid.npy.json"));
  EXPECT_NE(json.find("\"unit\": \"sr⁻¹\""), std::string::npos);
  EXPECT_NE(r.err.find("729 cells"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(File("grid.npy.partial")));

  r = Exec(SessionArgs() + " grid --steps 10,10,20 --quantity reflectance -o " + File("grid.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = CsvRows(ReadFile(File("grid.csv")));
  EXPECT_EQ(rows.size(), 1u + 729u);
  EXPECT_EQ(rows[0][3], "status");
}

TEST_F(BrdfExportTool, MerlFileReadsBackWhereTheToolLookedUp) {
  ToolRun r = Exec(SessionArgs() +
                   " merl --method nearest --threads 2 --probe 30,0,30,180 "
                   "--probe 20,0,40,120 -o " +
                   File("paint.binary"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string bytes = ReadFile(File("paint.binary"));
  ASSERT_EQ(bytes.size(), 12u + 3u * 8u * 90u * 90u * 180u);
  Result<MerlTable> table = ParseMerl(bytes);
  ASSERT_TRUE(table.ok()) << table.status().ToString();
  const auto rows = CsvRows(r.out);
  ASSERT_EQ(rows.size(), 3u) << r.out;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const Directions d{std::stod(rows[i][0]), std::stod(rows[i][1]), std::stod(rows[i][2]),
                       std::stod(rows[i][3])};
    const Rgb file = LookupMerl(*table, d);
    EXPECT_EQ(file.r, std::stod(rows[i][8]));
    EXPECT_EQ(file.g, std::stod(rows[i][9]));
    EXPECT_EQ(file.b, std::stod(rows[i][10]));
    // Nearest neighbour on a 11.25°/10°/5° rig grid: within 15 % of its own answer at the probe.
    EXPECT_NEAR(file.g, std::stod(rows[i][6]), 0.15 * std::stod(rows[i][6]));
  }
  EXPECT_NE(r.err.find("below the horizon"), std::string::npos) << r.err;
}

TEST_F(BrdfExportTool, RglFilesSpectralAndRgbParse) {
  ToolRun r = Exec(SessionArgs() + " rgl --theta-i 6 --resolution 12 -o " + File("paint.bsdf"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Result<RglMaterial> spectral = RglMaterial::Parse(ReadFile(File("paint.bsdf")));
  ASSERT_TRUE(spectral.ok()) << spectral.status().ToString();
  EXPECT_EQ(spectral->wavelengths().size(), 101u);
  EXPECT_NE(r.err.find("retro-reflection readings"), std::string::npos) << r.err;
  // A white-referenced paint: f at 30°/30° off-specular is a few tenths of sr⁻¹, not 0.
  const std::vector<double> f = spectral->Brdf({30, 0, 30, 120});
  EXPECT_GT(f[42], 0.05);
  EXPECT_LT(f[42], 1.0);
  r = Exec(SessionArgs() + " rgl --rgb --theta-i 6 --resolution 12 -o " + File("paint_rgb.bsdf"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Result<RglMaterial> rgb = RglMaterial::Parse(ReadFile(File("paint_rgb.bsdf")));
  ASSERT_TRUE(rgb.ok()) << rgb.status().ToString();
  EXPECT_TRUE(rgb->rgb());
  r = Exec(SessionArgs() + " rgl -o -");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("-o PATH.bsdf"), std::string::npos) << r.err;
}

TEST_F(BrdfExportTool, FitReportsParametersAndResiduals) {
  ToolRun r = Exec(SessionArgs() + " fit -o " + File("fit.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = ReadFile(File("fit.csv"));
  const auto rows = CsvRows(text);
  ASSERT_EQ(rows.size(), 102u);
  EXPECT_EQ(rows[0].front(), "wavelength_nm");
  EXPECT_EQ(rows[0].size(), 15u);  // each parameter with its _u
  EXPECT_NE(text.find(",ct_alpha,ct_alpha_u,"), std::string::npos);
  EXPECT_NE(r.err.find("Lambert: RMS"), std::string::npos) << r.err;
  // The stored readings carry no budget: an unweighted fit, and it says so.
  EXPECT_NE(r.err.find("unweighted"), std::string::npos) << r.err;
  EXPECT_NE(text.find("# weighting: none"), std::string::npos);
  EXPECT_NE(r.err.find("Cook-Torrance GGX"), std::string::npos) << r.err;
}

// A stored session whose readings carry budgets with shared components (here a white standard
// and the readings' reference) is fitted by generalised least squares, and says so.
TEST_F(BrdfExportTool, FitOfAStoredSessionWithBudgetsIsGeneralisedLeastSquares) {
  const std::string copy = File("budgets.sqlite");
  std::filesystem::copy_file(*db_, copy, std::filesystem::copy_options::overwrite_existing);
  std::size_t expected_terms = 0;
  {
    auto store = storage::SessionStore::Open(copy);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    Result<std::vector<storage::ReadingRecord>> records =
        (*store)->GetReadings(session_, 0, 100000);
    ASSERT_TRUE(records.ok());
    std::vector<std::pair<std::int64_t, uncertainty::ReadingBudget>> budgets;
    std::set<std::int64_t> references;
    for (const storage::ReadingRecord& r : *records) {
      if (r.kind != storage::ReadingKind::kSample) continue;
      const std::size_t n = r.spectrum.size();
      ASSERT_TRUE(r.reference_reading_id.has_value());
      references.insert(*r.reference_reading_id);
      uncertainty::ReadingBudget b;
      b.value.assign(n, 0.1);
      b.components = {{"sample_signal", {}, std::vector<double>(n, 0.002)},
                      {"white_standard",
                       {uncertainty::Sharing::kWhiteStandard, session_},
                       std::vector<double>(n, 0.001)},
                      {"reference_signal",
                       {uncertainty::Sharing::kReferenceReading, *r.reference_reading_id},
                       std::vector<double>(n, 0.0005)}};
      b.independent.assign(n, 0.002);
      b.combined.assign(n, std::sqrt(0.002 * 0.002 + 0.001 * 0.001 + 0.0005 * 0.0005));
      budgets.emplace_back(r.id, std::move(b));
    }
    ASSERT_FALSE(budgets.empty());
    const Status st = (*store)->ReplaceReadingUncertainties(session_, budgets);
    ASSERT_TRUE(st.ok()) << st.ToString();
    ASSERT_GE(references.size(), 1u);
    expected_terms = 1 + references.size();
  }
  ToolRun r = Exec("--db " + copy + " --session " + std::to_string(session_) + " --quiet fit -o " +
                   File("fit_gls.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string terms = "GLS with " + std::to_string(expected_terms) + " shared terms";
  EXPECT_NE(r.err.find("weighted by their uncertainties: " + terms), std::string::npos) << r.err;
  const std::string report = ReadFile(File("fit_gls.csv"));
  EXPECT_NE(report.find("# weighting: " + terms + " (generalised least squares)"),
            std::string::npos);
  EXPECT_NE(report.find("χ²/dof = "), std::string::npos);
  EXPECT_EQ(CsvRows(report).size(), 102u);
}

// The path from a session to a weighted fit: the readings CSV of the BRDF with its u_<λ> columns
// filled (here 2 % of each value, standing in for the budgets) is fitted weighted and reports
// χ²/dof; the same file without the u columns (an older export) is fitted unweighted.
TEST_F(BrdfExportTool, FitOfAReadingsCsvIsWeightedByItsUncertaintyColumns) {
  ToolRun r = Exec(SessionArgs() + " csv --quantity brdf -o " + File("brdf.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream in(ReadFile(File("brdf.csv")));
  std::string with_u, without_u, line;
  std::size_t first_value = 0, bands = 0;
  while (std::getline(in, line)) {
    if (line.starts_with("#")) {
      with_u += line + "\n";
      without_u += line + "\n";
      continue;
    }
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    if (line.ends_with(',')) f.emplace_back();
    if (f[0] == "id") {
      for (first_value = 0; f[first_value] != "380"; ++first_value) {
      }
      bands = (f.size() - first_value) / 2;
      ASSERT_EQ(f[first_value + bands], "u_380");
    } else {
      ASSERT_EQ(f[first_value + bands], "") << "the stored readings carry no budget";
      for (std::size_t b = 0; b < bands; ++b) {
        f[first_value + bands + b] = std::to_string(0.02 * std::stod(f[first_value + b]) + 1e-4);
      }
    }
    std::string joined, short_joined;
    for (std::size_t c = 0; c < f.size(); ++c) {
      joined += (c ? "," : "") + f[c];
      if (c < first_value + bands) short_joined += (c ? "," : "") + f[c];
    }
    with_u += joined + "\n";
    without_u += short_joined + "\n";
  }
  std::ofstream(File("brdf_u.csv")) << with_u;
  std::ofstream(File("brdf_old.csv")) << without_u;

  r = Exec("fit --readings " + File("brdf_u.csv") + " -o " + File("fit_u.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("weighted by their uncertainties"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("χ²/dof = "), std::string::npos) << r.err;
  const std::string report = ReadFile(File("fit_u.csv"));
  EXPECT_NE(report.find("# weighting: weighted, independent: every value by 1/u²"),
            std::string::npos);
  EXPECT_EQ(CsvRows(report).size(), 102u);

  r = Exec("fit --readings " + File("brdf_old.csv") + " -o " + File("fit_old.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("unweighted"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("χ²/dof: none"), std::string::npos) << r.err;

  r = Exec("fit --readings " + File("missing.csv") + " -o " + File("x.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("cannot open the readings CSV"), std::string::npos) << r.err;
  ASSERT_EQ(Exec(SessionArgs() + " csv --quantity radiance -o " + File("rad.csv")).exit_code, 0);
  r = Exec("fit --readings " + File("rad.csv") + " -o " + File("x.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--quantity brdf"), std::string::npos) << r.err;
}

TEST_F(BrdfExportTool, ErrorsNameWhatWasWrongAndExitTwo) {
  ToolRun r = Exec("--db " + *db_ + " --session 999 csv -o " + File("x.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown session 999"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(File("x.csv")));
  EXPECT_FALSE(std::filesystem::exists(File("x.csv.partial")));

  r = Exec("--db " + *db_ + " --session " + std::to_string(empty_session_) + " grid -o " +
           File("x.npy"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("empty session"), std::string::npos) << r.err;

  r = Exec(SessionArgs() + " grid --steps 7,1,1 -o " + File("x.npy"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("does not divide"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("θi"), std::string::npos) << r.err;

  r = Exec(SessionArgs() + " grid --steps 1,x -o " + File("x.npy"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'x'"), std::string::npos) << r.err;

  r = Exec("--db " + File("missing.sqlite") + " --session 1 csv -o " + File("x.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no database at"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(File("missing.sqlite")));

  r = Exec(SessionArgs() + " csv --quantity colour -o " + File("x.csv"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("radiance, reflectance or brdf"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace brdf::exports
