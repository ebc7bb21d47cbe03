// NumPy's .npy format, version 1.0, written by hand (no NumPy on the C++ side):
//   "\x93NUMPY", major 1, minor 0, the header's length (uint16, little-endian), then the header:
//   a Python dict literal {'descr': '<f8', 'fortran_order': False, 'shape': (…), } padded with
//   spaces and ended with '\n' so that the data starts at a multiple of 64 bytes; then the data,
//   little-endian doubles in C order. np.load reads it as an array of float64 with that shape.
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

// Magic, version, length and header for little-endian float64 in C order with `shape` (at
// least one dimension). Its size is a multiple of kNpyAlignment.
std::string NpyHeader(std::span<const std::size_t> shape);

// Appends `values` as little-endian IEEE-754 doubles (whatever the host's byte order).
void AppendLittleEndian(std::span<const double> values, std::string& out);

// A GridSink writing an .npy file of shape (nθi, nθo, nφ, bands) to `out`, NaN in the cells
// without a value. The axes' values are not in the file: describe them next to it
// (GridDescriptionJson). Errors: kIoError when the stream fails (disk full), kInternal for slices
// out of order.
class NpyGridWriter : public GridSink {
 public:
  explicit NpyGridWriter(std::ostream& out) : out_(out) {}
  Status Begin(const RegularGrid& grid, const WavelengthGrid& bands) override;
  Status WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                    std::span<const interp::InterpStatus> statuses) override;
  Status Finish(const GridReport& report) override;

 private:
  std::ostream& out_;
  RegularGrid grid_;
  std::size_t next_slice_ = 0;
  std::string buffer_;
};

}  // namespace brdf::exports
