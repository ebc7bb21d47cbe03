// Evaluating a batch of queries on several threads while keeping the output in query order:
// queries are cut into chunks, threads take chunks, each chunk is formatted into its own text,
// and the texts are handed to the sink in chunk order, a wave of chunks at a time (so memory
// stays bounded however many queries there are). The output is identical for any thread count.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string_view>

#include "core/interp/csv_table.h"
#include "core/interp/interpolator.h"
#include "core/status.h"
#include "tools/brdf-interp/output_csv.h"

namespace brdf::interp_tool {

struct BatchCounts {
  std::array<std::size_t, 4> by_status{};  // indexed by InterpStatus
  std::size_t total() const { return by_status[0] + by_status[1] + by_status[2] + by_status[3]; }
};

// `sink` receives the rows (not the header) in order; its first error stops the batch.
// threads >= 1.
Status RunBatch(const interp::Interpolator& interpolator, const interp::QueryTable& queries,
                const OutputLayout& layout, int threads,
                const std::function<Status(std::string_view)>& sink, BatchCounts* counts);

}  // namespace brdf::interp_tool
