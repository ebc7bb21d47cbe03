#include "data/cie_tables.h"

#include <fstream>
#include <sstream>

namespace brdf::data {
namespace {

Result<SpectralTable> ReadTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    return NotFound("cannot read " + path +
                    ": the CIE tables come from Debian's colord-data (apt-get install "
                    "colord-data), or pass --colord DIR");
  }
  std::ostringstream text;
  text << in.rdbuf();
  Result<SpectralTable> table = ParseSpectralTable(text.str());
  if (!table.ok()) return table.status().WithContext(path);
  return table;
}

}  // namespace

Result<CieTables> LoadCieTables(const std::string& colord_dir) {
  const std::string cmf_path = colord_dir + "/cmf/CIE1931-2deg-XYZ.cmf";
  const std::string d65_path = colord_dir + "/illuminant/CIE-D65.sp";
  Result<SpectralTable> cmf_table = ReadTable(cmf_path);
  if (!cmf_table.ok()) return cmf_table.status();
  Result<SpectralTable> d65_table = ReadTable(d65_path);
  if (!d65_table.ok()) return d65_table.status();
  Result<ColorMatchingFunctions> cmf = ColorMatchingFunctionsFromTable(*cmf_table);
  if (!cmf.ok()) return cmf.status().WithContext(cmf_path);
  Result<Spectrum> d65 = d65_table->SetAsSpectrum(0);
  if (!d65.ok()) return d65.status().WithContext(d65_path);
  return CieTables{std::move(*cmf), std::move(*d65)};
}

}  // namespace brdf::data
