// Interpolation in half/difference coordinates over gRPC (InterpolationOptions.coordinates),
// against a real brdfd recording from brdf-sim (noiseless):
//   - brdfd's answers in both coordinates are core/interp's over the same readings (the BRDF
//     recomputed from StreamReadings' raw spectra), for the three methods;
//   - the two coordinates give different answers, and the index cache never answers one with
//     the other's index: incidence, then half/difference, then incidence again on the same
//     session, after both were asked while the session recorded (the octant index extended,
//     the half/difference one rebuilt);
//   - an anisotropic session is refused with INVALID_ARGUMENT naming options.coordinates and
//     what to do; an unknown coordinates value names the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <thread>

#include "core/interp/interpolator.h"
#include "tests/daemon/interpolation/derived_readings.h"
#include "tests/daemon/interpolation/rig_test.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

const std::string kGridPlan = plans::InterpolationGrid().Retry(2, 0);

const std::string kAnisotropicPlan =
    plans::TwoAnisotropicPoses("anisotropic half/difference refusal");

// `symmetries`: mirror_phi and reciprocity too (the grid plan's cloud is thin, and the octant
// method needs the copies to fill octants in (θi, θo, φ)); not on anisotropic sessions.
v1::InterpolationOptions Coordinates(v1::InterpolationCoordinates c, bool symmetries = true) {
  v1::InterpolationOptions o;
  o.set_coordinates(c);
  o.set_mirror_phi(symmetries);
  o.set_reciprocity(symmetries);
  return o;
}

interp::InterpStatus FromProto(v1::InterpolationStatus s) {
  switch (s) {
    case v1::INTERPOLATION_STATUS_EMPTY_OCTANT:
      return interp::InterpStatus::kEmptyOctant;
    case v1::INTERPOLATION_STATUS_NO_ENCLOSING_SIMPLEX:
      return interp::InterpStatus::kNoEnclosingSimplex;
    case v1::INTERPOLATION_STATUS_OUTSIDE_HULL:
      return interp::InterpStatus::kOutsideHull;
    default:
      return interp::InterpStatus::kOk;
  }
}

class DaemonHalfDifferenceTest : public InterpolationRigTest {};

TEST_F(DaemonHalfDifferenceTest, AnswersAreCoresInBothCoordinatesAndTheCacheNeverMixesThem) {
  Result<v1::Session> submitted = rig_.Submit(kGridPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  op_ = std::make_unique<GrpcOperator>(rig_, id);

  // While the session records, octant answers in both coordinates, query after query: the
  // incidence index is extended as readings land, the half/difference one rebuilt (index_build.h).
  const IsoDirection probe{32, 30, 170};
  int rounds_with_both = 0;
  for (int round = 0; round < 400; ++round) {
    if (IsTerminal(rig_.Get(id)->state())) break;
    bool both = true;
    for (v1::InterpolationCoordinates c :
         {v1::INTERPOLATION_COORDINATES_INCIDENCE, v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE}) {
      v1::InterpolationResult r;
      grpc::Status st = Interpolate(id, Iso(probe), v1::INTERPOLATION_METHOD_OCTANT,
                                    v1::QUANTITY_BRDF, &r, Coordinates(c));
      // No sample reading with a BRDF yet: FAILED_PRECONDITION, until the first one lands.
      if (!st.ok()) {
        ASSERT_EQ(st.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << st.error_message();
        both = false;
      }
    }
    if (both) ++rounds_with_both;
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_GE(rounds_with_both, 2);

  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 60s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  Result<std::vector<v1::Reading>> all = rig_.Readings(id);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  std::shared_ptr<interp::SampleSet> set = BrdfSampleSet(*all);
  ASSERT_NE(set, nullptr);
  ASSERT_GE(set->size(), 20u);

  const std::vector<IsoDirection> queries = MidpointQueries(*set);

  for (v1::InterpolationMethod method :
       {v1::INTERPOLATION_METHOD_OCTANT, v1::INTERPOLATION_METHOD_DELAUNAY,
        v1::INTERPOLATION_METHOD_NEAREST}) {
    const interp::Method core_method =
        method == v1::INTERPOLATION_METHOD_OCTANT     ? interp::Method::kOctant
        : method == v1::INTERPOLATION_METHOD_DELAUNAY ? interp::Method::kDelaunay
                                                      : interp::Method::kNearest;
    SCOPED_TRACE(interp::MethodName(core_method));
    // Incidence, half/difference, incidence again: the third must be the first.
    std::vector<v1::InterpolationResult> incidence, half, again;
    grpc::Status st = Batch(id, queries, method, v1::QUANTITY_BRDF, &incidence,
                            Coordinates(v1::INTERPOLATION_COORDINATES_UNSPECIFIED));
    ASSERT_TRUE(st.ok()) << st.error_message();
    st = Batch(id, queries, method, v1::QUANTITY_BRDF, &half,
               Coordinates(v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE));
    ASSERT_TRUE(st.ok()) << st.error_message();
    st = Batch(id, queries, method, v1::QUANTITY_BRDF, &again,
               Coordinates(v1::INTERPOLATION_COORDINATES_INCIDENCE));
    ASSERT_TRUE(st.ok()) << st.error_message();
    ASSERT_EQ(incidence.size(), queries.size());
    ASSERT_EQ(half.size(), queries.size());
    ASSERT_EQ(again.size(), queries.size());

    // Fresh indexes of core/interp over the same readings.
    interp::Options incidence_options;
    incidence_options.mirror_phi = incidence_options.reciprocity = true;
    interp::Options half_options = incidence_options;
    half_options.coordinates = interp::Coordinates::kHalfDifference;
    auto core_incidence = interp::MakeInterpolator(core_method, set, incidence_options);
    auto core_half = interp::MakeInterpolator(core_method, set, half_options);
    ASSERT_TRUE(core_incidence.ok()) << core_incidence.status().ToString();
    ASSERT_TRUE(core_half.ok()) << core_half.status().ToString();

    int differ = 0, half_ok = 0, both_ok = 0;
    for (std::size_t i = 0; i < queries.size(); ++i) {
      const IsoDirection& q = queries[i];
      SCOPED_TRACE("θi " + std::to_string(q.theta_i) + " θo " + std::to_string(q.theta_o) + " φ " +
                   std::to_string(q.phi));
      const double p[3] = {q.theta_i, q.theta_o, q.phi};
      const interp::Interpolation want_incidence = (*core_incidence)->Evaluate(p);
      const interp::Interpolation want_half = (*core_half)->Evaluate(p);
      for (const auto& [got, want] :
           {std::pair{&incidence[i], &want_incidence}, std::pair{&again[i], &want_incidence},
            std::pair{&half[i], &want_half}}) {
        ASSERT_EQ(FromProto(got->status()), want->status) << got->detail() << " / " << want->detail;
        if (want->status != interp::InterpStatus::kOk) continue;
        EXPECT_LT(RelativeGap(got->spectrum(), want->spectrum), 1e-9);
        ASSERT_EQ(static_cast<std::size_t>(got->vertices_size()), want->vertices.size());
        for (int v = 0; v < got->vertices_size(); ++v) {
          EXPECT_EQ(got->vertices(v).reading_id(), want->vertices[static_cast<std::size_t>(v)].id);
          EXPECT_NEAR(got->vertices(v).weight(), want->vertices[static_cast<std::size_t>(v)].weight,
                      1e-9);
        }
      }
      // The third call is the first, bit for bit: nothing of the half/difference index leaked.
      ASSERT_EQ(again[i].spectrum_size(), incidence[i].spectrum_size());
      for (int b = 0; b < again[i].spectrum_size(); ++b) {
        EXPECT_EQ(again[i].spectrum(b), incidence[i].spectrum(b));
      }
      if (half[i].status() == v1::INTERPOLATION_STATUS_OK) {
        ++half_ok;
        // A half/difference vertex names a measured reading and reports the (θi, θo, φ) of the
        // directions it stands for: the reading's, or their swap for a reciprocal image.
        for (const v1::InterpolationVertex& v : half[i].vertices()) {
          bool found = false;
          for (std::size_t k = 0; k < set->size() && !found; ++k) {
            if (set->id(k) != v.reading_id()) continue;
            found = true;
            ASSERT_EQ(v.coords_size(), 3);
            const auto c = set->coords(k);
            auto near = [](double x, double y) { return std::abs(x - y) < 1e-6; };
            const bool same = near(v.coords(0), c[0]) && near(v.coords(1), c[1]);
            const bool swapped = near(v.coords(0), c[1]) && near(v.coords(1), c[0]);
            EXPECT_TRUE(same || swapped) << v.ShortDebugString();
            EXPECT_TRUE(near(std::abs(std::remainder(v.coords(2), 360.0)), c[2]))
                << v.ShortDebugString();
          }
          EXPECT_TRUE(found) << "reading " << v.reading_id();
        }
      }
      if (half[i].status() == v1::INTERPOLATION_STATUS_OK &&
          incidence[i].status() == v1::INTERPOLATION_STATUS_OK) {
        const std::vector<double> inc(incidence[i].spectrum().begin(),
                                      incidence[i].spectrum().end());
        ++both_ok;
        if (RelativeGap(half[i].spectrum(), inc) > 1e-6) ++differ;
      }
    }
    EXPECT_GT(half_ok, 0);
    // The two coordinates are different methods: most blends differ; the nearest reading is
    // often the same one in both metrics, but not always.
    EXPECT_GT(both_ok, 0);
    if (method == v1::INTERPOLATION_METHOD_NEAREST) {
      EXPECT_GT(differ, 0) << differ << " of " << both_ok;
    } else {
      EXPECT_GT(differ, both_ok / 2) << differ << " of " << both_ok;
    }

    // A single call answers as the batch does.
    v1::InterpolationResult single;
    ASSERT_TRUE(Interpolate(id, Iso(queries.back()), method, v1::QUANTITY_BRDF, &single,
                            Coordinates(v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE))
                    .ok());
    EXPECT_EQ(single.status(), half.back().status());
    ASSERT_EQ(single.spectrum_size(), half.back().spectrum_size());
    for (int b = 0; b < single.spectrum_size(); ++b) {
      EXPECT_EQ(single.spectrum(b), half.back().spectrum(b));
    }
  }
}

TEST_F(DaemonHalfDifferenceTest, AnisotropicSessionIsRefusedWithWhatToDo) {
  std::string id;
  ASSERT_NO_FATAL_FAILURE(Record(kAnisotropicPlan, &id));
  const v1::DirectionQuery four = Four(20, 0, 30, 150);
  v1::InterpolationResult result;
  // Incidence coordinates work on the session…
  grpc::Status st =
      Interpolate(id, four, v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE, &result,
                  Coordinates(v1::INTERPOLATION_COORDINATES_INCIDENCE, false));
  ASSERT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(result.status(), v1::INTERPOLATION_STATUS_OK);

  // …half/difference ones are refused, single and batch alike, saying what and what to do.
  st = Interpolate(id, four, v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE, &result,
                   Coordinates(v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE, false));
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  for (const char* part : {"options.coordinates", "isotropic", "anisotropic", "INCIDENCE"}) {
    EXPECT_NE(st.error_message().find(part), std::string::npos) << st.error_message();
  }
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(id);
  batch.set_quantity(v1::QUANTITY_RADIANCE);
  *batch.add_directions() = four;
  *batch.mutable_options() = Coordinates(v1::INTERPOLATION_COORDINATES_HALF_DIFFERENCE, false);
  auto context = DaemonRig::Context(kAnalystToken);
  auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
  v1::InterpolateBatchChunk chunk;
  while (reader->Read(&chunk)) ADD_FAILURE() << "a chunk for a refused batch";
  st = reader->Finish();
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(st.error_message().find("options.coordinates"), std::string::npos)
      << st.error_message();

  // A value the API does not have names the field.
  st = Interpolate(id, four, v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE, &result,
                   Coordinates(static_cast<v1::InterpolationCoordinates>(7), false));
  EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(st.error_message().find("options.coordinates"), std::string::npos)
      << st.error_message();
}

}  // namespace
}  // namespace brdf::testing
