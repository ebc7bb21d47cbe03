// core/readings' ReadingDeriver: readings folded one at a time give each sample's radiance,
// reflectance and BRDF from the reference and dark it names, or say why not.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/readings/derive.h"

namespace brdf {
namespace {

const WavelengthGrid kGrid{500, 100, 2};

Reading Make(std::int64_t id, ReadingKind kind, Directions d, std::vector<double> values) {
  Reading r;
  r.id = id;
  r.kind = kind;
  r.directions = d;
  r.spectrum = {kGrid, std::move(values)};
  return r;
}

TEST(ReadingDeriver, SampleIsDividedByTheReferenceAndDarkItNames) {
  ReadingDeriver deriver(0.95);
  EXPECT_FALSE(deriver.Fold(Make(1, ReadingKind::kReference, {30, 0, 30, 180}, {2.0, 4.0})));
  EXPECT_FALSE(deriver.Fold(Make(2, ReadingKind::kDark, {}, {0.5, 1.0})));
  EXPECT_FALSE(deriver.grid().has_value());
  Reading sample = Make(3, ReadingKind::kSample, {60, 0, 20, 90}, {1.1, 1.9});
  sample.reference_id = 1;
  sample.dark_id = 2;
  std::optional<SampleQuantities> q = deriver.Fold(sample);
  ASSERT_TRUE(q.has_value());
  ASSERT_TRUE(q->has(Quantity::kRadiance) && q->has(Quantity::kReflectance) &&
              q->has(Quantity::kBrdf));
  EXPECT_DOUBLE_EQ(q->of(Quantity::kRadiance)[0], 0.6);
  EXPECT_DOUBLE_EQ(q->of(Quantity::kReflectance)[1], 0.9 / 3.0);
  const double ratio =
      std::cos(30 * std::numbers::pi / 180) / std::cos(60 * std::numbers::pi / 180);
  EXPECT_NEAR(q->of(Quantity::kBrdf)[0], 0.4 * 0.95 / std::numbers::pi * ratio, 1e-15);
  ASSERT_TRUE(deriver.grid().has_value());
  EXPECT_EQ(*deriver.grid(), kGrid);
}

TEST(ReadingDeriver, WhatCannotBeComputedSaysWhy) {
  ReadingDeriver deriver(0.99);
  Reading unknown_ref = Make(5, ReadingKind::kSample, {20, 0, 20, 90}, {1.0, 1.0});
  unknown_ref.reference_id = 4;  // never folded
  std::optional<SampleQuantities> q = deriver.Fold(unknown_ref);
  ASSERT_TRUE(q.has_value());
  EXPECT_TRUE(q->has(Quantity::kRadiance));
  EXPECT_FALSE(q->has(Quantity::kBrdf));
  EXPECT_EQ(q->reason(Quantity::kReflectance),
            "reading 5: its reference reading 4 is not a reference reading of this session");

  Reading no_ref = Make(6, ReadingKind::kSample, {20, 0, 20, 90}, {1.0, 1.0});
  EXPECT_EQ(deriver.Fold(no_ref)->reason(Quantity::kBrdf),
            "reading 6: it names no reference reading");

  Reading other_grid = Make(7, ReadingKind::kSample, {20, 0, 20, 90}, {1.0, 1.0, 1.0});
  other_grid.spectrum.grid = WavelengthGrid{500, 50, 3};
  std::optional<SampleQuantities> g = deriver.Fold(other_grid);
  EXPECT_FALSE(g->has(Quantity::kRadiance));
  EXPECT_NE(g->reason(Quantity::kRadiance).find("wavelength grid differs"), std::string::npos);

  Reading below = Make(8, ReadingKind::kSample, {95, 0, 20, 90}, {1.0, 1.0});
  EXPECT_NE(deriver.Fold(below)->reason(Quantity::kRadiance).find("below the surface"),
            std::string::npos);
}

// A white standard's certificate gives ρw(λ): the BRDF uses it band by band, interpolated onto
// the session's grid, instead of the one number.
TEST(ReadingDeriver, WhiteReflectanceSpectrumReplacesTheNumber) {
  const Spectrum white{WavelengthGrid{400, 200, 3}, {0.90, 0.94, 0.98}};  // 400, 600, 800 nm
  ReadingDeriver deriver(0.5, white);
  deriver.Fold(Make(1, ReadingKind::kReference, {0, 0, 30, 180}, {2.0, 2.0}));
  Reading sample = Make(2, ReadingKind::kSample, {0, 0, 20, 90}, {1.0, 1.0});
  sample.reference_id = 1;
  std::optional<SampleQuantities> q = deriver.Fold(sample);
  ASSERT_TRUE(q.has_value() && q->has(Quantity::kBrdf)) << q->reason(Quantity::kBrdf);
  // kGrid is 500 and 600 nm: ρw 0.92 and 0.94; R = 0.5; equal incidence.
  EXPECT_NEAR(q->of(Quantity::kBrdf)[0], 0.5 * 0.92 / std::numbers::pi, 1e-15);
  EXPECT_NEAR(q->of(Quantity::kBrdf)[1], 0.5 * 0.94 / std::numbers::pi, 1e-15);
  EXPECT_DOUBLE_EQ(q->of(Quantity::kReflectance)[0], 0.5);
}

TEST(ReadingDeriver, WhiteSpectrumNotCoveringTheGridGivesNoBrdfAndSaysWhy) {
  ReadingDeriver deriver(0.99, Spectrum{WavelengthGrid{520, 10, 3}, {0.9, 0.9, 0.9}});
  deriver.Fold(Make(1, ReadingKind::kReference, {0, 0, 30, 180}, {2.0, 2.0}));
  Reading sample = Make(2, ReadingKind::kSample, {0, 0, 20, 90}, {1.0, 1.0});
  sample.reference_id = 1;
  std::optional<SampleQuantities> q = deriver.Fold(sample);
  ASSERT_TRUE(q.has_value());
  EXPECT_TRUE(q->has(Quantity::kReflectance));
  EXPECT_FALSE(q->has(Quantity::kBrdf));
  EXPECT_NE(q->reason(Quantity::kBrdf).find("ρw spectrum"), std::string::npos)
      << q->reason(Quantity::kBrdf);
}

}  // namespace
}  // namespace brdf

namespace brdf {
namespace {

// The clauses of a stored note that changed the integration time, and only those.
TEST(IntegrationNoteOf, KeepsTheClausesThatChangedTheIntegration) {
  EXPECT_EQ(IntegrationNoteOf(""), "");
  EXPECT_EQ(IntegrationNoteOf("code 18 (low light): accepted, flagged"), "");
  EXPECT_EQ(IntegrationNoteOf("code 19 (overload): integration halved from 500 to 250 ms"),
            "code 19 (overload): integration halved from 500 to 250 ms");
  EXPECT_EQ(IntegrationNoteOf("code 19 (overload): integration halved from 500 to 250 ms; "
                              "code 0 (OK); code 18 (low light), handled as quality 18: "
                              "integration doubled from 250 to 500 ms; units code 2: uncalibrated"),
            "code 19 (overload): integration halved from 500 to 250 ms; code 18 (low light), "
            "handled as quality 18: integration doubled from 250 to 500 ms");
}

}  // namespace
}  // namespace brdf
