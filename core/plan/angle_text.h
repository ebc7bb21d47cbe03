// How plan texts (labels, prompts, problems) print angles and numbers: at most 6 significant
// digits, no trailing zeros ("146.25", "-35", "0.5"), so that texts are short and deterministic.
#pragma once

#include <string>

namespace brdf::plan {

// "22.5"; values within 1e-9 of 0 print as "0"; "nan" and "inf" as such.
std::string Num(double value);
// "22.5°"
std::string Deg(double value);

}  // namespace brdf::plan
