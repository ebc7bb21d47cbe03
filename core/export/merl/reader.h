// Reading a MERL ".binary" back the way the MERL distribution's reader does (BRDFRead.cpp:
// read_brdf and lookup_brdf_val), for checks and round-trip tests; tools/check/merl_read.py is an
// independent NumPy version of the same.
#pragma once

#include <string_view>

#include "core/colorimetry.h"
#include "core/export/merl/layout.h"
#include "core/pose.h"
#include "core/status.h"

namespace brdf::exports {

// Parses the bytes of a file. Errors (kInvalidArgument): fewer than 12 bytes, dims whose product
// is not 90 · 90 · 180 (the reader's check), or a size other than 12 + 3 · 8 · dims product.
Result<MerlTable> ParseMerl(std::string_view bytes);

// The reader's lookup_brdf_val at directions given in degrees (converted to radians): the stored
// values of the cell, multiplied by the channel scales. A missing cell gives negative values.
Rgb LookupMerl(const MerlTable& table, const Directions& directions);

}  // namespace brdf::exports
