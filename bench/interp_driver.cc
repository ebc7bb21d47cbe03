// Our side of bench/compare.py: reads the same sample and query CSV files as the scipy side and
// answers commands on stdin, one JSON object per line on stdout, so that compare.py can
// interleave our repetitions with scipy's (same data, same queries, same order, same load).
//
//   samples NAME PATH              load a samples CSV; build octant, nearest, Delaunay (timed)
//   queries QNAME PATH             load a queries CSV
//   run NAME QNAME METHOD API      one timed pass over the queries, single thread, in file order
//                                  METHOD: octant | nearest | delaunay
//                                  API: spectrum (n × bands array, like scipy's result)
//                                       | evaluate (full answers with provenance)
//   check NAME QNAME THREADS       octant vs the O(N) reference on every query: mismatches
//   grid NAME THREADS NT NO NP PHIMAX REPS
//                                  resample the regular grid of cell centres (θi: NT over
//                                  [0,90), θo: NO over [0,90), φ: NP over [0,PHIMAX)), octant,
//                                  spectra into one n × bands array; REPS timed passes
//   gridcheck NAME STRIDE THREADS  every STRIDE-th grid answer vs the reference: mismatches
//   quit
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/interp/batch.h"
#include "core/interp/csv_table.h"
#include "core/interp/delaunay/delaunay.h"
#include "core/interp/interpolator.h"
#include "core/interp/nearest.h"
#include "core/interp/octant/octant.h"
#include "core/interp/octant/reference.h"

namespace brdf::interp {
namespace {

double WallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double CpuNow(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// An uninitialised array of doubles allocated as numpy allocates its arrays: numpy (>= 1.22, on
// Linux) advises the kernel to back allocations of 4 MB or more with transparent huge pages, so
// scipy's result array takes few page faults; ours gets the same treatment.
class NumpyLikeArray {
 public:
  explicit NumpyLikeArray(std::size_t count) : bytes_(std::max<std::size_t>(count, 1) * 8) {
    void* p = nullptr;
    if (posix_memalign(&p, std::size_t{1} << 21, bytes_) != 0) p = nullptr;
    data_ = static_cast<double*>(p);
    if (data_ != nullptr && bytes_ >= (std::size_t{1} << 22)) madvise(p, bytes_, MADV_HUGEPAGE);
  }
  ~NumpyLikeArray() { std::free(data_); }
  NumpyLikeArray(const NumpyLikeArray&) = delete;
  NumpyLikeArray& operator=(const NumpyLikeArray&) = delete;
  double* get() const { return data_; }

 private:
  std::size_t bytes_;
  double* data_ = nullptr;
};

struct Set {
  std::shared_ptr<SampleSet> samples;
  std::unique_ptr<OctantInterpolator> octant;
  std::unique_ptr<Interpolator> nearest;
  std::unique_ptr<DelaunayInterpolator> delaunay;
  std::unique_ptr<Interpolator> reference;
  std::string delaunay_error;
};

std::map<std::string, Set> sets;
std::map<std::string, QueryTable> query_sets;
// The last grid: its queries, statuses and spectra (for gridcheck).
std::vector<double> grid_queries;
std::vector<InterpStatus> grid_status;
std::unique_ptr<double[]> grid_spectra;
std::string grid_set;

void Reply(const std::string& json) {
  std::cout << json << "\n" << std::flush;
}
void Fail(const std::string& message) {
  std::string escaped;
  for (char c : message) {
    if (c == '"' || c == '\\') escaped += '\\';
    escaped += c == '\n' ? ' ' : c;
  }
  Reply("{\"error\":\"" + escaped + "\"}");
}
std::string Num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

Result<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return InvalidArgument("cannot read " + path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void CmdSamples(const std::string& name, const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Fail(text.status().message());
  auto table = ParseSamplesCsv(*text, path);
  if (!table.ok()) return Fail(table.status().message());
  Set set;
  set.samples = table->samples;
  double t0 = WallNow();
  auto octant = OctantInterpolator::Create(set.samples);
  const double octant_s = WallNow() - t0;
  if (!octant.ok()) return Fail(octant.status().message());
  set.octant = std::move(octant).value();
  t0 = WallNow();
  auto nearest = MakeNearestInterpolator(set.samples);
  const double nearest_s = WallNow() - t0;
  if (!nearest.ok()) return Fail(nearest.status().message());
  set.nearest = std::move(nearest).value();
  t0 = WallNow();
  auto delaunay = DelaunayInterpolator::Create(set.samples, {});
  const double delaunay_s = WallNow() - t0;
  if (delaunay.ok()) {
    set.delaunay = std::move(delaunay).value();
  } else {
    set.delaunay_error = delaunay.status().message();
  }
  set.reference = MakeOctantReferenceInterpolator(set.samples).value();
  Reply("{\"samples\":\"" + name + "\",\"n\":" + std::to_string(set.samples->size()) +
        ",\"dims\":" + std::to_string(set.samples->dims()) +
        ",\"bands\":" + std::to_string(set.samples->bands()) +
        ",\"build_s\":{\"octant\":" + Num(octant_s) + ",\"nearest\":" + Num(nearest_s) +
        (set.delaunay ? ",\"delaunay\":" + Num(delaunay_s) : std::string()) + "}}");
  sets[name] = std::move(set);
}

void CmdQueries(const std::string& name, const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Fail(text.status().message());
  auto table = ParseQueriesCsv(*text, path);
  if (!table.ok()) return Fail(table.status().message());
  Reply("{\"queries\":\"" + name + "\",\"n\":" + std::to_string(table->size()) + "}");
  query_sets[name] = std::move(table).value();
}

void CmdRun(const std::string& name, const std::string& qname, const std::string& method,
            const std::string& api) {
  auto s = sets.find(name);
  auto q = query_sets.find(qname);
  if (s == sets.end() || q == query_sets.end()) return Fail("run: unknown set or queries");
  const Set& set = s->second;
  const QueryTable& queries = q->second;
  const std::size_t n = queries.size();
  const auto bands = static_cast<std::size_t>(set.samples->bands());
  const Interpolator* interp = method == "octant"    ? set.octant.get()
                               : method == "nearest" ? set.nearest.get()
                               : method == "delaunay"
                                   ? static_cast<const Interpolator*>(set.delaunay.get())
                                   : nullptr;
  if (interp == nullptr) return Fail("run: no " + method + " interpolator for " + name);
  std::size_t ok = 0;
  double checksum = 0;
  // The result lives until the clocks are read: scipy's result is freed after compare.py's timing
  // too (when `out` is reassigned), so neither side's free is timed.
  std::optional<NumpyLikeArray> out;
  const double wall0 = WallNow();
  const double cpu0 = CpuNow(CLOCK_THREAD_CPUTIME_ID);
  if (api == "spectrum") {
    // Like scipy's result: one n × bands array, allocated per call, not zeroed, with the
    // transparent-huge-page advice numpy gives its large arrays (see NumpyLikeArray).
    out.emplace(n * bands);
    std::vector<InterpStatus> statuses(n);
    if (method == "delaunay") {
      // Delaunay's locality path: each search starts from the previous answer's simplex, as
      // scipy's does.
      LocateHint hint;
      for (std::size_t i = 0; i < n; ++i) {
        const std::span<double> row(out->get() + i * bands, bands);
        ok += set.delaunay->EvaluateSpectrum(queries.query(i), row, hint) == InterpStatus::kOk;
      }
    } else {
      // One call for the whole array, as scipy's.
      interp->SpectraAt(queries.coords, statuses, std::span(out->get(), n * bands));
      for (InterpStatus st : statuses) ok += st == InterpStatus::kOk;
    }
    checksum = out->get()[(n / 2) * bands];
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const Interpolation r = interp->Evaluate(queries.query(i));
      ok += r.status == InterpStatus::kOk;
      if (!r.spectrum.empty()) checksum += r.spectrum[0];
    }
  }
  const double cpu = CpuNow(CLOCK_THREAD_CPUTIME_ID) - cpu0;
  const double wall = WallNow() - wall0;
  Reply("{\"run\":\"" + method + "/" + api + "\",\"n\":" + std::to_string(n) +
        ",\"ok\":" + std::to_string(ok) + ",\"wall_s\":" + Num(wall) + ",\"cpu_s\":" + Num(cpu) +
        ",\"checksum\":" + Num(std::isfinite(checksum) ? checksum : -1) + "}");
}

bool SameAnswer(const Interpolation& a, const Interpolation& b) {
  if (a.status != b.status || a.detail != b.detail || a.spectrum != b.spectrum ||
      a.vertices.size() != b.vertices.size()) {
    return false;
  }
  for (std::size_t k = 0; k < a.vertices.size(); ++k) {
    const Vertex& x = a.vertices[k];
    const Vertex& y = b.vertices[k];
    if (x.id != y.id || x.index != y.index || x.coords != y.coords || x.weight != y.weight) {
      return false;
    }
  }
  return true;
}

void CmdCheck(const std::string& name, const std::string& qname, int threads) {
  auto s = sets.find(name);
  auto q = query_sets.find(qname);
  if (s == sets.end() || q == query_sets.end()) return Fail("check: unknown set or queries");
  BatchOptions options;
  options.threads = threads;
  const double t0 = WallNow();
  auto fast = EvaluateBatch(*s->second.octant, q->second.coords, options);
  auto ref = EvaluateBatch(*s->second.reference, q->second.coords, options);
  if (!fast.ok() || !ref.ok()) return Fail("check: batch failed");
  std::size_t mismatches = 0, ok = 0, empty = 0, no_simplex = 0;
  for (std::size_t i = 0; i < fast->size(); ++i) {
    mismatches += !SameAnswer((*fast)[i], (*ref)[i]);
    ok += (*fast)[i].status == InterpStatus::kOk;
    empty += (*fast)[i].status == InterpStatus::kEmptyOctant;
    no_simplex += (*fast)[i].status == InterpStatus::kNoEnclosingSimplex;
  }
  Reply("{\"check\":\"" + name + "/" + qname + "\",\"n\":" + std::to_string(fast->size()) +
        ",\"mismatches\":" + std::to_string(mismatches) + ",\"ok\":" + std::to_string(ok) +
        ",\"empty_octant\":" + std::to_string(empty) + ",\"no_enclosing_simplex\":" +
        std::to_string(no_simplex) + ",\"wall_s\":" + Num(WallNow() - t0) + "}");
}

void CmdGrid(const std::string& name, int threads, int nt, int no, int np, double phi_max,
             int reps) {
  auto s = sets.find(name);
  if (s == sets.end()) return Fail("grid: unknown set");
  const Set& set = s->second;
  const auto n =
      static_cast<std::size_t>(nt) * static_cast<std::size_t>(no) * static_cast<std::size_t>(np);
  const auto bands = static_cast<std::size_t>(set.samples->bands());
  grid_queries.resize(n * 3);
  std::size_t k = 0;
  for (int a = 0; a < nt; ++a) {
    for (int b = 0; b < no; ++b) {
      for (int c = 0; c < np; ++c) {
        grid_queries[k++] = 90.0 * (a + 0.5) / nt;
        grid_queries[k++] = 90.0 * (b + 0.5) / no;
        grid_queries[k++] = phi_max * (c + 0.5) / np;
      }
    }
  }
  grid_status.assign(n, InterpStatus::kOk);
  if (grid_set != name || !grid_spectra) {
    grid_spectra.reset(new double[n * bands]);
    std::memset(grid_spectra.get(), 0, n * bands * sizeof(double));  // not timed: page faults
  }
  grid_set = name;
  BatchPool pool(threads);
  BatchOptions options;
  options.pool = &pool;
  std::string walls, cpus;
  std::size_t ok = 0;
  for (int r = 0; r < reps; ++r) {
    const double wall0 = WallNow();
    const double cpu0 = CpuNow(CLOCK_PROCESS_CPUTIME_ID);
    const Status st = EvaluateSpectraBatch(*set.octant, grid_queries, grid_status,
                                           std::span(grid_spectra.get(), n * bands), options);
    const double cpu = CpuNow(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
    const double wall = WallNow() - wall0;
    if (!st.ok()) return Fail(st.message());
    walls += (walls.empty() ? "" : ",") + Num(wall);
    cpus += (cpus.empty() ? "" : ",") + Num(cpu);
  }
  for (InterpStatus st : grid_status) ok += st == InterpStatus::kOk;
  Reply("{\"grid\":\"" + name + "\",\"threads\":" + std::to_string(threads) +
        ",\"n\":" + std::to_string(n) + ",\"ok\":" + std::to_string(ok) + ",\"wall_s\":[" + walls +
        "],\"cpu_s\":[" + cpus + "]}");
}

void CmdGridCheck(const std::string& name, std::size_t stride, int threads) {
  auto s = sets.find(name);
  if (s == sets.end() || grid_set != name || !grid_spectra) return Fail("gridcheck: no grid");
  const Set& set = s->second;
  const std::size_t n = grid_status.size();
  const auto bands = static_cast<std::size_t>(set.samples->bands());
  std::vector<double> picked;
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < n; i += stride) {
    rows.push_back(i);
    picked.insert(picked.end(), grid_queries.begin() + static_cast<std::ptrdiff_t>(i * 3),
                  grid_queries.begin() + static_cast<std::ptrdiff_t>(i * 3 + 3));
  }
  std::vector<InterpStatus> status(rows.size());
  std::vector<double> spectra(rows.size() * bands);
  BatchOptions options;
  options.threads = threads;
  const double t0 = WallNow();
  const Status st = EvaluateSpectraBatch(*set.reference, picked, status, spectra, options);
  if (!st.ok()) return Fail(st.message());
  std::size_t mismatches = 0;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const double* a = grid_spectra.get() + rows[r] * bands;
    const double* b = spectra.data() + r * bands;
    bool same = status[r] == grid_status[rows[r]];
    // Bitwise, NaN rows included (both NaN when not ok).
    if (same) same = std::memcmp(a, b, bands * sizeof(double)) == 0;
    mismatches += !same;
  }
  Reply("{\"gridcheck\":\"" + name + "\",\"checked\":" + std::to_string(rows.size()) +
        ",\"mismatches\":" + std::to_string(mismatches) + ",\"wall_s\":" + Num(WallNow() - t0) +
        "}");
  grid_spectra.reset();
  grid_queries = {};
  grid_status = {};
  grid_set.clear();
}

}  // namespace
}  // namespace brdf::interp

int main() {
  using namespace brdf::interp;
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    std::string cmd;
    in >> cmd;
    if (cmd == "samples") {
      std::string name, path;
      in >> name >> path;
      CmdSamples(name, path);
    } else if (cmd == "queries") {
      std::string name, path;
      in >> name >> path;
      CmdQueries(name, path);
    } else if (cmd == "run") {
      std::string name, qname, method, api;
      in >> name >> qname >> method >> api;
      CmdRun(name, qname, method, api);
    } else if (cmd == "check") {
      std::string name, qname;
      int threads = 1;
      in >> name >> qname >> threads;
      CmdCheck(name, qname, threads);
    } else if (cmd == "grid") {
      std::string name;
      int threads = 1, nt = 0, no = 0, np = 0, reps = 1;
      double phi_max = 0;
      in >> name >> threads >> nt >> no >> np >> phi_max >> reps;
      CmdGrid(name, threads, nt, no, np, phi_max, reps);
    } else if (cmd == "gridcheck") {
      std::string name;
      std::size_t stride = 1;
      int threads = 1;
      in >> name >> stride >> threads;
      CmdGridCheck(name, stride, threads);
    } else if (cmd == "quit") {
      break;
    } else if (!cmd.empty()) {
      Fail("unknown command " + cmd);
    }
  }
  return 0;
}
