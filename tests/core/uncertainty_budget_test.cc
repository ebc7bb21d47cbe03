// core/uncertainty: the meter's noise model and one reading's budget per band, against numbers
// computed by hand (docs/uncertainty.md) and sensitivity coefficients checked by finite
// differences of the measurement equation, written here independently of the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/uncertainty/budget.h"

namespace brdf::uncertainty {
namespace {

const WavelengthGrid kGrid{500, 4, 3};
constexpr double kDeg = std::numbers::pi / 180.0;

MeasuredSignal Signal(std::int64_t id, std::vector<double> radiance) {
  return MeasuredSignal{id, std::move(radiance), 1000, 4};
}

// Sample 0.050/0.060/0.070, dark 0.001, white 0.201 (so I0 − D = 0.2), 1 s, 4 averages,
// ρw 0.99 ± 0.005, θi 30°, θr 0°, stray 0.001, session 7, reference 11, dark 12, sample 13.
BudgetInputs HandCase() {
  BudgetInputs in;
  in.session_id = 7;
  in.grid = kGrid;
  in.sample = Signal(13, {0.050, 0.060, 0.070});
  in.reference = Signal(11, {0.201, 0.201, 0.201});
  in.dark = Signal(12, {0.001, 0.001, 0.001});
  in.white_reflectance = {0.99};
  in.white_reflectance_u = {0.005};
  in.theta_i_deg = 30;
  in.theta_r_deg = 0;
  in.terms.stray_light = 0.001;
  return in;
}

const Component& Get(const ReadingBudget& budget, const std::string& name) {
  const Component* c = budget.Find(name);
  EXPECT_NE(c, nullptr) << name;
  static const Component kNone{"", {}, std::vector<double>(3, std::nan(""))};
  return c != nullptr ? *c : kNone;
}

TEST(MeterNoise, ShotAndReadNoiseByHand) {
  // 0.06 W·m⁻²·sr⁻¹·nm⁻¹ for 1 s fills 0.06 / 0.04 = 1.5 full scales: 300,000 counts;
  // sqrt(300,000 + 20²) = 548.0876 counts = 1.09618e-4 in radiance; over 4 averages, half.
  Result<std::vector<double>> u = SignalUncertainty({0.06, 0.0, -1.0}, 1000, 4, {});
  ASSERT_TRUE(u.ok()) << u.status().message();
  EXPECT_NEAR((*u)[0], 5.480875842417888e-05, 1e-15);
  // No light: the read noise alone, 20 counts = 4e-6, halved.
  EXPECT_NEAR((*u)[1], 2e-6, 1e-15);
  EXPECT_NEAR((*u)[2], 2e-6, 1e-15);
}

TEST(MeterNoise, AdaptiveIntegrationIsInferredFromTheBrightestBand) {
  const MeterNoiseModel model;
  // 0.5 · 0.04 / 0.2 = 0.1 s; a dark reading lands on the 6 s limit; a blinding one on 10 ms.
  EXPECT_DOUBLE_EQ(IntegrationSeconds({0.1, 0.2}, 0, model), 0.1);
  EXPECT_DOUBLE_EQ(IntegrationSeconds({1e-6, 0.0}, 0, model), 6.0);
  EXPECT_DOUBLE_EQ(IntegrationSeconds({0.0, 0.0}, 0, model), 6.0);
  EXPECT_DOUBLE_EQ(IntegrationSeconds({100.0}, 0, model), 0.01);
  EXPECT_DOUBLE_EQ(IntegrationSeconds({100.0}, 250, model), 0.25);
  Result<std::vector<double>> u = SignalUncertainty({0.2}, 0, 1, model);
  ASSERT_TRUE(u.ok());
  // 0.2 · 0.1 / 0.04 · 2e5 = 100,000 counts: sqrt(100,400) · 0.04 / (0.1 · 2e5).
  EXPECT_NEAR((*u)[0], 6.337191807101945e-4, 1e-15);
}

TEST(MeterNoise, GainRepeatabilityIsNotReducedByAveraging) {
  MeterNoiseModel model;
  model.read_noise_counts = 0;
  model.full_well_counts = 1e30;  // no shot noise to speak of
  model.gain_repeatability = 0.01;
  Result<std::vector<double>> u = SignalUncertainty({0.5}, 100, 50, model);
  ASSERT_TRUE(u.ok());
  EXPECT_NEAR((*u)[0], 0.005, 1e-12);
}

TEST(MeterNoise, BadInputsAreNamed) {
  EXPECT_NE(SignalUncertainty({0.1}, 100, 0, {}).status().message().find("averages"),
            std::string::npos);
  EXPECT_NE(SignalUncertainty({0.1}, -1, 1, {}).status().message().find("integration_ms"),
            std::string::npos);
  EXPECT_NE(SignalUncertainty({std::nan("")}, 100, 1, {}).status().message().find("band 0"),
            std::string::npos);
  MeterNoiseModel bad;
  bad.full_scale = 0;
  EXPECT_NE(SignalUncertainty({0.1}, 100, 1, bad).status().message().find("full_scale"),
            std::string::npos);
}

TEST(ReadingBudget, ComponentsByHand) {
  Result<ReadingBudget> budget = EstimateReadingBudget(HandCase());
  ASSERT_TRUE(budget.ok()) << budget.status().message();
  // Band 1: K = 0.99 / π / cos 30° = 0.363877, R = 0.059 / 0.2 = 0.295, f = K · R.
  EXPECT_NEAR(budget->value[1], 0.1073437359386229, 1e-15);
  // sample: K / (I0 − D) · u(I), u(I) = 5.4809e-5 (MeterNoise.ShotAndReadNoiseByHand).
  EXPECT_NEAR(Get(*budget, "sample_signal").contribution[1], 9.971825239675986e-05, 1e-17);
  // reference: −f / (I0 − D) · u(I0), u(0.201) = sqrt(1,005,000 + 400) · 2e-7 / 2.
  EXPECT_NEAR(Get(*budget, "reference_signal").contribution[1], -5.3816586905305525e-05, 1e-17);
  // dark: K (R − 1) / (I0 − D) · u(D), u(0.001) = sqrt(5,000 + 400) · 2e-7 / 2.
  EXPECT_NEAR(Get(*budget, "dark_signal").contribution[1], -9.425636592927783e-06, 1e-17);
  // white standard: f / ρw · 0.005.
  EXPECT_NEAR(Get(*budget, "white_standard").contribution[1], 5.421400804980955e-04, 1e-16);
  // wavelength: K · (0.345 − 0.245) / 8 nm · 2/√3 nm.
  EXPECT_NEAR(Get(*budget, "wavelength_scale").contribution[1], 5.252113122032547e-03, 1e-15);
  // stray light: K (R − 1) · 0.001.
  EXPECT_NEAR(Get(*budget, "stray_light").contribution[1], -2.5653333503975986e-04, 1e-17);
  // Normal incidence on the white: no first-order reference-pose term.
  EXPECT_EQ(Get(*budget, "reference_pose").contribution[1], 0.0);
}

TEST(ReadingBudget, CombinedAndIndependentParts) {
  Result<ReadingBudget> budget = EstimateReadingBudget(HandCase());
  ASSERT_TRUE(budget.ok());
  for (std::size_t b = 0; b < 3; ++b) {
    double all = 0, independent = 0;
    for (const Component& c : budget->components) {
      all += c.contribution[b] * c.contribution[b];
      if (c.shared.kind == Sharing::kIndependent)
        independent += c.contribution[b] * c.contribution[b];
    }
    EXPECT_DOUBLE_EQ(budget->combined[b], std::sqrt(all));
    EXPECT_DOUBLE_EQ(budget->independent[b], std::sqrt(independent));
    EXPECT_LT(budget->independent[b], budget->combined[b]);
  }
  // Band 1 by hand: the sample's noise is the only independent term without the pose.
  EXPECT_NEAR(budget->independent[1], 9.971825239675986e-05, 1e-17);
}

TEST(ReadingBudget, SharedComponentsNameWhatTheyAreSharedThrough) {
  Result<ReadingBudget> budget = EstimateReadingBudget(HandCase());
  ASSERT_TRUE(budget.ok());
  EXPECT_EQ(Get(*budget, "sample_signal").shared, (SharedThrough{Sharing::kIndependent, 0}));
  EXPECT_EQ(Get(*budget, "reference_signal").shared,
            (SharedThrough{Sharing::kReferenceReading, 11}));
  EXPECT_EQ(Get(*budget, "reference_pose").shared, (SharedThrough{Sharing::kReferenceReading, 11}));
  EXPECT_EQ(Get(*budget, "dark_signal").shared, (SharedThrough{Sharing::kDarkReading, 12}));
  EXPECT_EQ(Get(*budget, "white_standard").shared, (SharedThrough{Sharing::kWhiteStandard, 7}));
  EXPECT_EQ(Get(*budget, "wavelength_scale").shared, (SharedThrough{Sharing::kInstrument, 7}));
  EXPECT_EQ(Get(*budget, "stray_light").shared, (SharedThrough{Sharing::kInstrument, 7}));
  EXPECT_STREQ(SharingName(Sharing::kWhiteStandard), "white_standard");
}

// The extended measurement equation (docs/uncertainty.md), written out: every input at its
// estimate gives f; each is moved in turn for the finite differences.
struct Inputs {
  double sample, dark, white, rho, theta_r, theta_i, stray, drift;
};
double Equation(const Inputs& x, double theta_r_error) {
  const double k =
      x.rho / std::numbers::pi * std::cos(x.theta_r * kDeg) / std::cos(x.theta_i * kDeg);
  const double stray = x.stray * (x.white - x.dark);
  // The white's own light follows cos θr; the ambient the dark measures does not.
  const double white = x.dark + (x.white - x.dark) * std::cos((x.theta_r + theta_r_error) * kDeg) /
                                    std::cos(x.theta_r * kDeg);
  return k * (x.sample - x.dark - stray) / (white - x.dark - stray) / (1 + x.drift);
}

double Derivative(Inputs x, double Inputs::*field, double h) {
  Inputs up = x, down = x;
  up.*field += h;
  down.*field -= h;
  return (Equation(up, 0) - Equation(down, 0)) / (2 * h);
}

TEST(ReadingBudget, SensitivityCoefficientsMatchFiniteDifferences) {
  BudgetInputs in = HandCase();
  in.theta_r_deg = 20;
  in.terms.stage.repeatability_deg = {0.1, 0.2, 0.1, 0.1};
  in.drift = LampDrift{0.004, 0.5};
  Result<ReadingBudget> budget = EstimateReadingBudget(in);
  ASSERT_TRUE(budget.ok()) << budget.status().message();
  const MeterNoiseModel model;
  const std::vector<double> u_i = *SignalUncertainty(in.sample.radiance, 1000, 4, model);
  const std::vector<double> u_0 = *SignalUncertainty(in.reference.radiance, 1000, 4, model);
  const std::vector<double> u_d = *SignalUncertainty(in.dark->radiance, 1000, 4, model);
  for (std::size_t b = 0; b < 3; ++b) {
    const Inputs x{in.sample.radiance[b], 0.001, 0.201, 0.99, 20, 30, 0, 0};
    EXPECT_NEAR(budget->value[b], Equation(x, 0), 1e-14);
    const double tol = 1e-6 * std::abs(budget->value[b]);
    EXPECT_NEAR(Get(*budget, "sample_signal").contribution[b],
                Derivative(x, &Inputs::sample, 1e-6) * u_i[b], tol);
    EXPECT_NEAR(Get(*budget, "reference_signal").contribution[b],
                Derivative(x, &Inputs::white, 1e-6) * u_0[b], tol);
    EXPECT_NEAR(Get(*budget, "dark_signal").contribution[b],
                Derivative(x, &Inputs::dark, 1e-7) * u_d[b], tol);
    EXPECT_NEAR(Get(*budget, "white_standard").contribution[b],
                Derivative(x, &Inputs::rho, 1e-6) * 0.005, tol);
    EXPECT_NEAR(Get(*budget, "stray_light").contribution[b],
                Derivative(x, &Inputs::stray, 1e-6) * 0.001, tol);
    // Drift: δ = 0.004 over the interval, half of it by the reading: εL = w δ.
    EXPECT_NEAR(Get(*budget, "lamp_drift").contribution[b],
                Derivative(x, &Inputs::drift, 1e-6) * 0.5 * 0.004, tol);
    // Reference pose: the white read at θr + Δ, the BRDF's cosine at the nominal θr; per degree.
    const double h = 1e-4;
    const double d_theta = (Equation(x, h) - Equation(x, -h)) / (2 * h);
    EXPECT_NEAR(Get(*budget, "reference_pose").contribution[b], d_theta * 0.2, tol);
  }
}

TEST(ReadingBudget, PoseThroughTheGradientAndNotEstimatedWithoutIt) {
  BudgetInputs in = HandCase();
  in.terms.stage.repeatability_deg = {0.3, 0.4, 0.0, 0.0};
  in.terms.stage.alignment_deg = {0.0, 0.05, 0.0, 0.0};
  Result<ReadingBudget> without = EstimateReadingBudget(in);
  ASSERT_TRUE(without.ok());
  EXPECT_EQ(without->Find("pose_repeatability"), nullptr);
  ASSERT_EQ(without->not_estimated.size(), 2u);  // the pose, the lamp drift
  EXPECT_EQ(without->not_estimated[1].rfind("pose:", 0), 0u) << without->not_estimated[1];

  in.pose_gradient = std::array<std::vector<double>, 4>{
      std::vector<double>{0.01, 0.02, 0.03}, std::vector<double>{-0.03, -0.04, 0.0},
      std::vector<double>(3, 0.0), std::vector<double>(3, 0.0)};
  Result<ReadingBudget> with = EstimateReadingBudget(in);
  ASSERT_TRUE(with.ok());
  // Band 1: sqrt((0.02 · 0.3)² + (0.04 · 0.4)²) = sqrt(3.6e-5 + 2.56e-4).
  EXPECT_NEAR(Get(*with, "pose_repeatability").contribution[1], std::sqrt(2.92e-4), 1e-15);
  EXPECT_EQ(Get(*with, "pose_repeatability").shared.kind, Sharing::kIndependent);
  // Alignment on β alone (θr = 0: the reference adds nothing), signed.
  EXPECT_NEAR(Get(*with, "pose_alignment_beta").contribution[1], -0.04 * 0.05, 1e-15);
  EXPECT_EQ(Get(*with, "pose_alignment_beta").shared, (SharedThrough{Sharing::kInstrument, 7}));
  EXPECT_EQ(with->Find("pose_alignment_alpha"), nullptr);
  EXPECT_GT(with->combined[1], without->combined[1]);
}

TEST(ReadingBudget, ReflectanceHasNoWhiteStandardTerm) {
  BudgetInputs in = HandCase();
  in.quantity = Quantity::kReflectance;
  in.white_reflectance.clear();  // not needed for the reflectance
  Result<ReadingBudget> budget = EstimateReadingBudget(in);
  ASSERT_TRUE(budget.ok()) << budget.status().message();
  EXPECT_NEAR(budget->value[1], 0.295, 1e-15);
  EXPECT_EQ(budget->Find("white_standard"), nullptr);
  EXPECT_EQ(budget->Find("reference_pose"), nullptr);
  // (R − 1) · s with K = 1.
  EXPECT_NEAR(Get(*budget, "stray_light").contribution[1], -0.705 * 0.001, 1e-15);
}

TEST(ReadingBudget, WithoutADarkTheDarkIsNamedNotEstimated) {
  BudgetInputs in = HandCase();
  in.dark.reset();
  Result<ReadingBudget> budget = EstimateReadingBudget(in);
  ASSERT_TRUE(budget.ok());
  EXPECT_EQ(budget->Find("dark_signal"), nullptr);
  ASSERT_FALSE(budget->not_estimated.empty());
  EXPECT_EQ(budget->not_estimated[0].rfind("dark_signal:", 0), 0u);
  EXPECT_NEAR(budget->value[1], 0.36387707097838273 * 0.06 / 0.201, 1e-15);
}

TEST(ReadingBudget, WhiteReflectanceAsASpectrum) {
  BudgetInputs in = HandCase();
  in.white_reflectance = {0.98, 0.99, 0.97};
  in.white_reflectance_u = {0.001, 0.002, 0.003};
  Result<ReadingBudget> budget = EstimateReadingBudget(in);
  ASSERT_TRUE(budget.ok());
  for (std::size_t b = 0; b < 3; ++b) {
    EXPECT_NEAR(Get(*budget, "white_standard").contribution[b],
                budget->value[b] / in.white_reflectance[b] * in.white_reflectance_u[b], 1e-16);
  }
}

TEST(ReadingBudget, BadInputsAreRefusedWithTheirName) {
  auto message = [](BudgetInputs in) { return EstimateReadingBudget(in).status().message(); };
  BudgetInputs dark_white = HandCase();
  dark_white.reference.radiance[2] = 0.001;
  EXPECT_NE(message(dark_white).find("508"), std::string::npos) << message(dark_white);
  BudgetInputs short_sample = HandCase();
  short_sample.sample.radiance.pop_back();
  EXPECT_NE(message(short_sample).find("sample reading has 2 values"), std::string::npos);
  BudgetInputs grazing = HandCase();
  grazing.theta_i_deg = 90;
  EXPECT_NE(message(grazing).find("θi"), std::string::npos);
  BudgetInputs negative = HandCase();
  negative.white_reflectance_u = {-0.01};
  EXPECT_NE(message(negative).find("u(ρw)"), std::string::npos);
  BudgetInputs radiance = HandCase();
  radiance.quantity = Quantity::kRadiance;
  EXPECT_NE(message(radiance).find("radiance"), std::string::npos);
  BudgetInputs averages = HandCase();
  averages.reference.averages = 0;
  EXPECT_NE(message(averages).find("reference reading"), std::string::npos);
  BudgetInputs drift = HandCase();
  drift.drift = LampDrift{0.01, -1};
  EXPECT_NE(message(drift).find("drift"), std::string::npos);
}

}  // namespace
}  // namespace brdf::uncertainty
