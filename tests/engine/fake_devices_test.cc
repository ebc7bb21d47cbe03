// The in-process fakes the engine tests stand on (tests/support/fakes/devices.h) do what their
// contract says: injected failures, delays, a dropped link, cancellation, a pose-dependent
// spectrum.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "tests/support/fakes/devices.h"

namespace brdf::testing {
namespace {

using namespace std::chrono_literals;

class FakeDevicesTest : public ::testing::Test {
 protected:
  CallContext Ctx(std::chrono::milliseconds timeout = 2s, CancelToken cancel = CancelToken()) {
    return CallContext::WithTimeout(timeout, cancel);
  }
  Result<drivers::SpectrumReport> Read() {
    BRDF_ASSIGN_OR_RETURN(drivers::MeasuredSpectrum taken, meter_.MeasureSpectrum(Ctx(), nullptr));
    return taken.report;
  }

  std::shared_ptr<FakeBench> bench_ = std::make_shared<FakeBench>();
  std::shared_ptr<FakeFaultSwitch> meter_faults_ = std::make_shared<FakeFaultSwitch>();
  std::shared_ptr<FakeFaultSwitch> stage_faults_ = std::make_shared<FakeFaultSwitch>();
  FakeMeter meter_{bench_, meter_faults_};
  FakeStage stage_{bench_, stage_faults_};
};

TEST_F(FakeDevicesTest, SpectrumFollowsThePoseAndWhatIsMounted) {
  ASSERT_TRUE(meter_.Connect(Ctx()).ok());
  ASSERT_TRUE(stage_.Connect(Ctx()).ok());
  ASSERT_TRUE(meter_.Configure({.integration_ms = 100}, Ctx()).ok());
  ASSERT_TRUE(stage_.MoveTo({.alpha = 0.0, .beta = 0.0, .delta = 30.0}, Ctx()).ok());
  auto a = Read();
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  ASSERT_TRUE(stage_.MoveTo({.alpha = 40.0, .delta = 60.0}, Ctx()).ok());
  EXPECT_EQ(stage_.ReadPose(Ctx())->alpha, 40.0);
  auto b = Read();
  ASSERT_TRUE(b.ok());
  ASSERT_EQ(a->radiance.size(), WavelengthGrid::Pr650().count);
  EXPECT_NE(a->radiance[50], b->radiance[50]);
  bench_->SetMounted(FakeTarget::kWhite);
  auto white = Read();
  ASSERT_TRUE(white.ok());
  EXPECT_GT(white->radiance[50], b->radiance[50]);
  bench_->SetMounted(FakeTarget::kDark);
  auto dark = Read();
  ASSERT_TRUE(dark.ok());
  EXPECT_LT(dark->radiance[50], b->radiance[50] * 0.01);
  EXPECT_EQ(dark->quality_code, 10);
}

TEST_F(FakeDevicesTest, FailsTheNextNCallsThenRecovers) {
  ASSERT_TRUE(meter_.Connect(Ctx()).ok());
  FakeFaults faults;
  faults.fail_next = 2;
  faults.failure = DeviceError(14, "quality 14");
  meter_faults_->Set(faults);
  EXPECT_EQ(meter_.Measure(Ctx()).status().device_code(), 14);
  EXPECT_EQ(meter_.Measure(Ctx()).status().code(), StatusCode::kDeviceError);
  EXPECT_TRUE(meter_.Measure(Ctx()).ok());
  EXPECT_EQ(meter_faults_->counts().calls, 3);
  EXPECT_EQ(meter_faults_->counts().failures, 2);
}

TEST_F(FakeDevicesTest, DelayRunsIntoTheDeadlineAndCancelEndsTheWait) {
  ASSERT_TRUE(stage_.Connect(Ctx()).ok());
  FakeFaults slow;
  slow.delay = 500ms;
  stage_faults_->Set(slow);
  EXPECT_EQ(stage_.MoveTo({.beta = 10.0}, Ctx(50ms)).code(), StatusCode::kTimeout);
  CancelToken cancel;
  std::thread canceller([cancel]() mutable {
    std::this_thread::sleep_for(30ms);
    cancel.Cancel("pause");
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(stage_.MoveTo({.beta = 20.0}, Ctx(2s, cancel)).code(), StatusCode::kCancelled);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 400ms);
  canceller.join();
  EXPECT_EQ(stage_.ReadPose(Ctx())->beta, 0.0);  // neither move arrived
}

TEST_F(FakeDevicesTest, UnreachableDropsTheLinkAndRefusesToReconnect) {
  ASSERT_TRUE(meter_.Connect(Ctx()).ok());
  FakeFaults gone;
  gone.unreachable = true;
  meter_faults_->Set(gone);
  EXPECT_EQ(meter_.Measure(Ctx()).status().code(), StatusCode::kDisconnected);
  EXPECT_FALSE(meter_.connected());
  EXPECT_EQ(meter_.Connect(Ctx()).code(), StatusCode::kDisconnected);
  meter_faults_->Set(FakeFaults());
  EXPECT_TRUE(meter_.Connect(Ctx()).ok());
  EXPECT_TRUE(meter_.Identify(Ctx()).ok());
}

TEST_F(FakeDevicesTest, StageRefusesTargetsOutsideTravel) {
  ASSERT_TRUE(stage_.Connect(Ctx()).ok());
  EXPECT_EQ(stage_.MoveTo({.alpha = 120.0}, Ctx()).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(stage_.MoveTo({.gamma = 10.0}, Ctx()).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace brdf::testing
