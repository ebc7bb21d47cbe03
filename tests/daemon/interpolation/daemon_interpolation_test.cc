// Interpolation over gRPC against the simulator's ground truth. brdf-sim runs noiseless
// (--noise-scale 0) so that every difference has a known cause:
//   1. the daemon's quantities are exactly what its provenance says: the test recomputes
//      radiance, reflectance and BRDF of every vertex from the raw readings (StreamReadings)
//      and blends them with the returned weights (agreement to 1e-9, relative);
//   2. each measured BRDF equals the virtual sample's true BRDF at the reading's directions
//      within kMeasuredTolerance (see there);
//   3. the interpolated BRDF equals the true BRDF at the query within a bound derived from the
//      virtual sample's model (GlossBound, below), at queries half-way between neighbouring
//      readings (inside the data's hull).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>
#include <thread>

#include "core/analytic_brdf.h"
#include "core/geometry.h"
#include "tests/daemon/interpolation/derived_readings.h"
#include "tests/daemon/interpolation/rig_test.h"
#include "tests/support/daemon/test_rig.h"
#include "tests/support/plan_fixtures.h"
#include "tools/brdf-sim/optics/optics.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

// Two detector positions, three tilts, β every 10° while lamp and detector stay within 40° of
// the normal: a small 3D cloud of (θi, θo, φ) readings. Darks with each reference.
const std::string kGridPlan = plans::InterpolationGrid().Retry(2, 0);

// A measured BRDF vs the truth at the reading's directions: the meter prints 4 significant
// digits (%.3E: ≤ 0.05 % per value, in I, I0 and D), and the stage's position is quantised to
// one count (0.036°), which moves a reading along the glossy lobe (exponent 60: a relative slope
// of at most 60·tan θh per radian, ≤ 0.4 % per count where the lobe is steepest in this grid).
// 1 % covers both with margin.
constexpr double kMeasuredTolerance = 0.01;

// The interpolated BRDF vs the truth at the query. The virtual sample (AnalyticBrdf::PaintLike,
// core/analytic_brdf.h) is f(λ) = albedo(λ)/π + g(θh): a Lambertian part constant in angle plus
// a spectrally flat glossy lobe g = w·(e+8)/(8π)·cos^e θh of the half-vector's angle θh. Weights
// that sum to 1 reproduce the constant part exactly, so the interpolation error of the truth is
// Σ w_k g(v_k) − g(q), which lies within [−G, G] for G = max g over the query and the vertices
// (g ≥ 0). With the measurement error of check 2 (ε = kMeasuredTolerance of each vertex's
// largest band) the daemon's answer must satisfy, in every band,
//   |f̂(q) − f(q)| ≤ G + ε·(max f(q) + G).
// Away from the highlight G is small (θh ≥ 20°: G ≤ 0.005 sr⁻¹, ~2 % of the spectrum), so the
// check is tight there; near it, G bounds what linear interpolation can do on a 10° grid.
double GlossBound(const IsoDirection& d) {
  const AnalyticBrdfParams p = AnalyticBrdf::PaintLike().params();
  const double r = std::numbers::pi / 180;
  const double cos_i = std::cos(d.theta_i * r), cos_o = std::cos(d.theta_o * r);
  const double cos_delta =
      cos_i * cos_o + std::sin(d.theta_i * r) * std::sin(d.theta_o * r) * std::cos(d.phi * r);
  const double cos_h = (cos_i + cos_o) / std::sqrt(std::max(1e-12, 2 + 2 * cos_delta));
  return p.specular_weight * (p.exponent_x + 8) / (8 * std::numbers::pi) *
         std::pow(std::clamp(cos_h, 0.0, 1.0), p.exponent_x);
}

using Derived = DerivedReading;

std::vector<double> Truth(const IsoDirection& iso) {
  return sim::TrueBrdf(CanonicalDirections(iso), /*anisotropic=*/false);
}

// max_b |a_b − t_b| / max_b |t_b|.
double MaxRelativeError(const std::vector<double>& a, const std::vector<double>& t) {
  double max_diff = 0, max_t = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    max_diff = std::max(max_diff, std::abs(a[i] - t[i]));
    max_t = std::max(max_t, std::abs(t[i]));
  }
  return max_diff / max_t;
}

class DaemonInterpolationTest : public InterpolationRigTest {};

TEST_F(DaemonInterpolationTest, InterpolatedSpectraFollowTheirProvenanceAndMatchTheTruth) {
  Result<v1::Session> submitted = rig_.Submit(kGridPlan);
  ASSERT_TRUE(submitted.ok()) << submitted.status().ToString();
  const std::string id = submitted->session_id();
  op_ = std::make_unique<GrpcOperator>(rig_, id);

  // While the session runs, the index follows the readings as they land: the nearest reading to
  // the newest reading's direction is that reading, query after query.
  int fresh_checks = 0;
  std::int64_t last_checked = 0;
  for (int round = 0; round < 400 && fresh_checks < 3; ++round) {
    Result<std::vector<v1::Reading>> so_far = rig_.Readings(id);
    ASSERT_TRUE(so_far.ok());
    const v1::Reading* newest = nullptr;
    for (const auto& r : *so_far) {
      if (r.kind() == v1::READING_KIND_SAMPLE) newest = &r;
    }
    if (newest != nullptr && newest->id() != last_checked) {
      v1::InterpolationResult result;
      grpc::Status st = Interpolate(
          id, Iso({newest->iso().theta_i(), newest->iso().theta_o(), newest->iso().phi()}),
          v1::INTERPOLATION_METHOD_NEAREST, v1::QUANTITY_RADIANCE, &result);
      ASSERT_TRUE(st.ok()) << st.error_message();
      ASSERT_EQ(result.vertices_size(), 1);
      EXPECT_EQ(result.vertices(0).reading_id(), newest->id());
      last_checked = newest->id();
      ++fresh_checks;
    }
    if (IsTerminal(rig_.Get(id)->state())) break;
    std::this_thread::sleep_for(150ms);
  }
  EXPECT_GE(fresh_checks, 2);

  const v1::Session done = rig_.WaitForState(id, v1::SESSION_STATE_COMPLETED, 60s);
  ASSERT_EQ(done.state(), v1::SESSION_STATE_COMPLETED) << done.DebugString();
  Result<std::vector<v1::Reading>> all = rig_.Readings(id);
  ASSERT_TRUE(all.ok()) << all.status().ToString();
  std::map<std::int64_t, v1::Reading> by_id;
  for (const auto& r : *all) by_id[r.id()] = r;
  std::map<std::int64_t, Derived> derived;
  std::vector<const v1::Reading*> samples;
  for (const auto& r : *all) {
    if (r.kind() != v1::READING_KIND_SAMPLE) continue;
    samples.push_back(&by_id[r.id()]);
    derived[r.id()] = DeriveReading(r, by_id);
  }
  ASSERT_GE(samples.size(), 20u);

  // 2. The measurement chain: each reading's BRDF is the truth at its directions.
  for (const v1::Reading* r : samples) {
    const Derived& d = derived[r->id()];
    EXPECT_LT(MaxRelativeError(d.brdf, sim::TrueBrdf(d.directions, /*anisotropic=*/false)),
              kMeasuredTolerance)
        << "reading " << r->id() << " " << r->label();
  }

  // Queries half-way between readings taken one after the other at the same δ and α (β
  // neighbours): on a segment between two readings, so inside the readings' convex hull.
  std::vector<IsoDirection> queries;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    const v1::Reading& a = *samples[i - 1];
    const v1::Reading& b = *samples[i];
    if (a.pose().delta() != b.pose().delta() || a.pose().alpha() != b.pose().alpha()) continue;
    queries.push_back({(a.iso().theta_i() + b.iso().theta_i()) / 2,
                       (a.iso().theta_o() + b.iso().theta_o()) / 2,
                       (a.iso().phi() + b.iso().phi()) / 2});
  }
  ASSERT_GE(queries.size(), 10u);

  double worst_max = 0, worst_ratio = 0;
  int octant_ok = 0;
  std::vector<v1::InterpolationResult> singles;
  for (const IsoDirection& q : queries) {
    v1::InterpolationResult brdf;
    grpc::Status st =
        Interpolate(id, Iso(q), v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_BRDF, &brdf);
    ASSERT_TRUE(st.ok()) << st.error_message();
    ASSERT_EQ(brdf.status(), v1::INTERPOLATION_STATUS_OK) << brdf.detail();
    EXPECT_EQ(brdf.method(), v1::INTERPOLATION_METHOD_DELAUNAY);
    EXPECT_EQ(brdf.quantity(), v1::QUANTITY_BRDF);
    EXPECT_EQ(brdf.grid().count(), 101u);
    ASSERT_EQ(brdf.vertices_size(), 4);
    ASSERT_EQ(brdf.spectrum_size(), 101);
    singles.push_back(brdf);

    // 1. Provenance: the spectrum is the weighted blend of the named readings' BRDFs.
    double weight_sum = 0;
    std::vector<double> blend(101, 0.0);
    for (const auto& v : brdf.vertices()) {
      ASSERT_TRUE(derived.count(v.reading_id())) << v.reading_id();
      const Derived& d = derived[v.reading_id()];
      EXPECT_GE(v.weight(), 0);
      weight_sum += v.weight();
      ASSERT_EQ(v.coords_size(), 3);
      EXPECT_NEAR(v.coords(0), d.iso.theta_i, 1e-9);
      EXPECT_NEAR(v.coords(1), d.iso.theta_o, 1e-9);
      EXPECT_NEAR(v.coords(2), d.iso.phi, 1e-9);
      for (int b = 0; b < 101; ++b) blend[static_cast<std::size_t>(b)] += v.weight() * d.brdf[b];
    }
    EXPECT_NEAR(weight_sum, 1.0, 1e-9);
    for (int b = 0; b < 101; ++b) {
      EXPECT_NEAR(brdf.spectrum(b), blend[static_cast<std::size_t>(b)],
                  1e-9 * std::abs(blend[static_cast<std::size_t>(b)]));
    }

    // Figure 8 in one call: asked with include_vertex_spectra, each vertex carries its reading's
    // own spectrum in the quantity asked for (as recomputed from the raw readings), and the
    // answer is their blend with its weights; asked without (above), the vertices carry none.
    for (const auto& v : brdf.vertices()) EXPECT_EQ(v.spectrum_size(), 0);
    {
      v1::InterpolateRequest request;
      request.set_session_id(id);
      request.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
      request.set_quantity(v1::QUANTITY_REFLECTANCE);
      *request.mutable_direction() = Iso(q);
      request.set_include_vertex_spectra(true);
      v1::InterpolateResponse response;
      const grpc::Status called = rig_.interpolation().Interpolate(
          DaemonRig::Context(kAnalystToken).get(), request, &response);
      ASSERT_TRUE(called.ok()) << called.error_message();
      const v1::InterpolationResult& with = response.result();
      ASSERT_EQ(with.vertices_size(), 4);
      ASSERT_EQ(with.spectrum_size(), 101);
      std::vector<double> blended(101, 0.0);
      for (const auto& v : with.vertices()) {
        ASSERT_EQ(v.spectrum_size(), 101) << "vertex " << v.reading_id();
        const Derived& d = derived[v.reading_id()];
        for (int b = 0; b < 101; ++b) {
          EXPECT_NEAR(v.spectrum(b), d.reflectance[b], 1e-9 * std::abs(d.reflectance[b]));
          blended[static_cast<std::size_t>(b)] += v.weight() * v.spectrum(b);
        }
      }
      for (int b = 0; b < 101; ++b) {
        EXPECT_NEAR(with.spectrum(b), blended[static_cast<std::size_t>(b)],
                    1e-9 * std::abs(blended[static_cast<std::size_t>(b)]));
      }
    }

    // The weights reproduce the query from the vertices (barycentric coordinates): the simplex
    // encloses the query.
    for (int axis = 0; axis < 3; ++axis) {
      double at = 0;
      for (const auto& v : brdf.vertices()) at += v.weight() * v.coords(axis);
      EXPECT_NEAR(at, axis == 0 ? q.theta_i : axis == 1 ? q.theta_o : q.phi, 1e-6);
    }

    // 3. The truth at the query, within the bound derived above kMeasuredTolerance.
    double lobe = GlossBound(q);
    for (const auto& v : brdf.vertices()) {
      lobe = std::max(lobe, GlossBound({v.coords(0), v.coords(1), v.coords(2)}));
    }
    const std::vector<double> truth = Truth(q);
    const double truth_max = *std::max_element(truth.begin(), truth.end());
    const double allowed = lobe + kMeasuredTolerance * (truth_max + lobe);
    double worst_band = 0;
    for (int b = 0; b < 101; ++b) {
      worst_band = std::max(worst_band, std::abs(brdf.spectrum(b) - truth[b]));
    }
    EXPECT_LE(worst_band, allowed) << "θi " << q.theta_i << " θo " << q.theta_o << " φ " << q.phi;
    worst_max = std::max(worst_max, worst_band / truth_max);
    worst_ratio = std::max(worst_ratio, worst_band / allowed);

    // The other quantities blend the same readings with the same weights.
    for (v1::Quantity quantity : {v1::QUANTITY_RADIANCE, v1::QUANTITY_REFLECTANCE}) {
      v1::InterpolationResult other;
      ASSERT_TRUE(
          Interpolate(id, Iso(q), v1::INTERPOLATION_METHOD_DELAUNAY, quantity, &other).ok());
      ASSERT_EQ(other.vertices_size(), 4);
      EXPECT_EQ(other.quantity(), quantity);
      for (int b = 0; b < 101; b += 10) {
        double expected = 0;
        for (const auto& v : other.vertices()) {
          const Derived& d = derived[v.reading_id()];
          expected +=
              v.weight() * (quantity == v1::QUANTITY_RADIANCE ? d.radiance[b] : d.reflectance[b]);
        }
        EXPECT_NEAR(other.spectrum(b), expected, 1e-9 * std::abs(expected));
      }
    }

    // The paper's octant method, with the isotropic symmetries (the data is a thin cloud; the
    // mirrored and reciprocal copies fill octants): where it answers, it blends readings the
    // same way (a copy keeps the id of the reading it copies).
    v1::InterpolationOptions symmetric;
    symmetric.set_mirror_phi(true);
    symmetric.set_reciprocity(true);
    v1::InterpolationResult octant;
    ASSERT_TRUE(Interpolate(id, Iso(q), v1::INTERPOLATION_METHOD_OCTANT, v1::QUANTITY_BRDF, &octant,
                            symmetric)
                    .ok());
    if (octant.status() == v1::INTERPOLATION_STATUS_OK) {
      ++octant_ok;
      double sum = 0;
      std::vector<double> blended(101, 0.0);
      for (const auto& v : octant.vertices()) {
        sum += v.weight();
        const Derived& d = derived[v.reading_id()];
        for (int b = 0; b < 101; ++b)
          blended[static_cast<std::size_t>(b)] += v.weight() * d.brdf[b];
      }
      EXPECT_NEAR(sum, 1.0, 1e-9);
      for (int b = 0; b < 101; b += 10) {
        EXPECT_NEAR(octant.spectrum(b), blended[static_cast<std::size_t>(b)],
                    1e-9 * blended[static_cast<std::size_t>(b)]);
      }
    } else {
      EXPECT_EQ(octant.status(), v1::INTERPOLATION_STATUS_EMPTY_OCTANT) << octant.detail();
      EXPECT_EQ(octant.spectrum_size(), 0);
    }
  }
  std::cout << queries.size() << " queries (octant answered " << octant_ok
            << "); worst Delaunay error vs truth: " << worst_max << " of the spectrum's peak, "
            << worst_ratio << " of the allowed bound\n";

  // Equivalent forms of a direction give the same answer: the four-angle form of an isotropic
  // direction, its azimuths mirrored or turned by 360° (brdf.proto: taken modulo 360). The
  // relative azimuth of `iso` has one form: −φ and φ + 360 are refused, naming the field.
  {
    const IsoDirection q = queries.front();
    for (const auto& [phi_i, phi_o] : std::vector<std::pair<double, double>>{
             {-25, -25 - q.phi}, {25 - 360, 25 + q.phi}, {25, 25 + q.phi - 360}}) {
      v1::DirectionQuery form;
      form.mutable_four()->set_theta_i(q.theta_i);
      form.mutable_four()->set_phi_i(phi_i);
      form.mutable_four()->set_theta_o(q.theta_o);
      form.mutable_four()->set_phi_o(phi_o);
      v1::InterpolationResult same;
      ASSERT_TRUE(
          Interpolate(id, form, v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_BRDF, &same).ok());
      ASSERT_EQ(same.spectrum_size(), 101);
      for (int b = 0; b < 101; ++b) {
        EXPECT_NEAR(same.spectrum(b), singles.front().spectrum(b), 1e-12) << phi_i << ", " << phi_o;
      }
    }
    std::vector<double> outside = {q.phi + 360};
    if (q.phi > 0) outside.push_back(-q.phi);  // (−0 is 0, the same point)
    for (double phi : outside) {
      const v1::DirectionQuery form = Iso({q.theta_i, q.theta_o, phi});
      v1::InterpolationResult refused;
      const grpc::Status st =
          Interpolate(id, form, v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_BRDF, &refused);
      EXPECT_EQ(st.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << form.DebugString();
      EXPECT_NE(st.error_message().find("direction.iso.phi"), std::string::npos)
          << st.error_message();
    }
    v1::DirectionQuery four;
    four.mutable_four()->set_theta_i(q.theta_i);
    four.mutable_four()->set_phi_i(25);
    four.mutable_four()->set_theta_o(q.theta_o);
    four.mutable_four()->set_phi_o(25 + q.phi);
    v1::InterpolationResult same;
    ASSERT_TRUE(
        Interpolate(id, four, v1::INTERPOLATION_METHOD_DELAUNAY, v1::QUANTITY_BRDF, &same).ok());
    for (int b = 0; b < 101; ++b) EXPECT_NEAR(same.spectrum(b), singles.front().spectrum(b), 1e-12);
  }

  // Nearest at a reading's own direction is that reading's BRDF.
  {
    const v1::Reading& r = *samples[samples.size() / 2];
    v1::InterpolationResult nearest;
    ASSERT_TRUE(Interpolate(id, Iso(derived[r.id()].iso), v1::INTERPOLATION_METHOD_NEAREST,
                            v1::QUANTITY_BRDF, &nearest)
                    .ok());
    ASSERT_EQ(nearest.vertices_size(), 1);
    EXPECT_EQ(nearest.vertices(0).reading_id(), r.id());
    EXPECT_EQ(nearest.vertices(0).weight(), 1);
    for (int b = 0; b < 101; ++b) {
      EXPECT_NEAR(nearest.spectrum(b), derived[r.id()].brdf[b], 1e-12);
    }
  }

  // The batch form answers in order, in chunks of chunk_size, from one snapshot: the same
  // results as the single calls.
  v1::InterpolateBatchRequest batch;
  batch.set_session_id(id);
  batch.set_method(v1::INTERPOLATION_METHOD_DELAUNAY);
  batch.set_chunk_size(4);
  for (const IsoDirection& q : queries) *batch.add_directions() = Iso(q);
  auto context = DaemonRig::Context(kAnalystToken);
  auto reader = rig_.interpolation().InterpolateBatch(context.get(), batch);
  v1::InterpolateBatchChunk chunk;
  std::uint32_t expected_first = 0;
  std::size_t chunks = 0;
  while (reader->Read(&chunk)) {
    ++chunks;
    EXPECT_EQ(chunk.first_index(), expected_first);
    EXPECT_LE(chunk.results_size(), 4);
    for (int i = 0; i < chunk.results_size(); ++i) {
      const v1::InterpolationResult& got = chunk.results(i);
      const v1::InterpolationResult& single =
          singles[expected_first + static_cast<std::uint32_t>(i)];
      EXPECT_EQ(got.query().iso().theta_i(), single.query().iso().theta_i());
      ASSERT_EQ(got.spectrum_size(), single.spectrum_size());
      for (int b = 0; b < got.spectrum_size(); ++b) EXPECT_EQ(got.spectrum(b), single.spectrum(b));
    }
    expected_first += static_cast<std::uint32_t>(chunk.results_size());
  }
  grpc::Status st = reader->Finish();
  EXPECT_TRUE(st.ok()) << st.error_message();
  EXPECT_EQ(expected_first, queries.size());
  EXPECT_EQ(chunks, (queries.size() + 3) / 4);
}

}  // namespace
}  // namespace brdf::testing
