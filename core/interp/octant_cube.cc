#include "core/interp/octant_cube.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/interp/barycentric.h"

namespace brdf::interp {
namespace {

constexpr std::array<int, 8> kOrthantOfLetter = {0, 1, 3, 2, 4, 5, 7, 6};  // A … H

// The paper's five tetrahedra, in the paper's order: corners B, D, E, G cut off, then the centre.
constexpr std::array<CubeSimplex, 5> kTetrahedra = {{
    {{0, 1, 3, 5, 0}},  // ABCF
    {{0, 3, 2, 6, 0}},  // ACDH
    {{0, 4, 5, 6, 0}},  // AEFH
    {{3, 5, 7, 6, 0}},  // CFGH
    {{0, 3, 5, 6, 0}},  // ACFH
}};

std::array<CubeSimplex, 24> MakeKuhnSimplices() {
  std::array<CubeSimplex, 24> out{};
  std::array<int, 4> perm = {0, 1, 2, 3};
  int s = 0;
  do {
    int corner = 0;
    out[s].corners[0] = corner;
    for (int k = 0; k < 4; ++k) {
      corner |= 1 << perm[k];
      out[s].corners[k + 1] = corner;
    }
    ++s;
  } while (std::next_permutation(perm.begin(), perm.end()));
  return out;
}

const char* AxisName(int axis, int dims) {
  static const char* const k3[] = {"θi", "θo", "φ"};
  static const char* const k4[] = {"θi", "φi", "θo", "φo"};
  return dims == 3 ? k3[axis] : k4[axis];
}

std::string Signs(int orthant, int dims) {
  std::string out = "(";
  for (int j = 0; j < dims; ++j) {
    if (j > 0) out += ", ";
    out += AxisName(j, dims);
    out += (orthant >> j) & 1 ? "+" : "−";
  }
  return out + ")";
}

// Asks the memory system for every cache line of a spectrum, so the lines of all vertices arrive
// in parallel instead of one stream after another.
void PrefetchSpectrum(const double* spectrum, int bands) {
  const char* p = reinterpret_cast<const char*>(spectrum);
  const char* end = reinterpret_cast<const char*>(spectrum + bands);
  for (; p < end; p += 64) __builtin_prefetch(p);
}

}  // namespace

char OctantLetter(int orthant) {
  for (int k = 0; k < 8; ++k) {
    if (kOrthantOfLetter[k] == orthant) return static_cast<char>('A' + k);
  }
  return '?';
}

std::string OrthantName(int orthant, int dims) {
  if (dims == 3) return std::string("octant ") + OctantLetter(orthant) + " " + Signs(orthant, 3);
  return "orthant " + std::to_string(orthant) + " " + Signs(orthant, dims);
}

std::span<const CubeSimplex> CubeSimplices(int dims) {
  static const std::array<CubeSimplex, 24> kKuhn = MakeKuhnSimplices();
  if (dims == 3) return kTetrahedra;
  return kKuhn;
}

const std::string& SimplexName(int simplex_index, int dims) {
  static const auto kNames = [] {
    std::array<std::vector<std::string>, 2> names;  // [0]: 3D, [1]: 4D
    for (int d = 3; d <= 4; ++d) {
      const auto simplices = CubeSimplices(d);
      for (std::size_t s = 0; s < simplices.size(); ++s) {
        std::string name;
        if (d == 3) {
          name = "tetrahedron ";
          for (int k = 0; k < 4; ++k) name += OctantLetter(simplices[s].corners[k]);
        } else {
          name = "Kuhn simplex " + std::to_string(s) + " of 24 (corners ";
          for (int k = 0; k <= d; ++k) {
            if (k > 0) name += "-";
            name += std::to_string(simplices[s].corners[k]);
          }
          name += ")";
        }
        names[static_cast<std::size_t>(d - 3)].push_back(std::move(name));
      }
    }
    return names;
  }();
  return kNames[static_cast<std::size_t>(dims - 3)][static_cast<std::size_t>(simplex_index)];
}

bool ValidQuery(std::span<const double> query, int dims) {
  if (query.size() != static_cast<std::size_t>(dims)) return false;
  return std::all_of(query.begin(), query.end(), [](double x) { return std::isfinite(x); });
}

Interpolation InvalidQueryAnswer(Method method, InterpStatus status, std::span<const double> query,
                                 int dims) {
  Interpolation out;
  out.method = method;
  out.status = status;
  if (query.size() != static_cast<std::size_t>(dims)) {
    out.detail = "the query has " + std::to_string(query.size()) +
                 " coordinates; the samples have " + std::to_string(dims);
    return out;
  }
  for (std::size_t j = 0; j < query.size(); ++j) {
    if (!std::isfinite(query[j])) {
      out.detail = std::string("query coordinate ") + AxisName(static_cast<int>(j), dims) +
                   " is not a finite number";
      break;
    }
  }
  return out;
}

Interpolation AssembleOctantAnswer(const PointCloud& cloud, const SampleSet& samples,
                                   const OrthantWinners& winners,
                                   std::span<const double> scaled_query) {
  const int dims = cloud.dims;
  const int orthants = 1 << dims;
  Interpolation out;
  out.method = Method::kOctant;

  std::string empty;
  for (int k = 0; k < orthants; ++k) {
    // In 3D list empty octants in letter order (A … H), in 4D by number.
    const int o = dims == 3 ? kOrthantOfLetter[static_cast<std::size_t>(k)] : k;
    if (winners.rank[static_cast<std::size_t>(o)] != kNoPoint) continue;
    empty += empty.empty() ? "" : ", ";
    empty += OrthantName(o, dims);
  }
  if (!empty.empty()) {
    out.status = InterpStatus::kEmptyOctant;
    out.detail = "no sample in " + empty;
    return out;
  }

  const auto simplices = CubeSimplices(dims);
  const auto vertex_count = static_cast<std::size_t>(dims + 1);
  int degenerate = 0;
  std::array<const double*, kMaxSimplexVertices> vertex_points{};
  for (std::size_t s = 0; s < simplices.size(); ++s) {
    for (std::size_t k = 0; k < vertex_count; ++k) {
      vertex_points[k] = winners.scaled[static_cast<std::size_t>(simplices[s].corners[k])];
    }
    const BarycentricWeights bw =
        Barycentric(std::span(vertex_points.data(), vertex_count), scaled_query.data(), dims);
    if (bw.fit == SimplexFit::kDegenerate) ++degenerate;
    if (bw.fit != SimplexFit::kEncloses) continue;

    // The vertex spectra are scattered over the sample set: start fetching all of them at once.
    std::array<std::uint32_t, kMaxSimplexVertices> index{};
    std::array<const double*, kMaxSimplexVertices> spectra{};
    for (std::size_t k = 0; k < vertex_count; ++k) {
      const std::uint32_t rank = winners.rank[static_cast<std::size_t>(simplices[s].corners[k])];
      index[k] = cloud.sample[rank];
      spectra[k] = samples.spectrum(index[k]).data();
      PrefetchSpectrum(spectra[k], samples.bands());
    }
    out.vertices.resize(vertex_count);
    for (std::size_t k = 0; k < vertex_count; ++k) {
      const std::uint32_t rank = winners.rank[static_cast<std::size_t>(simplices[s].corners[k])];
      Vertex& v = out.vertices[k];
      v.id = samples.id(index[k]);
      v.index = index[k];
      const auto p = cloud.point(rank);
      v.coords.assign(p.begin(), p.end());
      v.weight = bw.weights[k];
    }
    out.spectrum.resize(static_cast<std::size_t>(samples.bands()));
    BlendSpectra(std::span(bw.weights.data(), vertex_count),
                 std::span(spectra.data(), vertex_count), out.spectrum);
    out.detail = SimplexName(static_cast<int>(s), dims);
    return out;
  }
  out.status = InterpStatus::kNoEnclosingSimplex;
  out.detail = std::string("none of the ") + (dims == 3 ? "5 tetrahedra" : "24 Kuhn simplices") +
               " of the nearest samples encloses the query";
  if (degenerate > 0) out.detail += " (" + std::to_string(degenerate) + " of them flat)";
  return out;
}

}  // namespace brdf::interp
