#include "core/interp/delaunay/qhull.h"

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

extern "C" {
#include <libqhull_r/libqhull_r.h>
}

namespace brdf::interp {
namespace {

// Qhull's diagnostics, captured in memory instead of going to stderr.
class MemoryStream {
 public:
  MemoryStream() : file_(open_memstream(&buffer_, &size_)) {}
  ~MemoryStream() {
    if (file_ != nullptr) std::fclose(file_);
    std::free(buffer_);
  }
  MemoryStream(const MemoryStream&) = delete;
  MemoryStream& operator=(const MemoryStream&) = delete;

  FILE* file() const { return file_; }
  std::string Text() {
    if (file_ == nullptr) return {};
    std::fflush(file_);
    return std::string(buffer_, size_);
  }

 private:
  char* buffer_ = nullptr;
  std::size_t size_ = 0;
  FILE* file_;
};

// Frees Qhull's memory however the triangulation ends.
class QhullSession {
 public:
  explicit QhullSession(FILE* errors) : qh_(std::make_unique<qhT>()) {
    QHULL_LIB_CHECK
    qh_zero(qh_.get(), errors);
  }
  ~QhullSession() {
    int curlong = 0;
    int totlong = 0;
    qh_freeqhull(qh_.get(), !qh_ALL);
    qh_memfreeshort(qh_.get(), &curlong, &totlong);
  }
  QhullSession(const QhullSession&) = delete;
  QhullSession& operator=(const QhullSession&) = delete;

  qhT* get() const { return qh_.get(); }

 private:
  std::unique_ptr<qhT> qh_;
};

// Qhull's message, trimmed to its first few lines: the rest is a generic help text.
std::string FirstLines(const std::string& text, int lines) {
  std::size_t end = 0;
  for (int i = 0; i < lines; ++i) {
    end = text.find('\n', end);
    if (end == std::string::npos) break;
    ++end;
  }
  std::string head = text.substr(0, end);
  while (!head.empty() && (head.back() == '\n' || head.back() == ' ')) head.pop_back();
  return head;
}

}  // namespace

Result<QhullTriangulation> TriangulateWithQhull(std::span<const double> points, int dims) {
  if (dims != 3 && dims != 4) {
    return InvalidArgument("Delaunay triangulation: " + std::to_string(dims) +
                           " dimensions; only 3 (isotropic) and 4 (anisotropic) are supported");
  }
  const std::size_t count = points.size() / static_cast<std::size_t>(dims);
  if (count < static_cast<std::size_t>(dims) + 1) {
    return InvalidArgument("Delaunay triangulation: " + std::to_string(count) +
                           " distinct sample points, need at least " + std::to_string(dims + 1) +
                           " not on one hyperplane; measure more poses");
  }
  if (count > 0x7fffffff) {
    return InvalidArgument("Delaunay triangulation: " + std::to_string(count) +
                           " points exceed Qhull's limit; thin the sample set");
  }

  // Qhull takes a mutable array; give it a copy.
  std::vector<coordT> coords(points.begin(), points.end());
  char options[] = "qhull d Qt Qbb Qc Qz Q12";
  MemoryStream errors;
  QhullSession session(errors.file());
  qhT* qh = session.get();
  const int exit_code = qh_new_qhull(qh, dims, static_cast<int>(count), coords.data(), False,
                                     options, nullptr, errors.file());
  if (exit_code != 0) {
    return InvalidArgument(
        "Delaunay triangulation of " + std::to_string(count) + " points failed (Qhull exit code " +
        std::to_string(exit_code) +
        "; are all samples on one plane or hyperplane?): " + FirstLines(errors.Text(), 4));
  }

  // Number the lower (Delaunay) facets; upper ones (the point at infinity's) are the outside.
  const int corners = dims + 1;
  unsigned lower = 0;
  for (facetT* facet = qh->facet_list; facet != nullptr && facet->next != nullptr;
       facet = facet->next) {
    facet->visitid = facet->upperdelaunay ? 0 : ++lower;
  }
  QhullTriangulation out;
  out.vertices.reserve(static_cast<std::size_t>(lower) * static_cast<std::size_t>(corners));
  out.neighbours.reserve(out.vertices.capacity());
  for (facetT* facet = qh->facet_list; facet != nullptr && facet->next != nullptr;
       facet = facet->next) {
    if (facet->upperdelaunay) continue;
    setT* vertices = facet->vertices;
    setT* neighbours = facet->neighbors;
    if (!facet->simplicial || qh_setsize(qh, vertices) != corners ||
        qh_setsize(qh, neighbours) != corners) {
      return Internal("Delaunay triangulation: Qhull returned a cell with " +
                      std::to_string(qh_setsize(qh, vertices)) + " vertices despite option Qt; " +
                      "report this input");
    }
    // For a simplicial facet Qhull keeps the k-th neighbour opposite the k-th vertex.
    for (int i = 0; i < corners; ++i) {
      auto* vertex = static_cast<vertexT*>(vertices->e[i].p);
      const int id = qh_pointid(qh, vertex->point);
      if (id < 0 || static_cast<std::size_t>(id) >= count) {
        return Internal("Delaunay triangulation: Qhull returned vertex " + std::to_string(id) +
                        " outside the input; report this input");
      }
      out.vertices.push_back(id);
      auto* neighbour = static_cast<facetT*>(neighbours->e[i].p);
      out.neighbours.push_back(
          neighbour->upperdelaunay ? -1 : static_cast<std::int32_t>(neighbour->visitid) - 1);
    }
  }
  if (out.vertices.empty()) {
    return InvalidArgument("Delaunay triangulation of " + std::to_string(count) +
                           " points produced no simplex; the samples are degenerate (coplanar)");
  }
  return out;
}

Result<std::vector<std::array<double, 4>>> ConvexHullPlanes3(std::span<const double> points) {
  const std::size_t count = points.size() / 3;
  if (count < 4 || count > 0x7fffffff) {
    return InvalidArgument("convex hull of " + std::to_string(count) +
                           " points: give 4 to 2^31 − 1 points not on one plane");
  }
  std::vector<coordT> coords(points.begin(), points.end());
  char options[] = "qhull Qt";
  MemoryStream errors;
  QhullSession session(errors.file());
  qhT* qh = session.get();
  const int exit_code = qh_new_qhull(qh, 3, static_cast<int>(count), coords.data(), False, options,
                                     nullptr, errors.file());
  if (exit_code != 0) {
    return InvalidArgument("convex hull of " + std::to_string(count) +
                           " points failed (Qhull exit code " + std::to_string(exit_code) +
                           "; are they all on one plane?): " + FirstLines(errors.Text(), 4));
  }
  std::vector<std::array<double, 4>> planes;
  for (facetT* facet = qh->facet_list; facet != nullptr && facet->next != nullptr;
       facet = facet->next) {
    if (facet->normal == nullptr) continue;
    planes.push_back({facet->normal[0], facet->normal[1], facet->normal[2], facet->offset});
  }
  return planes;
}

}  // namespace brdf::interp
