// A plan's sample block (brdf.v1.Sample): the lab's catalogue entry for what is measured, and
// optionally the white standard's ρw as one number or as a spectrum ρw(λ). Pure: no I/O.
#pragma once

#include <optional>

#include "brdf/v1/plan.pb.h"
#include "core/plan/problem.h"
#include "core/spectrum.h"

namespace brdf::plan {

// Longest text accepted in a sample field (id, name, material, white standard id, each tag).
inline constexpr std::size_t kMaxSampleTextLength = 256;
// Longest sample description, bytes.
inline constexpr std::size_t kMaxSampleDescriptionLength = 4096;
// Most tags a sample may carry.
inline constexpr int kMaxSampleTags = 64;

// Problems with plan.sample: texts too long, an empty tag, ρw outside (0, 1], u(ρw) outside
// [0, 0.5], a ρw spectrum with
// a step ≤ 0, fewer than 2 values or a value outside (0, 1]. Paths "sample.<field>".
void CheckSample(const v1::Sample& sample, ProblemSink& sink);

// ρw(λ) when the sample block gives a spectrum; nullopt otherwise (the plan must be valid).
std::optional<Spectrum> WhiteReflectanceSpectrumOf(const v1::Plan& plan);

// ρw as one number when the sample block gives one and no spectrum; nullopt otherwise.
std::optional<double> WhiteReflectanceOf(const v1::Plan& plan);

// u(ρw), the standard uncertainty of the white standard's reflectance, when the sample block
// gives it; nullopt otherwise (the daemon's [sample] white_reflectance_uncertainty then).
std::optional<double> WhiteReflectanceUncertaintyOf(const v1::Plan& plan);

}  // namespace brdf::plan
