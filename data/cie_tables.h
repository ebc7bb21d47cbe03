// The CIE tables the MERL export needs, read from Debian's colord-data (/usr/share/colord): the
// CIE 1931 2° colour-matching functions and illuminant D65. The files are parsed by
// core/colorimetry; this is the file I/O around it (data/ holds the loaders of reference data the
// system provides, so that core/ stays free of I/O; brdfd's Data.Export and brdf-export use it).
#pragma once

#include <string>

#include "core/colorimetry.h"
#include "core/status.h"

namespace brdf::data {

inline constexpr const char* kDefaultColordDir = "/usr/share/colord";

struct CieTables {
  ColorMatchingFunctions cmf;
  Spectrum d65;
};

// Reads <dir>/cmf/CIE1931-2deg-XYZ.cmf and <dir>/illuminant/CIE-D65.sp. Errors name the file
// (kNotFound: "install colord-data"; parse errors as core/colorimetry reports them).
Result<CieTables> LoadCieTables(const std::string& colord_dir);

}  // namespace brdf::data
