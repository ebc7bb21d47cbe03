// LazyStage (daemon/api/appearance_stage.h), the lit sphere's fill-chain stages made on first use:
//   - a stage nobody asks for is never made, and a failure it would have had never shows;
//   - the first lookup makes it once, on the calling thread, and every lookup answers from it;
//   - a stage started beforehand is made on another thread, and the lookup waits for that one
//     (made once); its failure shows once a lookup asked;
//   - a start nobody asked for is cancelled when the stage goes, and waited for.
#include "daemon/api/appearance_stage.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

namespace brdf::daemon {
namespace {

using interp::InterpStatus;

// A source answering 1 in every band.
exports::SpectrumSource Ones() {
  return [](const IsoDirection&, std::span<double> out) {
    for (double& v : out) v = 1;
    return InterpStatus::kOk;
  };
}

TEST(LazyStageTest, AStageNobodyAsksForIsNeverMadeAndItsFailureNeverShows) {
  int makes = 0;
  {
    LazyStage stage([&makes](const CancelToken&) -> Result<exports::SpectrumSource> {
      ++makes;
      return FailedPrecondition("no readings");
    });
    exports::SpectrumSource source = stage.Source();
    EXPECT_EQ(stage.error(), "");
    EXPECT_TRUE(stage.Lasting());
  }
  EXPECT_EQ(makes, 0);
}

TEST(LazyStageTest, TheFirstLookupMakesItOnceOnTheCallingThread) {
  int makes = 0;
  std::thread::id made_on;
  LazyStage stage([&](const CancelToken&) -> Result<exports::SpectrumSource> {
    ++makes;
    made_on = std::this_thread::get_id();
    return Ones();
  });
  const exports::SpectrumSource source = stage.Source();
  std::vector<double> out(3, 0);
  EXPECT_EQ(source({45, 0, 0}, out), InterpStatus::kOk);
  EXPECT_EQ(source({30, 20, 10}, out), InterpStatus::kOk);
  EXPECT_EQ(out, std::vector<double>(3, 1));
  EXPECT_EQ(makes, 1);
  EXPECT_EQ(made_on, std::this_thread::get_id());
  EXPECT_EQ(stage.error(), "");
}

TEST(LazyStageTest, AStartedStageIsMadeElsewhereOnceAndItsFailureShowsOnceAsked) {
  std::atomic<int> makes = 0;
  std::thread::id made_on;
  LazyStage stage([&](const CancelToken&) -> Result<exports::SpectrumSource> {
    ++makes;
    made_on = std::this_thread::get_id();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return Timeout("the fit ran past its deadline");
  });
  stage.Start();
  stage.Start();
  const exports::SpectrumSource source = stage.Source();
  std::vector<double> out(3, 7);
  EXPECT_EQ(source({45, 0, 0}, out), InterpStatus::kOutsideHull);
  EXPECT_EQ(out, std::vector<double>(3, 7));
  EXPECT_EQ(makes.load(), 1);
  EXPECT_NE(made_on, std::this_thread::get_id());
  EXPECT_EQ(stage.error(), "the fit ran past its deadline");
  EXPECT_FALSE(stage.Lasting());  // this call's deadline, not the readings'
}

TEST(LazyStageTest, AStartNobodyAskedForIsCancelledAndWaitedForWhenTheStageGoes) {
  std::atomic<bool> saw_cancel = false;
  std::atomic<bool> ended = false;
  {
    LazyStage stage([&](const CancelToken& cancel) -> Result<exports::SpectrumSource> {
      while (!cancel.cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      saw_cancel = true;
      ended = true;
      return Cancelled(cancel.reason());
    });
    stage.Start();
    EXPECT_EQ(stage.error(), "");  // not asked: its cancellation is not this render's error
    EXPECT_TRUE(stage.Lasting());
  }
  EXPECT_TRUE(saw_cancel.load());
  EXPECT_TRUE(ended.load());
}

// NearFallback: the few directions answered near the readings, the whole stage made only after.
struct NearSetup {
  std::shared_ptr<interp::SampleSet> samples = std::make_shared<interp::SampleSet>(3, 2);
  int whole_makes = 0;
  int asked = 0;
  LazyStage whole{[this](const CancelToken&) -> Result<exports::SpectrumSource> {
    ++whole_makes;
    return Ones();
  }};
  NearSetup() {
    // A lattice of readings θi, θo 0…80, φ 0…180: mirrored and swapped, 45°:0° is inside.
    std::int64_t id = 0;
    for (double ti = 0; ti <= 80; ti += 10) {
      for (double to = 0; to <= 80; to += 10) {
        for (double phi = 0; phi <= 180; phi += 30) {
          const std::vector<double> at{ti + 0.01 * id, to, phi};
          const std::vector<double> spectrum{at[0] + at[1], phi};
          EXPECT_TRUE(samples->Add(id++, at, spectrum).ok());
        }
      }
    }
  }
  NearFallback::MakeNear Make() const {
    return [set = samples] {
      interp::Options options;
      options.mirror_phi = true;
      options.reciprocity = true;
      return interp::NearDelaunay::Create(set, options);
    };
  }
};

TEST(NearFallbackTest, AFewDirectionsAreAnsweredWithoutTheWholeStage) {
  NearSetup setup;
  NearFallback fallback(setup.Make(), setup.whole, [&setup] { ++setup.asked; });
  EXPECT_EQ(setup.asked, 0);
  const exports::SpectrumSource source = fallback.Source();
  std::vector<double> out(2, -1);
  EXPECT_EQ(source({45, 0, 0}, out), InterpStatus::kOk);
  EXPECT_NEAR(out[0], 45, 1e-9);  // θi + θo is linear: every blend reproduces it
  EXPECT_EQ(source({89.9, 89.9, 10}, out), InterpStatus::kOutsideHull);  // beyond the readings
  EXPECT_EQ(setup.whole_makes, 0);
  EXPECT_EQ(setup.asked, 1);
  EXPECT_EQ(fallback.near_answers(), 2u);
  EXPECT_EQ(setup.whole.error(), "");
}

TEST(NearFallbackTest, TheWholeStageAnswersFromTheDirectionAfterTheLast) {
  NearSetup setup;
  NearFallback fallback(setup.Make(), setup.whole, [&setup] { ++setup.asked; });
  const exports::SpectrumSource source = fallback.Source();
  std::vector<double> out(2, -1);
  for (std::size_t i = 0; i < NearFallback::kNearDirections; ++i) {
    EXPECT_EQ(source({20.0 + static_cast<double>(i), 30, 40}, out), InterpStatus::kOk);
  }
  EXPECT_EQ(setup.whole_makes, 0);
  EXPECT_EQ(source({45, 0, 0}, out), InterpStatus::kOk);
  EXPECT_EQ(out, std::vector<double>(2, 1));  // the whole stage's answer (Ones)
  EXPECT_EQ(source({20, 30, 40}, out), InterpStatus::kOk);
  EXPECT_EQ(setup.whole_makes, 1);
  EXPECT_EQ(fallback.near_answers(), NearFallback::kNearDirections);
  EXPECT_EQ(setup.asked, 1);
}

TEST(NearFallbackTest, ReadingsItCannotUseGoToTheWholeStage) {
  NearSetup setup;
  NearFallback fallback([] { return Result<interp::NearDelaunay>(InvalidArgument("4D")); },
                        setup.whole, [&setup] { ++setup.asked; });
  const exports::SpectrumSource source = fallback.Source();
  std::vector<double> out(2, -1);
  EXPECT_EQ(source({45, 0, 0}, out), InterpStatus::kOk);
  EXPECT_EQ(out, std::vector<double>(2, 1));
  EXPECT_EQ(setup.whole_makes, 1);
  EXPECT_EQ(setup.asked, 1);
  EXPECT_EQ(fallback.near_answers(), 0u);
}

}  // namespace
}  // namespace brdf::daemon
