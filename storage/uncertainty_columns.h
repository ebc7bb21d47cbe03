// The on-disk form of a reading's uncertainty budget (core/uncertainty/budget.h), the columns of
// table reading_uncertainty (schema.md, version 5):
//   quantity       "brdf" or "reflectance"
//   value          BLOB, the quantity per band the budget was evaluated at (the derivation's)
//   combined       BLOB, one little-endian float64 per band (as a spectrum, spectrum_blob.h)
//   independent    BLOB, the same
//   components     TEXT, one line per component: "name<TAB>sharing<TAB>id" (sharing as
//                  core's SharingName: independent, reference_reading, …)
//   contributions  BLOB, the components' signed contributions, component after component, each
//                  one float64 per band (numpy.frombuffer(b, "<f8").reshape(n_components, bands))
//   not_estimated  TEXT, one line per component left out ("name: why"), '' when none
// Shared by the rig's store and the lab archive (storage/archive/), whose table
// reading_uncertainty has the same columns.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/status.h"
#include "core/uncertainty/budget.h"

namespace brdf::storage {

struct UncertaintyColumns {
  std::string quantity;
  std::vector<std::uint8_t> value;
  std::vector<std::uint8_t> combined;
  std::vector<std::uint8_t> independent;
  std::string components;
  std::vector<std::uint8_t> contributions;
  std::string not_estimated;
};

// kInvalidArgument when the budget does not fit `bands` (a per-band vector of another size), is
// for another quantity than BRDF or reflectance, holds a non-finite or negative uncertainty or a
// non-finite contribution, or a name or reason with a tab or line break.
Result<UncertaintyColumns> EncodeUncertainty(const uncertainty::ReadingBudget& budget,
                                             std::size_t bands);

// The budget back. kInvalidArgument naming the column when one does not
// parse or does not fit `bands`.
Result<uncertainty::ReadingBudget> DecodeUncertainty(const UncertaintyColumns& columns,
                                                     std::size_t bands);

}  // namespace brdf::storage
