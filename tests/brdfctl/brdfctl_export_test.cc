// `brdfctl export` as a user runs it: the built brdfctl against brdfd and brdf-sim (processes),
// with an analyst token, on a small session measured once in the test. The files it writes are
// checked on their own terms: the MERL file's size, the .npy loaded by NumPy (/usr/bin/python3),
// whose NaN cells must be the count brdfctl reports, the CSV's rows, the RGL .bsdf read by
// tools/check/rgl_read.py, the fill counts; `brdfctl appearance`'s colours and PPM spheres.
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "brdf/v1/brdf.pb.h"
#include "tests/brdfctl/ctl_test_rig.h"
#include "tests/support/plan_fixtures.h"
#include "tests/support/test_env.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

const std::string kPlan = plans::InterpolationGrid().Name("export session");

std::string Describe(const CommandResult& r) {
  return "exit " + std::to_string(r.exit_code) + "\n--- stdout:\n" + r.out.substr(0, 4000) +
         "\n--- stderr:\n" + r.err;
}

// Runs `command` with /bin/sh; its exit code and standard output.
CommandResult RunShell(const std::string& command) {
  CommandResult r;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "", "popen failed: " + command};
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    r.out.append(buffer, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  return r;
}

class BrdfctlExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const Status started = rig_.Start();
    ASSERT_TRUE(started.ok()) << started.ToString();
    const std::string plan = rig_.dir().file("plan.json").string();
    std::ofstream(plan) << kPlan;
    const CommandResult submit = Ctl({"submit", plan, "--start", "--quiet"}, kCtlOperatorToken);
    ASSERT_EQ(submit.exit_code, 0) << Describe(submit);
    id_ = Lines(submit.out).at(0);
    const std::string ctl = *BrdfctlBinary();
    const CommandResult watch =
        Ctl({"watch", id_, "--auto-confirm", "--no-progress", "--on-prompt",
             "'" + ctl + "' sim-mount from-prompt --modbus " + rig_.modbus()},
            kCtlOperatorToken, 120s);
    ASSERT_EQ(watch.exit_code, 0) << Describe(watch) << "\nbrdfd's log:\n" << rig_.log();
  }

  CommandResult Ctl(const std::vector<std::string>& args,
                    const std::string& token = kCtlAnalystToken,
                    std::chrono::milliseconds timeout = 150s) {
    Result<CommandResult> r = rig_.Ctl(args, token, timeout);
    EXPECT_TRUE(r.ok()) << r.status().ToString();
    return r.ok() ? *r : CommandResult{-1, "", r.status().ToString()};
  }

  std::string Path(const std::string& name) const { return rig_.dir().file(name).string(); }

  CtlRig rig_;
  std::string id_;
};

TEST_F(BrdfctlExportTest, AnAnalystExportsMerlGridAndCsvFilesThatTheirReadersLoad) {
  // MERL: the reference reader's size (three int32 dims, then 3 · 90 · 90 · 180 doubles).
  const std::string merl = Path("session.binary");
  const CommandResult m = Ctl({"export", id_, "merl", "-o", merl});
  ASSERT_EQ(m.exit_code, 0) << Describe(m);
  EXPECT_EQ(std::filesystem::file_size(merl), 90u * 90u * 180u * 3u * 8u + 12u);
  EXPECT_FALSE(std::filesystem::exists(merl + ".partial"));
  EXPECT_NE(m.err.find("export merl: "), std::string::npos) << "no progress line\n" << m.err;
  EXPECT_NE(m.err.find("100%"), std::string::npos) << m.err;

  // Grid as .npy: NumPy loads it; its NaN cells are the count brdfctl reports.
  const std::string npy = Path("grid.npy");
  const CommandResult g = Ctl({"export", id_, "grid", "--steps", "10,10,20", "-o", npy});
  ASSERT_EQ(g.exit_code, 0) << Describe(g);
  ASSERT_TRUE(std::filesystem::exists(npy + ".json"));
  std::smatch match;
  ASSERT_TRUE(std::regex_search(g.err, match, std::regex("NaN cells: ([0-9]+)"))) << g.err;
  const std::string reported_nan = match[1];
  const std::string script = Path("load_npy.py");
  std::ofstream(script)
      << "import json, sys, numpy as np\n"
         "a = np.load(sys.argv[1])\n"
         "d = json.load(open(sys.argv[1] + '.json'))\n"
         "nan = np.isnan(a).all(axis=-1)\n"
         "assert (np.isnan(a).any(axis=-1) == nan).all(), 'a cell is partly NaN'\n"
         "print(a.dtype, *a.shape, int(nan.sum()), "
         "int(np.isfinite(a).all(axis=-1).sum()))\n";
  const CommandResult numpy = RunShell("/usr/bin/python3 '" + script + "' '" + npy + "' 2>&1");
  ASSERT_EQ(numpy.exit_code, 0) << Describe(numpy);
  EXPECT_EQ(Lines(numpy.out).at(0), "float64 9 9 9 101 " + reported_nan + " " +
                                        std::to_string(729 - std::stoi(reported_nan)))
      << numpy.out;

  // Readings CSV to standard output: a '#' header, the column line, one row per sample reading.
  const CommandResult c = Ctl({"export", id_, "csv", "-o", "-", "--no-progress"});
  ASSERT_EQ(c.exit_code, 0) << Describe(c);
  std::size_t rows = 0;
  for (const std::string& line : Lines(c.out)) {
    if (!line.empty() && line[0] != '#' && line.rfind("id,", 0) != 0) ++rows;
  }
  ASSERT_TRUE(std::regex_search(c.err, match, std::regex("([0-9]+) rows"))) << c.err;
  EXPECT_EQ(std::to_string(rows), std::string(match[1]));
  EXPECT_GT(rows, 10u);

  // --coordinates half-diff: the grid's sidecar records it (beside the symmetries and scales),
  // its values differ from the incidence grid's; interpolate takes the flag too and says so.
  const std::string half_npy = Path("grid-half.npy");
  const CommandResult h = Ctl(
      {"export", id_, "grid", "--steps", "10,10,20", "--coordinates", "half-diff", "-o", half_npy});
  ASSERT_EQ(h.exit_code, 0) << Describe(h);
  const std::string compare = Path("compare_npy.py");
  std::ofstream(compare) << "import json, sys, numpy as np\n"
                            "a, b = np.load(sys.argv[1]), np.load(sys.argv[2])\n"
                            "da = json.load(open(sys.argv[1] + '.json'))\n"
                            "db = json.load(open(sys.argv[2] + '.json'))\n"
                            "both = np.isfinite(a) & np.isfinite(b)\n"
                            "print(da['coordinates'], db['coordinates'], db['mirror_phi'], "
                            "db['axis_scale'], bool((a[both] != b[both]).any()))\n";
  const CommandResult cmp =
      RunShell("/usr/bin/python3 '" + compare + "' '" + npy + "' '" + half_npy + "' 2>&1");
  ASSERT_EQ(cmp.exit_code, 0) << Describe(cmp);
  EXPECT_EQ(Lines(cmp.out).at(0), "incidence half_difference False None True") << cmp.out;

  // A direction inside the readings' hull in both coordinates (the quick start's 35°, 40°, 40°
  // is not, in half/difference angles: φd > 90° there, beyond every reading).
  const std::vector<std::string> at = {"--theta-i", "25",  "--theta-o", "25",
                                       "--phi",     "100", "--method",  "delaunay"};
  auto interpolate = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"interpolate", id_};
    args.insert(args.end(), at.begin(), at.end());
    args.insert(args.end(), extra.begin(), extra.end());
    return Ctl(args);
  };
  const CommandResult text = interpolate({"--coordinates", "half-diff"});
  ASSERT_EQ(text.exit_code, 0) << Describe(text);
  EXPECT_NE(text.out.find("delaunay in half/difference coordinates: ok"), std::string::npos)
      << Describe(text);
  const CommandResult half_json = interpolate({"--coordinates", "half-diff", "--json"});
  const CommandResult incidence_json = interpolate({"--coordinates", "incidence", "--json"});
  ASSERT_EQ(half_json.exit_code, 0) << Describe(half_json);
  ASSERT_EQ(incidence_json.exit_code, 0) << Describe(incidence_json);
  v1::InterpolateResponse half_reply, incidence_reply;
  ASSERT_TRUE(
      google::protobuf::util::JsonStringToMessage(Lines(half_json.out).at(0), &half_reply).ok());
  ASSERT_TRUE(
      google::protobuf::util::JsonStringToMessage(Lines(incidence_json.out).at(0), &incidence_reply)
          .ok());
  ASSERT_EQ(half_reply.result().spectrum_size(), 101);
  ASSERT_EQ(incidence_reply.result().spectrum_size(), 101);
  EXPECT_NE(half_reply.result().spectrum(45), incidence_reply.result().spectrum(45));
  const CommandResult unknown = interpolate({"--coordinates", "polar"});
  EXPECT_EQ(unknown.exit_code, 2) << Describe(unknown);

  // --trend bivariate: interpolate says so and answers otherwise; the grid's sidecar records it.
  const CommandResult trend_text = interpolate({"--trend", "bivariate"});
  ASSERT_EQ(trend_text.exit_code, 0) << Describe(trend_text);
  EXPECT_NE(trend_text.out.find("delaunay over the bivariate trend: ok"), std::string::npos)
      << Describe(trend_text);
  EXPECT_NE(trend_text.out.find("bivariate trend T(θh, θd)"), std::string::npos)
      << Describe(trend_text);
  const CommandResult trend_json = interpolate({"--trend", "bivariate", "--json"});
  ASSERT_EQ(trend_json.exit_code, 0) << Describe(trend_json);
  v1::InterpolateResponse trend_reply;
  ASSERT_TRUE(
      google::protobuf::util::JsonStringToMessage(Lines(trend_json.out).at(0), &trend_reply).ok());
  ASSERT_EQ(trend_reply.result().spectrum_size(), 101);
  EXPECT_NE(trend_reply.result().spectrum(45), incidence_reply.result().spectrum(45));
  EXPECT_EQ(interpolate({"--trend", "quadratic"}).exit_code, 2);
  const std::string trend_npy = Path("grid-trend.npy");
  const CommandResult t =
      Ctl({"export", id_, "grid", "--steps", "10,10,20", "--trend", "bivariate", "-o", trend_npy});
  ASSERT_EQ(t.exit_code, 0) << Describe(t);
  const CommandResult trend_cmp = RunShell(
      "/usr/bin/python3 -c \"import json, sys; d = "
      "json.load(open(sys.argv[1])); print(d['trend'], "
      "d['coordinates'])\" '" +
      trend_npy + ".json' 2>&1");
  ASSERT_EQ(trend_cmp.exit_code, 0) << Describe(trend_cmp);
  EXPECT_EQ(Lines(trend_cmp.out).at(0), "bivariate incidence") << trend_cmp.out;
  const CommandResult csv_trend =
      Ctl({"export", id_, "csv", "--trend", "bivariate", "-o", Path("trend.csv")});
  EXPECT_EQ(csv_trend.exit_code, 2) << Describe(csv_trend);
  EXPECT_NE(csv_trend.err.find("--trend is for grid, merl and rgl exports"), std::string::npos)
      << Describe(csv_trend);

  // A grid step that does not divide 90° is the user's error (exit 2), and leaves no file.
  const std::string bad = Path("bad.npy");
  const CommandResult b = Ctl({"export", id_, "grid", "--steps", "7", "-o", bad});
  EXPECT_EQ(b.exit_code, 2) << Describe(b);
  EXPECT_FALSE(std::filesystem::exists(bad));
  EXPECT_FALSE(std::filesystem::exists(bad + ".partial"));
}

// rgl: the .bsdf reads back with tools/check/rgl_read.py, with a value where a renderer looks;
// the fill line counts the chain's cells, none of them empty. --fill none leaves a grid's holes
// and counts them; --rgb on a grid is the user's error.
TEST_F(BrdfctlExportTest, UncertaintyArraysGoBesideTheGridAndItsSidecarNamesThem) {
  // --uncertainty: three more .npy files named after -o, of the grid's shape and dtype, named in
  // OUT.json as they are on disk; u is NaN where the values are, ≥ 0 at every interpolated cell,
  // and ≥ 0 or NaN (not estimated, beyond the model's calibrated reach) at the chain's model cells.
  const std::string npy = Path("ugrid.npy");
  const CommandResult g =
      Ctl({"export", id_, "grid", "--steps", "10,10,20", "--float32", "--uncertainty", "-o", npy});
  ASSERT_EQ(g.exit_code, 0) << Describe(g);
  for (const char* part : {"u", "u_measurement", "u_interpolation"}) {
    EXPECT_TRUE(std::filesystem::exists(Path(std::string("ugrid.") + part + ".npy"))) << part;
    EXPECT_FALSE(std::filesystem::exists(npy + ".partial." + part)) << part;
    EXPECT_NE(g.err.find(std::string(part) + " → " + Path(std::string("ugrid.") + part + ".npy")),
              std::string::npos)
        << g.err;
  }
  const std::string script = Path("load_u.py");
  std::ofstream(script)
      << "import json, sys, numpy as np\n"
         "a = np.load(sys.argv[1])\n"
         "d = json.load(open(sys.argv[1] + '.json'))['uncertainty']\n"
         "u = np.load(sys.argv[1][:-4] + '.u.npy')\n"
         "um = np.load(sys.argv[1][:-4] + '.u_measurement.npy')\n"
         "names = sorted(v['file'] for v in d['arrays'].values())\n"
         "ok = np.isfinite(a)\n"
         "model = ok & np.isnan(um)\n"  // the fill chain's model cells may be not estimated (NaN)
         "i = ok & ~model\n"
         "assert np.isnan(u[~ok]).all() and (u[i] >= 0).all() and np.isfinite(u[i]).all()\n"
         "m = u[model]\n"
         "assert (m[np.isfinite(m)] >= 0).all()\n"
         "print(u.dtype, *u.shape, d['k'], *names)\n";
  const CommandResult numpy = RunShell("/usr/bin/python3 '" + script + "' '" + npy + "' 2>&1");
  ASSERT_EQ(numpy.exit_code, 0) << Describe(numpy);
  EXPECT_EQ(Lines(numpy.out).at(0),
            "float32 9 9 9 101 1 ugrid.u.npy ugrid.u_interpolation.npy ugrid.u_measurement.npy")
      << numpy.out;

  const CommandResult refused = Ctl({"export", id_, "csv", "-o", Path("r.csv"), "--uncertainty"});
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.err.find("--uncertainty is for grid exports to .npy"), std::string::npos)
      << refused.err;
}

TEST_F(BrdfctlExportTest, RglReadsBackAndTheFillIsReported) {
  const std::string bsdf = Path("session.bsdf");
  const CommandResult r =
      Ctl({"export", id_, "rgl", "--theta-i", "4", "--resolution", "12", "-o", bsdf});
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  EXPECT_FALSE(std::filesystem::exists(bsdf + ".partial"));
  EXPECT_NE(r.err.find("fill chain: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" 0 empty"), std::string::npos) << r.err;
  const CommandResult read =
      RunShell(std::string("/usr/bin/python3 '") + BRDF_TEST_SOURCE_DIR +
               "/tools/check/rgl_read.py' '" + bsdf + "' --at 20,0,25,180 2>&1");
  ASSERT_EQ(read.exit_code, 0) << Describe(read);
  EXPECT_NE(read.out.find("spectra: float32"), std::string::npos) << read.out;
  std::smatch match;
  ASSERT_TRUE(std::regex_search(read.out, match,
                                std::regex("20,0,25,180 ([0-9.e+-]+) ([0-9.e+-]+) ([0-9.e+-]+)")))
      << read.out;
  for (int k = 1; k <= 3; ++k) EXPECT_GT(std::stod(match[k]), 0) << read.out;

  const std::string npy = Path("holes.npy");
  const CommandResult g =
      Ctl({"export", id_, "grid", "--steps", "10,10,20", "--fill", "none", "-o", npy});
  ASSERT_EQ(g.exit_code, 0) << Describe(g);
  ASSERT_TRUE(std::regex_search(g.err, match, std::regex("NaN cells: ([0-9]+)"))) << g.err;
  const std::string nan_cells = match[1];
  EXPECT_GT(std::stoi(nan_cells), 0) << g.err;
  EXPECT_NE(g.err.find("fill none: "), std::string::npos) << g.err;
  EXPECT_NE(g.err.find(", " + nan_cells + " empty"), std::string::npos) << g.err;

  const CommandResult bad = Ctl({"export", id_, "grid", "--rgb", "-o", Path("rgb.npy")});
  EXPECT_EQ(bad.exit_code, 2) << Describe(bad);
  EXPECT_FALSE(std::filesystem::exists(Path("rgb.npy")));
}

// bird: a BiRD universal BRDF JSON file that tools/check/bird_validate.py finds holding what the
// format requires (tests/python/bird_required.schema.json), one point per sample reading and band;
// another quantity or an interpolation option is the user's error, leaving no file.
TEST_F(BrdfctlExportTest, BirdJsonHoldsWhatTheFormatRequires) {
  const std::string json = Path("session-bird.json");
  const CommandResult r = Ctl({"export", id_, "bird", "-o", json, "--json"});
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  EXPECT_FALSE(std::filesystem::exists(json + ".partial"));
  v1::ExportReport report;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(Lines(r.out).at(0), &report).ok())
      << r.out;
  EXPECT_EQ(report.file_name(), "session-" + id_ + "-bird.json");
  EXPECT_GT(report.rows(), 0u);
  EXPECT_EQ(report.rows() % 101, 0u) << "one point per reading and band (101 bands)";
  EXPECT_EQ(report.warnings_size(), 0) << "every reading has a budget: uBRDF is written";
  const CommandResult check =
      RunShell(std::string("/usr/bin/python3 '") + BRDF_TEST_SOURCE_DIR +
               "/tools/check/bird_validate.py' '" + BRDF_TEST_SOURCE_DIR + "/tests/python' '" +
               json + "' --top bird_required.schema.json 2>&1");
  EXPECT_EQ(check.exit_code, 0) << Describe(check);
  EXPECT_NE(check.out.find("0 violation(s)"), std::string::npos) << check.out;

  for (const std::vector<std::string>& bad : {std::vector<std::string>{"--quantity", "reflectance"},
                                              {"--fill", "none"},
                                              {"--trend", "bivariate"}}) {
    std::vector<std::string> args = {"export", id_, "bird", "-o", Path("bad.json")};
    args.insert(args.end(), bad.begin(), bad.end());
    const CommandResult refused = Ctl(args);
    EXPECT_EQ(refused.exit_code, 2) << bad[0] << ": " << Describe(refused);
    EXPECT_FALSE(std::filesystem::exists(Path("bad.json")));
  }
}

// appearance: the colours under both illuminants, and the spheres as PPM files whose header and
// size are a PPM's (P6, 24 × 24 pixels, 255) with lit (not white, not black) pixels; the JSON
// form parses as the AppearanceResponse; an unknown illuminant is the user's error.
TEST_F(BrdfctlExportTest, AppearancePrintsTheColoursAndWritesTheSpheres) {
  const std::string ppm = Path("sphere.ppm");
  const CommandResult r = Ctl({"appearance", id_, "--size", "24", "-o", ppm});
  ASSERT_EQ(r.exit_code, 0) << Describe(r);
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(D65  #[0-9a-f]{6}  X [0-9.]+  Y [0-9.]+)")))
      << Describe(r);
  EXPECT_TRUE(std::regex_search(r.out, std::regex(R"(A    #[0-9a-f]{6} )"))) << Describe(r);
  for (const char* name : {"sphere-D65.ppm", "sphere-A.ppm"}) {
    std::ifstream in(Path(name), std::ios::binary);
    ASSERT_TRUE(in.good()) << name << "\n" << Describe(r);
    std::string magic;
    int w = 0, h = 0, max = 0;
    in >> magic >> w >> h >> max;
    in.get();
    EXPECT_EQ(magic, "P6");
    EXPECT_EQ(w, 24);
    EXPECT_EQ(h, 24);
    EXPECT_EQ(max, 255);
    std::string pixels((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(pixels.size(), 24U * 24U * 3U) << name;
    int lit = 0;
    for (std::size_t i = 0; i < pixels.size(); i += 3) {
      const int sum = static_cast<unsigned char>(pixels[i]) +
                      static_cast<unsigned char>(pixels[i + 1]) +
                      static_cast<unsigned char>(pixels[i + 2]);
      if (sum > 30 && sum < 765) ++lit;
    }
    EXPECT_GT(lit, 24 * 24 / 4) << name;
  }
  const CommandResult json = Ctl({"appearance", id_, "--illuminant", "A", "--json"});
  ASSERT_EQ(json.exit_code, 0) << Describe(json);
  v1::AppearanceResponse reply;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(Lines(json.out).at(0), &reply).ok());
  ASSERT_EQ(reply.images_size(), 1);
  EXPECT_EQ(reply.images(0).name(), "A");
  EXPECT_EQ(reply.reflectance_size(), 101);
  const CommandResult bad = Ctl({"appearance", id_, "--illuminant", "F2"});
  EXPECT_EQ(bad.exit_code, 2) << Describe(bad);
}

}  // namespace
}  // namespace brdf::testing
