// The readable (default) output's small pieces: enum values by their short lower-case names
// ("awaiting_operator", "mount_white"), numbers without noise, durations as h:mm:ss, poses and
// directions with their Greek letters, timestamps in UTC.
#pragma once

#include <google/protobuf/timestamp.pb.h>

#include <string>
#include <string_view>

#include "brdf/v1/brdf.pb.h"

namespace brdf::ctl {

// "SESSION_STATE_AWAITING_OPERATOR" minus "SESSION_STATE_", lower-cased: "awaiting_operator".
std::string ShortEnumName(std::string_view full_name, std::string_view prefix);

std::string StateName(v1::SessionState state);
std::string PromptKindName(v1::PromptKind kind);
std::string StepKindName(v1::StepKind kind);
std::string ReadingKindName(v1::ReadingKind kind);
std::string ConnectionStateName(v1::ConnectionState state);
std::string InterpolationStatusName(v1::InterpolationStatus status);
std::string MethodName(v1::InterpolationMethod method);
std::string QuantityName(v1::Quantity quantity);
// The quantity's unit: "W·m⁻²·sr⁻¹·nm⁻¹", "1" (reflectance), "sr⁻¹".
std::string QuantityUnit(v1::Quantity quantity);

// The command lines' --coordinates value ("incidence", "half-diff") as the API's; false for an
// unknown name.
bool ParseCoordinatesName(std::string_view name, v1::InterpolationCoordinates* coordinates);
// The command lines' --trend value ("none", "bivariate") as the API's; false for another.
bool ParseTrendName(std::string_view name, v1::InterpolationTrend* trend);

// Inverse of StateName ("running" → SESSION_STATE_RUNNING); false for an unknown name.
bool ParseStateName(std::string_view name, v1::SessionState* state);

// Up to `digits` significant digits, no trailing zeros: 22.5, 0.0125, 1.23457e-05.
std::string Num(double value, int digits = 6);

// Seconds as "42 s", "3:07", "1:02:03" (negative or non-finite: "?").
std::string Duration(double seconds);

// A stage angle to 0.001° (finer than a rotation stage's step; a pose computed for the
// sample-fixed method prints 0, not 2.0255e-15): "45", "12.5", "-30.001".
std::string StageAngle(double degrees);
// "α 20° β −30° γ 0° δ 22.5°".
std::string PoseText(const v1::Pose& pose);
// "θi 35° φi 0° θo 20° φo 150°".
std::string DirectionsText(const v1::Directions& directions);
// "θi 35° θo 20° φ 150°".
std::string IsoText(const v1::IsoDirection& iso);

// "2026-11-21 22:31:25Z"; "-" when unset (seconds and nanos both 0).
std::string TimeText(const google::protobuf::Timestamp& time);
// The same in the local time zone (TZ), with its offset: "2026-11-21 23:31:25 +0100".
std::string LocalTimeText(const google::protobuf::Timestamp& time);

}  // namespace brdf::ctl
