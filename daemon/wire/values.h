// The small values every brdf.v1 message carries, from brdfd's: instants, poses, directions,
// wavelength grids.
#pragma once

#include <google/protobuf/timestamp.pb.h>

#include <chrono>

#include "brdf/v1/brdf.pb.h"
#include "core/pose.h"
#include "core/wavelength_grid.h"
#include "storage/records.h"

namespace brdf::daemon {

// Instants: storage's Unix seconds (to the nanosecond, rounded), a clock's time point, now.
google::protobuf::Timestamp ToTimestamp(storage::UnixSeconds seconds);
google::protobuf::Timestamp ToTimestamp(std::chrono::system_clock::time_point at);
google::protobuf::Timestamp NowTimestamp();
// And back, as Unix seconds (a request's created_after, a session's created_at).
double ToUnixSeconds(const google::protobuf::Timestamp& at);

v1::Pose ToProtoPose(const Pose& pose);
v1::Directions ToProtoDirections(const Directions& directions);
v1::IsoDirection ToProtoIso(const IsoDirection& iso);
v1::WavelengthGrid ToProtoGrid(const WavelengthGrid& grid);

}  // namespace brdf::daemon
