// NumPy's .npy format, version 1.0, written by hand (no NumPy on the C++ side):
//   "\x93NUMPY", major 1, minor 0, the header's length (uint16, little-endian), then the header:
//   a Python dict literal {'descr': '<f8', 'fortran_order': False, 'shape': (…), } padded with
//   spaces and ended with '\n' so that the data starts at a multiple of 64 bytes; then the data,
//   little-endian doubles in C order ('<f4', floats, for NpyType::kFloat32). np.load reads it as
//   an array of float64 (float32) with that shape.
#pragma once

#include <cstddef>
#include <ostream>
#include <span>
#include <string>

#include "core/export/grid/regular_grid.h"
#include "core/status.h"

namespace brdf::exports {

// The NPY data offset is a multiple of this.
inline constexpr std::size_t kNpyAlignment = 64;

// The element type of an .npy file: IEEE-754 binary64 ('<f8', the default) or binary32 ('<f4':
// half the bytes; about 7 significant digits, far below any meter's noise, and the range of a
// BRDF many times over).
enum class NpyType { kFloat64, kFloat32 };
const char* NpyDescr(NpyType type);     // "<f8", "<f4"
const char* NpyTypeName(NpyType type);  // "float64", "float32"

// Magic, version, length and header for little-endian `type` in C order with `shape` (at least
// one dimension). Its size is a multiple of kNpyAlignment.
std::string NpyHeader(std::span<const std::size_t> shape, NpyType type = NpyType::kFloat64);

// Appends `values` as little-endian IEEE-754 doubles (whatever the host's byte order).
void AppendLittleEndian(std::span<const double> values, std::string& out);
// Appends `values` rounded to the nearest float (NaN stays NaN) as little-endian binary32.
void AppendLittleEndianFloat32(std::span<const double> values, std::string& out);

// A GridSink writing an .npy file of shape (nθi, nθo, nφ, bands) of `type` to `out`, NaN in the
// cells without a value. The axes' values are not in the file: describe them next to it
// (GridDescriptionJson). Errors: kIoError when the stream fails (disk full), kInternal for slices
// out of order.
class NpyGridWriter : public GridSink {
 public:
  explicit NpyGridWriter(std::ostream& out, NpyType type = NpyType::kFloat64)
      : out_(out), type_(type) {}
  Status Begin(const RegularGrid& grid, const WavelengthGrid& bands) override;
  Status WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                    std::span<const interp::InterpStatus> statuses) override;
  // float32: each cell's row of the plane converted where it lies (no gathered copy first);
  // float64: GridSink's.
  Status WritePlane(std::size_t theta_i_index, std::span<const double> rows, std::size_t planes,
                    std::size_t plane, std::size_t bands,
                    std::span<const interp::InterpStatus> statuses,
                    std::vector<double>& scratch) override;
  Status Finish(const GridReport& report) override;

 private:
  Status NextSlice(std::size_t theta_i_index);
  Status Written(std::size_t theta_i_index);

  std::ostream& out_;
  NpyType type_;
  RegularGrid grid_;
  std::size_t next_slice_ = 0;
  std::string buffer_;
};

}  // namespace brdf::exports
