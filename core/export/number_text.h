// Numbers in the exports' text files: the shortest decimal form that reads back to the same
// double (std::to_chars), so that a CSV export loses nothing; "nan" for a cell without a value
// (NumPy, pandas and spreadsheet readers all take it as NaN).
#pragma once

#include <string>

namespace brdf::exports {

std::string FormatNumber(double value);
// Appends FormatNumber(value) to `out` without a temporary string.
void AppendNumber(std::string& out, double value);

}  // namespace brdf::exports
