// Fuzz target: the CSV reader of brdf-interp (core/interp/csv_table.h), the whole text given to
// ParseNumericCsv, ParseSamplesCsv and ParseQueriesCsv; then, as the tool does next, a small
// accepted sample table is indexed (octant, nearest, Delaunay) and evaluated at its own points.
//
// Promises checked: a table's shape matches its header and its line numbers, every value is
// finite; samples have 3 or 4 coordinates, increasing positive wavelengths, one value per
// wavelength; every refusal is kInvalidArgument naming the source; an interpolation that says ok
// has one value per band.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "core/interp/csv_table.h"
#include "core/interp/interpolator.h"
#include "fuzz/fuzz_check.h"

namespace brdf::fuzz {
namespace {

using namespace brdf::interp;

constexpr std::string_view kSource = "fuzz.csv";

void CheckRefusal(const Status& s) {
  BRDF_FUZZ_CHECK(s.code() == StatusCode::kInvalidArgument, "wrong code: " + s.ToString());
  BRDF_FUZZ_CHECK(s.message().find(kSource) != std::string::npos,
                  "an error that does not name the file: " + s.ToString());
}

void CheckTable(const CsvTable& t) {
  BRDF_FUZZ_CHECK(t.columns() > 0, "a table without columns");
  BRDF_FUZZ_CHECK(t.values.size() == t.rows() * t.columns(), "values do not fill rows x columns");
  std::set<std::string> names;
  for (const std::string& h : t.header) {
    BRDF_FUZZ_CHECK(!h.empty(), "an empty column name accepted");
    BRDF_FUZZ_CHECK(names.insert(h).second, "a duplicate column name accepted: " + h);
  }
  std::size_t previous = t.header_line;
  for (std::size_t line : t.lines) {
    BRDF_FUZZ_CHECK(line > previous, "row line numbers not increasing after the header");
    previous = line;
  }
  for (double v : t.values) BRDF_FUZZ_CHECK(std::isfinite(v), "a non-finite value accepted");
}

void Interpolate(const SampleTable& table) {
  const auto& samples = table.samples;
  const std::size_t n = samples->size();
  for (Method m : {Method::kOctant, Method::kNearest, Method::kDelaunay}) {
    if (m == Method::kDelaunay && n > 64) continue;  // Qhull's cost grows fast with points
    auto index = MakeInterpolator(m, samples);
    if (!index.ok()) continue;  // degenerate sets are refused, which is fine
    for (std::size_t i = 0; i < n && i < 8; ++i) {
      const Interpolation r = (*index)->Evaluate(samples->coords(i));
      if (r.status != InterpStatus::kOk) continue;
      BRDF_FUZZ_CHECK(r.spectrum.size() == static_cast<std::size_t>(samples->bands()),
                      std::string(MethodName(m)) + ": an answer with the wrong band count");
      for (const Vertex& v : r.vertices) {
        BRDF_FUZZ_CHECK(v.index < n, std::string(MethodName(m)) + ": a vertex beyond the set");
        BRDF_FUZZ_CHECK(std::isfinite(v.weight), std::string(MethodName(m)) + ": bad weight");
      }
    }
  }
}

}  // namespace

int FuzzInterpCsv(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = AsText(data, size);

  const Result<CsvTable> table = ParseNumericCsv(text, kSource);
  if (table.ok()) {
    CheckTable(*table);
  } else {
    CheckRefusal(table.status());
  }

  const Result<QueryTable> queries = ParseQueriesCsv(text, kSource);
  if (queries.ok()) {
    BRDF_FUZZ_CHECK(queries->dims == 3 || queries->dims == 4, "queries of another dimension");
    BRDF_FUZZ_CHECK(
        queries->coords.size() == queries->size() * static_cast<std::size_t>(queries->dims),
        "query coordinates do not fill size x dims");
    for (double v : queries->coords) BRDF_FUZZ_CHECK(std::isfinite(v), "non-finite query");
  } else {
    CheckRefusal(queries.status());
  }

  const Result<SampleTable> samples = ParseSamplesCsv(text, kSource);
  if (!samples.ok()) {
    CheckRefusal(samples.status());
    return 0;
  }
  const SampleTable& s = *samples;
  BRDF_FUZZ_CHECK(s.dims == 3 || s.dims == 4, "samples of another dimension");
  BRDF_FUZZ_CHECK(s.samples != nullptr && s.samples->size() > 0, "a sample table without rows");
  BRDF_FUZZ_CHECK(s.samples->dims() == s.dims, "sample set dims differ from the table's");
  BRDF_FUZZ_CHECK(!s.wavelengths_nm.empty() &&
                      s.wavelengths_nm.size() == s.wavelength_headers.size() &&
                      static_cast<int>(s.wavelengths_nm.size()) == s.samples->bands(),
                  "wavelengths, headers and bands disagree");
  for (std::size_t i = 0; i < s.wavelengths_nm.size(); ++i) {
    BRDF_FUZZ_CHECK(std::isfinite(s.wavelengths_nm[i]) && s.wavelengths_nm[i] > 0,
                    "a non-positive wavelength accepted");
    if (i > 0) {
      BRDF_FUZZ_CHECK(s.wavelengths_nm[i] > s.wavelengths_nm[i - 1], "wavelengths not increasing");
    }
  }
  for (std::size_t i = 0; i < s.samples->size(); ++i) {
    for (double v : s.samples->coords(i)) BRDF_FUZZ_CHECK(std::isfinite(v), "non-finite coord");
    for (double v : s.samples->spectrum(i)) BRDF_FUZZ_CHECK(std::isfinite(v), "non-finite value");
  }
  if (s.samples->size() <= 256) Interpolate(s);
  return 0;
}

}  // namespace brdf::fuzz

BRDF_FUZZ_ENTRY(brdf::fuzz::FuzzInterpCsv)
