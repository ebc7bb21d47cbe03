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

}  // namespace
}  // namespace brdf::daemon
