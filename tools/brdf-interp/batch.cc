#include "tools/brdf-interp/batch.h"

#include <algorithm>
#include <atomic>
#include <string>
#include <thread>
#include <vector>

namespace brdf::interp_tool {
namespace {

constexpr std::size_t kChunk = 512;           // queries per chunk
constexpr std::size_t kChunksPerThread = 16;  // chunks per wave, per thread

}  // namespace

Status RunBatch(const interp::Interpolator& interpolator, const interp::QueryTable& queries,
                const OutputLayout& layout, int threads,
                const std::function<Status(std::string_view)>& sink, BatchCounts* counts) {
  const std::size_t n = queries.size();
  const std::size_t workers = static_cast<std::size_t>(std::max(1, threads));
  const std::size_t chunks_total = (n + kChunk - 1) / kChunk;
  const std::size_t wave = workers * kChunksPerThread;
  std::vector<std::string> texts;
  std::vector<BatchCounts> per_worker(workers);

  for (std::size_t first = 0; first < chunks_total; first += wave) {
    const std::size_t chunks = std::min(wave, chunks_total - first);
    texts.assign(chunks, std::string());
    std::atomic<std::size_t> next{0};
    auto work = [&](std::size_t worker) {
      BatchCounts& local = per_worker[worker];
      for (std::size_t c = next.fetch_add(1); c < chunks; c = next.fetch_add(1)) {
        std::string& text = texts[c];
        const std::size_t begin = (first + c) * kChunk;
        const std::size_t end = std::min(n, begin + kChunk);
        for (std::size_t q = begin; q < end; ++q) {
          const interp::Interpolation answer = interpolator.Evaluate(queries.query(q));
          ++local.by_status[static_cast<std::size_t>(answer.status)];
          AppendRow(layout, queries.query(q), answer, text);
        }
      }
    };
    if (workers == 1 || chunks == 1) {
      work(0);
    } else {
      std::vector<std::jthread> pool;
      for (std::size_t w = 1; w < std::min(workers, chunks); ++w) pool.emplace_back(work, w);
      work(0);
    }  // the jthreads join here
    for (const std::string& text : texts) BRDF_RETURN_IF_ERROR(sink(text));
  }
  if (counts != nullptr) {
    *counts = {};
    for (const BatchCounts& c : per_worker) {
      for (std::size_t s = 0; s < 4; ++s) counts->by_status[s] += c.by_status[s];
    }
  }
  return Status::Ok();
}

}  // namespace brdf::interp_tool
