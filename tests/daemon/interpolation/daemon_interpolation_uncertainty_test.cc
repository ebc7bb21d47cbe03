// Interpolated values carry their uncertainty over gRPC (InterpolateRequest.include_uncertainty,
// docs/uncertainty.md "Interpolated values"), on a session recorded by brdf-sim and brdfd:
//   - the measurement part is the blend of exactly the vertices' stored budgets (as
//     StreamReadings shows them), recomputed here with core/uncertainty/blend.h: the daemon
//     matched each vertex to its own reading's budget;
//   - the white standard, shared by every reading, is carried whole (Σ wᵢ uᵢ), not reduced as if
//     the vertices were independent;
//   - the interpolation term is stated apart and the combined is their quadrature sum;
//   - InterpolateBatch gives the same as Interpolate (its answers carry the measurement and
//     interpolation parts, the shared part when asked, and leave the combined to the client,
//     which gets Interpolate's bits from them); what is not estimated is named.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <vector>

#include "core/uncertainty/blend.h"
#include "tests/daemon/interpolation/rig_test.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

// The API's uncertainties are floats: a value equals its double to within 2⁻²⁴ of itself.
constexpr double kFloatRounding = 0x1p-24;
// The index keeps the budgets' shared contributions as floats (core/uncertainty/blend_budget.h):
// its measurement part is the core blend of the stored budgets in that form (bit for bit, once
// rounded to the API's float), and a sum of their doubles to within a float's rounding of each
// contribution, relative; twice that is allowed here for the signed contributions' sums.
constexpr double kIndexRows = 2 * 0x1p-24;

// combined as brdf.proto defines it from the two float parts (a part not sent counts 0): in
// double, rounded to float. A client computes it so from a batch's answer.
std::vector<float> QuadratureSum(const v1::InterpolationUncertainty& u, int bands) {
  std::vector<float> out(static_cast<std::size_t>(bands));
  for (int k = 0; k < bands; ++k) {
    const double m = k < u.measurement_size() ? u.measurement(k) : 0.0;
    const double i = k < u.interpolation_size() ? u.interpolation(k) : 0.0;
    out[static_cast<std::size_t>(k)] = static_cast<float>(std::sqrt(m * m + i * i));
  }
  return out;
}

uncertainty::Sharing FromProto(v1::UncertaintySharing s) {
  switch (s) {
    case v1::UNCERTAINTY_SHARING_REFERENCE_READING:
      return uncertainty::Sharing::kReferenceReading;
    case v1::UNCERTAINTY_SHARING_DARK_READING:
      return uncertainty::Sharing::kDarkReading;
    case v1::UNCERTAINTY_SHARING_WHITE_STANDARD:
      return uncertainty::Sharing::kWhiteStandard;
    case v1::UNCERTAINTY_SHARING_INSTRUMENT:
      return uncertainty::Sharing::kInstrument;
    default:
      return uncertainty::Sharing::kIndependent;
  }
}

uncertainty::ReadingBudget FromProto(const v1::ReadingUncertainty& u) {
  uncertainty::ReadingBudget b;
  b.combined.assign(u.combined().begin(), u.combined().end());
  b.independent.assign(u.independent().begin(), u.independent().end());
  for (const v1::UncertaintyComponent& c : u.components()) {
    b.components.push_back({c.name(),
                            {FromProto(c.sharing()), c.shared_id()},
                            {c.contribution().begin(), c.contribution().end()}});
  }
  b.not_estimated.assign(u.not_estimated().begin(), u.not_estimated().end());
  return b;
}

class DaemonInterpolationUncertaintyTest : public InterpolationRigTest {
 protected:
  grpc::Status Ask(const std::string& id, const IsoDirection& q, v1::InterpolationMethod method,
                   v1::Quantity quantity, bool with_uncertainty, v1::InterpolationResult* out) {
    v1::InterpolateRequest request;
    request.set_session_id(id);
    request.set_method(method);
    request.set_quantity(quantity);
    *request.mutable_direction() = Iso(q);
    request.set_include_uncertainty(with_uncertainty);
    v1::InterpolateResponse response;
    grpc::Status st = rig_.interpolation().Interpolate(DaemonRig::Context(kAnalystToken).get(),
                                                       request, &response);
    *out = response.result();
    return st;
  }

  // InterpolateBatch at `queries` with include_uncertainty, with and without
  // include_uncertainty_shared, answer for answer against Interpolate's `singles`: the same
  // measurement and interpolation parts (the same floats) and not_estimated; shared only when
  // asked; combined left out, and computed from the parts it is Interpolate's, bit for bit.
  void ExpectBatchAsSingles(const std::string& id, v1::InterpolationMethod method,
                            const std::vector<IsoDirection>& queries,
                            const std::vector<v1::InterpolationResult>& singles) {
    for (bool shared : {false, true}) {
      v1::InterpolateBatchRequest batch;
      batch.set_session_id(id);
      batch.set_method(method);
      batch.set_include_uncertainty(true);
      batch.set_include_uncertainty_shared(shared);
      for (const IsoDirection& q : queries) *batch.add_directions() = Iso(q);
      auto context = DaemonRig::Context(kAnalystToken);
      auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
      v1::InterpolateBatchChunk chunk;
      std::size_t i = 0, ok = 0;
      while (reader->Read(&chunk)) {
        for (const v1::InterpolationResult& r : chunk.results()) {
          ASSERT_LT(i, singles.size());
          const v1::InterpolationResult& one = singles[i];
          const std::string where = "method " + std::to_string(method) + ", direction " +
                                    std::to_string(i) + (shared ? ", with shared" : "");
          ASSERT_EQ(r.status(), one.status()) << where;
          EXPECT_EQ(r.has_uncertainty(), one.has_uncertainty()) << where;
          ++i;
          if (r.status() != v1::INTERPOLATION_STATUS_OK) continue;
          ++ok;
          const v1::InterpolationUncertainty& u = r.uncertainty();
          const v1::InterpolationUncertainty& want = one.uncertainty();
          using Floats = std::vector<float>;
          EXPECT_EQ(Floats(u.measurement().begin(), u.measurement().end()),
                    Floats(want.measurement().begin(), want.measurement().end()))
              << where;
          EXPECT_EQ(Floats(u.interpolation().begin(), u.interpolation().end()),
                    Floats(want.interpolation().begin(), want.interpolation().end()))
              << where;
          EXPECT_EQ(u.combined_size(), 0) << where;
          EXPECT_EQ(QuadratureSum(u, r.spectrum_size()),
                    Floats(want.combined().begin(), want.combined().end()))
              << where;
          if (shared) {
            EXPECT_EQ(Floats(u.shared().begin(), u.shared().end()),
                      Floats(want.shared().begin(), want.shared().end()))
                << where;
          } else {
            EXPECT_EQ(u.shared_size(), 0) << where;
          }
          EXPECT_EQ(
              std::vector<std::string>(u.not_estimated().begin(), u.not_estimated().end()),
              std::vector<std::string>(want.not_estimated().begin(), want.not_estimated().end()))
              << where;
        }
      }
      ASSERT_TRUE(reader->Finish().ok());
      EXPECT_EQ(i, singles.size());
      EXPECT_GE(ok, 3u) << "method " << method << ": too few OK answers to compare";
    }
  }
};

TEST_F(DaemonInterpolationUncertaintyTest, InterpolatedValuesCarryTheirVerticesBudgets) {
  std::string id;
  ASSERT_NO_FATAL_FAILURE(Record(plans::InterpolationGrid().Retry(2, 0), &id));
  Result<std::vector<v1::Reading>> all = rig_.Readings(id);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  std::map<std::int64_t, uncertainty::ReadingBudget> budgets;
  std::vector<const v1::Reading*> samples;
  for (const v1::Reading& r : *all) {
    if (r.kind() != v1::READING_KIND_SAMPLE) continue;
    ASSERT_TRUE(r.has_uncertainty()) << "reading " << r.id() << " has no budget";
    budgets[r.id()] = FromProto(r.uncertainty());
    samples.push_back(&r);
  }
  ASSERT_GE(samples.size(), 10u);

  // Half-way between consecutive readings: inside the data, blends of several readings.
  std::vector<IsoDirection> queries;
  for (std::size_t i = 1; i < samples.size() && queries.size() < 12; ++i) {
    const v1::Reading& a = *samples[i - 1];
    const v1::Reading& b = *samples[i];
    queries.push_back({(a.iso().theta_i() + b.iso().theta_i()) / 2,
                       (a.iso().theta_o() + b.iso().theta_o()) / 2,
                       (a.iso().phi() + b.iso().phi()) / 2});
  }

  int checked = 0;
  std::vector<v1::InterpolationResult> singles;
  uncertainty::NameCodes codes;
  for (const IsoDirection& q : queries) {
    v1::InterpolationResult plain, r;
    ASSERT_TRUE(
        Ask(id, q, v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_BRDF, false, &plain).ok());
    EXPECT_FALSE(plain.has_uncertainty());  // opt-in
    grpc::Status st = Ask(id, q, v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_BRDF, true, &r);
    ASSERT_TRUE(st.ok()) << st.error_message();
    singles.push_back(r);
    if (r.status() != v1::INTERPOLATION_STATUS_OK) continue;
    const v1::InterpolationUncertainty& u = r.uncertainty();
    ASSERT_EQ(u.measurement_size(), r.spectrum_size());
    ASSERT_EQ(u.interpolation_size(), r.spectrum_size());
    ASSERT_EQ(u.combined_size(), r.spectrum_size());
    ASSERT_EQ(u.shared_size(), r.spectrum_size());

    // The daemon's measurement part is the blend of these vertices' own stored budgets.
    std::vector<uncertainty::BlendVertex> vertices;
    std::vector<uncertainty::BlendBudget> blendable;
    blendable.reserve(static_cast<std::size_t>(r.vertices_size()));
    double white = 0;  // Σ wᵢ u_white,ᵢ at band 50
    for (const v1::InterpolationVertex& v : r.vertices()) {
      ASSERT_TRUE(budgets.count(v.reading_id())) << v.reading_id();
      const uncertainty::ReadingBudget& b = budgets[v.reading_id()];
      Result<uncertainty::BlendBudget> made = uncertainty::ToBlendBudget(b, codes);
      ASSERT_TRUE(made.ok()) << made.status().message();
      blendable.push_back(*std::move(made));
      vertices.push_back({v.reading_id(), v.weight(), &blendable.back()});
      const uncertainty::Component* w = b.Find("white_standard");
      ASSERT_NE(w, nullptr);
      white += v.weight() * w->contribution[50];
    }
    Result<uncertainty::BlendedUncertainty> expected =
        uncertainty::BlendMeasurementUncertainty(vertices, r.spectrum_size());
    ASSERT_TRUE(expected.ok()) << expected.status().message();
    for (int k = 0; k < r.spectrum_size(); ++k) {
      const double m = expected->measurement[static_cast<std::size_t>(k)];
      EXPECT_EQ(u.measurement(k), static_cast<float>(m)) << "band " << k;
      EXPECT_GT(u.measurement(k), 0) << "band " << k;
      EXPECT_NEAR(u.combined(k), std::hypot(u.measurement(k), u.interpolation(k)),
                  kFloatRounding * u.combined(k));
    }
    EXPECT_EQ(QuadratureSum(u, r.spectrum_size()),
              std::vector<float>(u.combined().begin(), u.combined().end()));
    // The shared white standard is carried whole, never averaged down.
    EXPECT_GE(u.shared(50), white * (1 - kFloatRounding - kIndexRows));
    ++checked;
  }
  EXPECT_GE(checked, 5);

  // The batch gives the same answers; chunks that could outgrow a message are refused.
  ExpectBatchAsSingles(id, v1::INTERPOLATION_METHOD_DELAUNAY, queries, singles);
  // The octant method (the benchmark's) needs a reading in every orthant: on this small grid it
  // answers few directions, so a lattice over the range is asked (no uncertainty) and the first
  // six it answers, with two it does not, are compared.
  std::vector<IsoDirection> inside;
  {
    v1::InterpolateBatchRequest lattice;
    lattice.set_session_id(id);
    lattice.set_method(v1::INTERPOLATION_METHOD_OCTANT);
    std::vector<IsoDirection> grid;
    for (double ti = 0; ti <= 60; ti += 4) {
      for (double to = 0; to <= 60; to += 4) {
        for (double phi = 0; phi <= 180; phi += 12) grid.push_back({ti, to, phi});
      }
    }
    for (const IsoDirection& q : grid) *lattice.add_directions() = Iso(q);
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.interpolation().InterpolateBatch(context.get(), lattice);
    v1::InterpolateBatchChunk chunk;
    int good = 0, bad = 0;
    while (reader->Read(&chunk)) {
      for (int k = 0; k < chunk.results_size(); ++k) {
        const bool ok = chunk.results(k).status() == v1::INTERPOLATION_STATUS_OK;
        if ((ok && good < 6) || (!ok && bad < 2)) {
          inside.push_back(grid[chunk.first_index() + static_cast<std::size_t>(k)]);
          (ok ? good : bad) += 1;
        }
      }
    }
    ASSERT_TRUE(reader->Finish().ok());
  }
  std::vector<v1::InterpolationResult> octant(inside.size());
  for (std::size_t i = 0; i < inside.size(); ++i) {
    ASSERT_TRUE(
        Ask(id, inside[i], v1::INTERPOLATION_METHOD_OCTANT, v1::QUANTITY_BRDF, true, &octant[i])
            .ok());
  }
  ExpectBatchAsSingles(id, v1::INTERPOLATION_METHOD_OCTANT, inside, octant);
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(id);
  batch.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  batch.set_include_uncertainty(true);
  for (const IsoDirection& q : queries) *batch.add_directions() = Iso(q);
  batch.set_chunk_size(1024);
  {
    auto context = DaemonRig::Context(kAnalystToken);
    auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
    v1::InterpolateBatchChunk chunk;
    while (reader->Read(&chunk)) {
    }
    grpc::Status st = reader->Finish();
    EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(st.error_message().find("chunk_size"), std::string::npos) << st.error_message();
  }

  // What cannot be estimated is named: the reflectance's measurement part (budgets are of the
  // BRDF), the nearest method's interpolation term.
  v1::InterpolationResult reflectance, nearest;
  ASSERT_TRUE(Ask(id, queries[0], v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_REFLECTANCE, true,
                  &reflectance)
                  .ok());
  if (reflectance.status() == v1::INTERPOLATION_STATUS_OK) {
    EXPECT_EQ(reflectance.uncertainty().measurement_size(), 0);
    ASSERT_GE(reflectance.uncertainty().not_estimated_size(), 1);
    EXPECT_NE(reflectance.uncertainty().not_estimated(0).find("BRDF"), std::string::npos);
  }
  ASSERT_TRUE(
      Ask(id, queries[0], v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_BRDF, true, &nearest)
          .ok());
  ASSERT_EQ(nearest.status(), v1::INTERPOLATION_STATUS_OK);
  EXPECT_EQ(nearest.uncertainty().interpolation_size(), 0);
  EXPECT_EQ(nearest.uncertainty().measurement_size(), nearest.spectrum_size());
  bool named = false;
  for (const std::string& s : nearest.uncertainty().not_estimated()) {
    named = named || s.rfind("interpolation:", 0) == 0;
  }
  EXPECT_TRUE(named);
}

}  // namespace
}  // namespace brdf::testing
