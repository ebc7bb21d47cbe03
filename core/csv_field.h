// Text as one field of a CSV file (RFC 4180), for the files the tools and exports write.
#pragma once

#include <string>
#include <string_view>

namespace brdf {

// Appends `text` to `out` as one CSV field: as it is, or quoted (with "" for ") when it holds a
// comma, a quote or a line break.
void AppendCsvField(std::string& out, std::string_view text);

}  // namespace brdf
