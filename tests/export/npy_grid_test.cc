// Regular grids: axes and step errors, the NPY header (parsed here independently of the writer,
// from the format's published description), NaN counting, parallel == serial bit for bit,
// progress and cancellation, the CSV form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <regex>
#include <sstream>

#include "core/export/fill/uncertain_chain.h"
#include "core/export/grid/npy_writer.h"
#include "core/export/grid/regular_grid.h"
#include "core/export/grid/text.h"
#include "core/export/synthetic_session.h"
#include "core/interp/octant/octant.h"
#include "export_test_util.h"

namespace brdf::exports {
namespace {

CallContext LongContext(CancelToken token = CancelToken()) {
  return CallContext::WithTimeout(std::chrono::hours(1), std::move(token));
}

// An NPY v1.0 file's header, read as the format describes it.
struct ParsedNpy {
  bool ok = false;
  std::string descr;
  bool fortran = true;
  std::vector<std::size_t> shape;
  std::size_t data_offset = 0;
};

ParsedNpy ParseNpy(const std::string& bytes) {
  ParsedNpy p;
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) return p;
  if (bytes[6] != 1 || bytes[7] != 0) return p;
  const std::size_t len = static_cast<unsigned char>(bytes[8]) |
                          (static_cast<std::size_t>(static_cast<unsigned char>(bytes[9])) << 8);
  if (bytes.size() < 10 + len) return p;
  const std::string header = bytes.substr(10, len);
  if (header.back() != '\n') return p;
  std::smatch m;
  if (!std::regex_search(header, m, std::regex(R"('descr':\s*'([^']*)')"))) return p;
  p.descr = m[1];
  if (!std::regex_search(header, m, std::regex(R"('fortran_order':\s*(True|False))"))) return p;
  p.fortran = m[1] == "True";
  if (!std::regex_search(header, m, std::regex(R"('shape':\s*\(([^)]*)\))"))) return p;
  const std::string dims = m[1];
  const std::regex number(R"(\d+)");
  for (std::sregex_iterator it(dims.begin(), dims.end(), number), end; it != end; ++it) {
    p.shape.push_back(std::stoul(it->str()));
  }
  p.data_offset = 10 + len;
  p.ok = true;
  return p;
}

// A source that fails in known places: outside_hull for θi > 60°, empty_octant for φ < 30°, and
// otherwise a spectrum that encodes the direction.
interp::InterpStatus PatternSource(const IsoDirection& at, std::span<double> out) {
  if (at.theta_i > 60) return interp::InterpStatus::kOutsideHull;
  if (at.phi < 30) return interp::InterpStatus::kEmptyOctant;
  for (std::size_t b = 0; b < out.size(); ++b) {
    out[b] = at.theta_i + 100 * at.theta_o + 1e4 * at.phi + 1e6 * static_cast<double>(b);
  }
  return interp::InterpStatus::kOk;
}

TEST(RegularGrid, StepsGiveTheExpectedAxes) {
  Result<RegularGrid> centres = MakeRegularGrid(1, 1, 1, GridPlacement::kCellCentres);
  ASSERT_TRUE(centres.ok());
  EXPECT_EQ(centres->theta_i.count, 90u);
  EXPECT_EQ(centres->theta_o.count, 90u);
  EXPECT_EQ(centres->phi.count, 180u);
  EXPECT_DOUBLE_EQ(centres->theta_i.at(0), 0.5);
  EXPECT_DOUBLE_EQ(centres->phi.at(179), 179.5);
  Result<RegularGrid> nodes = MakeRegularGrid(2.5, 5, 10, GridPlacement::kNodes);
  ASSERT_TRUE(nodes.ok());
  EXPECT_EQ(nodes->theta_i.count, 37u);
  EXPECT_EQ(nodes->theta_o.count, 19u);
  EXPECT_EQ(nodes->phi.count, 19u);
  EXPECT_DOUBLE_EQ(nodes->phi.at(18), 180.0);
}

TEST(RegularGrid, BadStepsAreRefusedNamingTheAxis) {
  for (double bad : {0.0, -1.0, 7.0, 100.0, std::nan("")}) {
    Result<RegularGrid> g = MakeRegularGrid(1, bad, 1, GridPlacement::kCellCentres);
    ASSERT_FALSE(g.ok()) << bad;
    EXPECT_EQ(g.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(g.status().message().find("θo"), std::string::npos) << g.status().message();
  }
  EXPECT_FALSE(MakeRegularGrid(1, 1, 7, GridPlacement::kNodes).ok());  // 180/7 is not whole
  RegularGrid outside{{0, 1, 91}, {0, 1, 2}, {0, 1, 2}};               // θi up to 90 is fine …
  EXPECT_TRUE(ValidateRegularGrid(outside).ok());
  outside.theta_i.count = 92;  // … 91 is not
  EXPECT_EQ(ValidateRegularGrid(outside).code(), StatusCode::kInvalidArgument);
}

TEST(Npy, HeaderParsesAndAlignsTheData) {
  for (const std::vector<std::size_t>& shape :
       {std::vector<std::size_t>{90, 90, 180, 101}, {5}, {3, 4}, {1234567, 2, 3, 4}}) {
    const std::string h = NpyHeader(shape);
    const ParsedNpy p = ParseNpy(h);
    ASSERT_TRUE(p.ok) << h;
    EXPECT_EQ(p.descr, "<f8");
    EXPECT_FALSE(p.fortran);
    EXPECT_EQ(p.shape, shape);
    EXPECT_EQ(p.data_offset, h.size());
    EXPECT_EQ(h.size() % 64, 0u);
  }
  // A one-dimensional shape is a Python one-element tuple.
  EXPECT_NE(NpyHeader(std::vector<std::size_t>{5}).find("(5,)"), std::string::npos);
}

// PatternSource on a 9 × 6 × 6 grid of 3 bands, written as .npy of `type` and kept in memory.
struct PatternNpy {
  std::string bytes;
  ParsedNpy parsed;
  MemoryGrid memory;
};
PatternNpy WritePatternNpy(NpyType type) {
  PatternNpy out;
  Result<RegularGrid> grid = MakeRegularGrid(10, 15, 30, GridPlacement::kCellCentres);
  EXPECT_TRUE(grid.ok());
  if (!grid.ok()) return out;
  const WavelengthGrid bands{400, 100, 3};
  std::ostringstream file;
  NpyGridWriter npy(file, type);
  EXPECT_TRUE(ResampleOnGrid(PatternSource, *grid, bands, {}, LongContext(), npy).ok());
  EXPECT_TRUE(ResampleOnGrid(PatternSource, *grid, bands, {}, LongContext(), out.memory).ok());
  out.bytes = file.str();
  out.parsed = ParseNpy(out.bytes);
  return out;
}

// Value `i` of the file's data as little-endian IEEE-754 `Float`, whatever the host's order.
template <typename Float, typename Bits>
Float LittleEndianValue(const PatternNpy& f, std::size_t i) {
  Bits bits = 0;
  for (std::size_t b = 0; b < sizeof(Bits); ++b) {
    bits |= static_cast<Bits>(
                static_cast<unsigned char>(f.bytes[f.parsed.data_offset + sizeof(Bits) * i + b]))
            << (8 * b);
  }
  Float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

TEST(Npy, GridFileHoldsTheValuesInCOrderAsLittleEndianDoubles) {
  const PatternNpy f = WritePatternNpy(NpyType::kFloat64);
  ASSERT_TRUE(f.parsed.ok);
  EXPECT_EQ(f.parsed.descr, "<f8");
  EXPECT_EQ(f.parsed.shape, (std::vector<std::size_t>{9, 6, 6, 3}));
  ASSERT_EQ(f.bytes.size(), f.parsed.data_offset + 9 * 6 * 6 * 3 * 8);
  for (std::size_t i = 0; i < f.memory.values().size(); ++i) {
    const double v = LittleEndianValue<double, std::uint64_t>(f, i);
    const double want = f.memory.values()[i];
    if (std::isnan(want)) {
      EXPECT_TRUE(std::isnan(v));
    } else {
      EXPECT_EQ(v, want);
    }
  }
  // Cell (θi index 2, θo index 3, φ index 4), band 1: θi 25, θo 52.5, φ 135.
  EXPECT_EQ(f.memory.spectrum(2, 3, 4)[1], 25 + 100 * 52.5 + 1e4 * 135 + 1e6);
}

TEST(Npy, Float32GridHoldsEachValueRoundedToTheNearestFloat) {
  const PatternNpy f = WritePatternNpy(NpyType::kFloat32);
  ASSERT_TRUE(f.parsed.ok);
  EXPECT_EQ(f.parsed.descr, "<f4");
  EXPECT_EQ(f.parsed.shape, (std::vector<std::size_t>{9, 6, 6, 3}));
  ASSERT_EQ(f.bytes.size(), f.parsed.data_offset + 9 * 6 * 6 * 3 * 4);
  std::size_t nan = 0;
  for (std::size_t i = 0; i < f.memory.values().size(); ++i) {
    const float v = LittleEndianValue<float, std::uint32_t>(f, i);
    const double want = f.memory.values()[i];
    if (std::isnan(want)) {
      EXPECT_TRUE(std::isnan(v));
      ++nan;
    } else {
      EXPECT_EQ(v, static_cast<float>(want)) << "value " << i;
      EXPECT_LE(std::abs(static_cast<double>(v) - want), std::abs(want) * 6e-8) << "value " << i;
    }
  }
  EXPECT_LT(nan, f.memory.values().size());
}

TEST(Grid, CellsTheSourceCannotFillAreNaNAndCounted) {
  Result<RegularGrid> grid = MakeRegularGrid(5, 5, 5, GridPlacement::kCellCentres);
  ASSERT_TRUE(grid.ok());
  const WavelengthGrid bands{400, 50, 4};
  MemoryGrid memory;
  Result<GridReport> report =
      ResampleOnGrid(PatternSource, *grid, bands, {}, LongContext(), memory);
  ASSERT_TRUE(report.ok());
  // Expected counts, from the axes: θi > 60 → 6 of 18 values; φ < 30 → 6 of 36 values.
  const std::size_t cells = 18 * 18 * 36;
  const std::size_t outside = 6 * 18 * 36;
  const std::size_t empty = 12 * 18 * 6;
  EXPECT_EQ(report->cells, cells);
  EXPECT_EQ(report->by_status.at(interp::InterpStatus::kOutsideHull), outside);
  EXPECT_EQ(report->by_status.at(interp::InterpStatus::kEmptyOctant), empty);
  EXPECT_EQ(report->nan_cells, outside + empty);
  EXPECT_EQ(report->filled, cells - outside - empty);
  std::size_t nan_cells = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    const bool ok = memory.statuses()[c] == interp::InterpStatus::kOk;
    for (std::size_t b = 0; b < bands.count; ++b) {
      EXPECT_EQ(std::isnan(memory.values()[c * bands.count + b]), !ok);
    }
    nan_cells += !ok;
  }
  EXPECT_EQ(nan_cells, report->nan_cells);
  EXPECT_NE(report->Summary().find(std::to_string(empty) + " empty_octant"), std::string::npos);
}

class InterpolatedGrid : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::optional<testing::PaintGridSamples> samples = testing::PaintLikeGridSamples();
    ASSERT_TRUE(samples.has_value());
    bands_ = samples->derived.grid;
    auto interpolator = interp::MakeInterpolator(interp::Method::kOctant, samples->set);
    ASSERT_TRUE(interpolator.ok());
    interpolator_ = std::move(*interpolator);
  }
  WavelengthGrid bands_;
  std::unique_ptr<interp::Interpolator> interpolator_;
};

TEST_F(InterpolatedGrid, ParallelIsBitIdenticalToSerialAndMatchesTheInterpolator) {
  Result<RegularGrid> grid = MakeRegularGrid(3, 3, 6, GridPlacement::kNodes);
  ASSERT_TRUE(grid.ok());
  const SpectrumSource source = InterpolatorSource(*interpolator_);
  MemoryGrid serial, parallel;
  std::ostringstream npy1, npy4;
  NpyGridWriter w1(npy1), w4(npy4);
  RunControl one{1, {}}, four{4, {}};
  ASSERT_TRUE(ResampleOnGrid(source, *grid, bands_, one, LongContext(), serial).ok());
  ASSERT_TRUE(ResampleOnGrid(source, *grid, bands_, four, LongContext(), parallel).ok());
  ASSERT_TRUE(ResampleOnGrid(source, *grid, bands_, one, LongContext(), w1).ok());
  ASSERT_TRUE(ResampleOnGrid(source, *grid, bands_, four, LongContext(), w4).ok());
  ASSERT_EQ(serial.values().size(), parallel.values().size());
  EXPECT_EQ(std::memcmp(serial.values().data(), parallel.values().data(),
                        serial.values().size() * sizeof(double)),
            0);
  EXPECT_EQ(serial.statuses(), parallel.statuses());
  EXPECT_EQ(npy1.str(), npy4.str());
  // Some cells fail (the octant method at the edges of the data), and they are the ones the
  // interpolator itself refuses.
  EXPECT_GT(serial.report().nan_cells, 0u);
  EXPECT_GT(serial.report().filled, 0u);
  for (std::size_t i = 0; i < grid->theta_i.count; i += 7) {
    for (std::size_t j = 0; j < grid->theta_o.count; j += 5) {
      for (std::size_t k = 0; k < grid->phi.count; k += 3) {
        const double q[3] = {grid->theta_i.at(i), grid->theta_o.at(j), grid->phi.at(k)};
        const interp::Interpolation direct = interpolator_->Evaluate(q);
        const std::size_t c = serial.CellIndex(i, j, k);
        ASSERT_EQ(serial.statuses()[c], direct.status);
        if (direct.status == interp::InterpStatus::kOk) {
          for (std::size_t b = 0; b < bands_.count; ++b) {
            EXPECT_EQ(serial.spectrum(i, j, k)[b], direct.spectrum[b]);
          }
        }
      }
    }
  }
}

TEST_F(InterpolatedGrid, InterpolatorSourceSortsItsBatchesWithTheOneByOneAnswers) {
  // The export's product path: an octant interpolator's cells go through SpectraAt in batches
  // large enough to sort by cell, and the grid is the one a source asking cell by cell makes.
  const auto* octant = dynamic_cast<const interp::OctantInterpolator*>(interpolator_.get());
  ASSERT_NE(octant, nullptr);
  Result<RegularGrid> grid = MakeRegularGrid(1, 2, 2, GridPlacement::kCellCentres);
  ASSERT_TRUE(grid.ok());
  const interp::Interpolator& in = *interpolator_;
  const SpectrumSource one_by_one = [&in](const IsoDirection& at, std::span<double> out) {
    const double q[3] = {at.theta_i, at.theta_o, at.phi};
    return in.SpectrumAt(q, out);
  };
  MemoryGrid batched, single;
  ASSERT_TRUE(ResampleOnGrid(InterpolatorSource(in), *grid, bands_, RunControl{2, {}},
                             LongContext(), batched)
                  .ok());
  const std::uint64_t sorted = octant->sorted_queries();
  EXPECT_GT(sorted, grid->cells() * 9 / 10);  // all but a window's short last batch
  ASSERT_TRUE(
      ResampleOnGrid(one_by_one, *grid, bands_, RunControl{2, {}}, LongContext(), single).ok());
  EXPECT_EQ(octant->sorted_queries(), sorted);
  EXPECT_EQ(batched.statuses(), single.statuses());
  ASSERT_EQ(batched.values().size(), single.values().size());
  EXPECT_EQ(std::memcmp(batched.values().data(), single.values().data(),
                        batched.values().size() * sizeof(double)),
            0);
  EXPECT_GT(batched.report().filled, 0u);
  EXPECT_GT(batched.report().nan_cells, 0u);
}

TEST_F(InterpolatedGrid, ProgressRisesToOneAndCancellationStopsTheRun) {
  Result<RegularGrid> grid = MakeRegularGrid(2, 2, 4, GridPlacement::kCellCentres);
  ASSERT_TRUE(grid.ok());
  const SpectrumSource source = InterpolatorSource(*interpolator_);
  std::vector<double> seen;
  RunControl control{2, [&](double f) { seen.push_back(f); }};
  MemoryGrid memory;
  ASSERT_TRUE(ResampleOnGrid(source, *grid, bands_, control, LongContext(), memory).ok());
  ASSERT_GT(seen.size(), 10u);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1.0), 1);

  // Cancelled a third of the way through, from the progress callback (as a gRPC handler would
  // when its client goes away).
  CancelToken token;
  seen.clear();
  RunControl cancelling{2, [&](double f) {
                          seen.push_back(f);
                          if (f > 0.33) token.Cancel("client went away");
                        }};
  MemoryGrid partial;
  Result<GridReport> r =
      ResampleOnGrid(source, *grid, bands_, cancelling, LongContext(token), partial);
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_NE(r.status().message().find("client went away"), std::string::npos);
  EXPECT_LT(seen.back(), 0.5);
  // A deadline in the past stops it too, as kTimeout.
  const CallContext expired = CallContext::WithTimeout(std::chrono::nanoseconds(0));
  EXPECT_EQ(ResampleOnGrid(source, *grid, bands_, {}, expired, partial).status().code(),
            StatusCode::kTimeout);
}

TEST(GridCsv, RowsPerCellWithStatusAndDocumentedHeader) {
  Result<RegularGrid> grid = MakeRegularGrid(15, 30, 45, GridPlacement::kCellCentres);
  ASSERT_TRUE(grid.ok());
  const WavelengthGrid bands{400, 100, 2};
  std::ostringstream out;
  CsvGridWriter csv(out, GridExportInfo{3, "paint", Quantity::kBrdf, "octant", 100, 2});
  Result<GridReport> report = ResampleOnGrid(PatternSource, *grid, bands, {}, LongContext(), csv);
  ASSERT_TRUE(report.ok());
  const auto rows = testing::CsvRows(out.str());
  ASSERT_EQ(rows.size(), 1 + 6 * 3 * 4u);
  EXPECT_EQ(rows[0],
            (std::vector<std::string>{"theta_i", "theta_o", "phi", "status", "400", "500"}));
  std::size_t nan_rows = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const bool ok = rows[i][3] == "ok";
    EXPECT_EQ(rows[i][4] == "nan", !ok);
    nan_rows += !ok;
    if (!ok) {
      const double ti = std::stod(rows[i][0]), phi = std::stod(rows[i][2]);
      EXPECT_EQ(rows[i][3], ti > 60 ? "outside_hull" : "empty_octant") << ti << " " << phi;
    }
  }
  EXPECT_EQ(nan_rows, report->nan_cells);
  std::string comments;
  for (const auto& l : testing::CommentLines(out.str())) comments += l + "\n";
  EXPECT_NE(comments.find("sr⁻¹"), std::string::npos);
  EXPECT_NE(comments.find("degrees"), std::string::npos);
  EXPECT_NE(comments.find(report->Summary()), std::string::npos);

  const std::string json =
      GridDescriptionJson(*grid, bands, {3, "paint", Quantity::kBrdf, "octant", 100, 2}, *report);
  EXPECT_NE(json.find("\"shape\": [6, 3, 4, 2]"), std::string::npos) << json;
  EXPECT_NE(json.find("\"nan_cells\": " + std::to_string(report->nan_cells)), std::string::npos);
}

}  // namespace
}  // namespace brdf::exports

namespace brdf::exports {
namespace {

// PatternSource's value and three more planes derived from it (as the uncertain fill chain
// answers: value, u, u_measurement, u_interpolation), NaN rows where it has none.
interp::InterpStatus PlanesSource(const IsoDirection& at, std::span<double> row) {
  const std::size_t bands = row.size() / kUncertainPlanes;
  const interp::InterpStatus st = PatternSource(at, row.first(bands));
  if (st != interp::InterpStatus::kOk) return st;
  for (std::size_t p = 1; p < kUncertainPlanes; ++p) {
    for (std::size_t b = 0; b < bands; ++b)
      row[p * bands + b] = 0.001 * static_cast<double>(p) * row[b];
  }
  return st;
}

// Each plane's file as its values' own (float32: converted where the plane lies in the rows;
// float64: gathered first), the same bytes either way as the plane written alone.
class NpyPlanes : public ::testing::TestWithParam<NpyType> {};

TEST_P(NpyPlanes, UncertaintyPlanesGoToFilesOfTheValuesShapeAndDtype) {
  const NpyType type = GetParam();
  Result<RegularGrid> grid = MakeRegularGrid(10, 15, 30, GridPlacement::kCellCentres);
  ASSERT_TRUE(grid.ok());
  const WavelengthGrid bands{400, 100, 3};
  std::ostringstream files[kUncertainPlanes];
  std::vector<std::unique_ptr<NpyGridWriter>> writers;
  std::vector<GridSink*> sinks;
  for (std::ostringstream& f : files) {
    writers.push_back(std::make_unique<NpyGridWriter>(f, type));
    sinks.push_back(writers.back().get());
  }
  PlaneSplitSink split(sinks);
  Result<GridReport> report =
      ResampleOnGrid(PlanesSource, *grid, bands, {}, LongContext(), split, kUncertainPlanes);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  MemoryGrid plain;
  ASSERT_TRUE(ResampleOnGrid(PatternSource, *grid, bands, {}, LongContext(), plain).ok());
  EXPECT_EQ(report->filled, plain.report().filled);
  for (std::size_t p = 0; p < kUncertainPlanes; ++p) {
    PatternNpy f;
    f.bytes = files[p].str();
    f.parsed = ParseNpy(f.bytes);
    ASSERT_TRUE(f.parsed.ok) << "plane " << p;
    const bool f32 = type == NpyType::kFloat32;
    EXPECT_EQ(f.parsed.descr, f32 ? "<f4" : "<f8");
    EXPECT_EQ(f.parsed.shape, (std::vector<std::size_t>{9, 6, 6, 3}));
    ASSERT_EQ(f.bytes.size(), f.parsed.data_offset + 9 * 6 * 6 * 3 * (f32 ? 4 : 8));
    for (std::size_t i = 0; i < plain.values().size(); ++i) {
      const double want = plain.values()[i] * (p == 0 ? 1.0 : 0.001 * static_cast<double>(p));
      const double got = f32 ? LittleEndianValue<float, std::uint32_t>(f, i)
                             : LittleEndianValue<double, std::uint64_t>(f, i);
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got)) << "plane " << p << " value " << i;
      } else if (f32) {
        EXPECT_EQ(got, static_cast<float>(want)) << "plane " << p << " value " << i;
      } else {
        EXPECT_EQ(got, want) << "plane " << p << " value " << i;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Npy, NpyPlanes, ::testing::Values(NpyType::kFloat32, NpyType::kFloat64));

TEST(Npy, PlaneSplitRefusesASliceWithoutItsPlanes) {
  MemoryGrid a, b;
  PlaneSplitSink split({&a, &b});
  Result<RegularGrid> grid = MakeRegularGrid(30, 30, 60, GridPlacement::kCellCentres);
  ASSERT_TRUE(grid.ok());
  // One plane per cell where two are due: the same source without planes.
  Result<GridReport> report =
      ResampleOnGrid(PatternSource, *grid, {400, 100, 2}, {}, LongContext(), split);
  EXPECT_FALSE(report.ok());
}

}  // namespace
}  // namespace brdf::exports
