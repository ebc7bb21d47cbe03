#include "core/export/grid/npy_writer.h"

#include <bit>
#include <cstdint>
#include <cstring>

namespace brdf::exports {

const char* NpyDescr(NpyType type) {
  return type == NpyType::kFloat32 ? "<f4" : "<f8";
}

const char* NpyTypeName(NpyType type) {
  return type == NpyType::kFloat32 ? "float32" : "float64";
}

std::string NpyHeader(std::span<const std::size_t> shape, NpyType type) {
  std::string dict =
      std::string("{'descr': '") + NpyDescr(type) + "', 'fortran_order': False, 'shape': (";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) dict += ", ";
    dict += std::to_string(shape[i]);
  }
  if (shape.size() == 1) dict += ",";  // a one-element tuple needs its comma
  dict += "), }";
  // 6 magic + 2 version + 2 length bytes precede the header; the header ends with '\n'.
  const std::size_t preamble = 10;
  std::size_t total = preamble + dict.size() + 1;
  total = (total + kNpyAlignment - 1) / kNpyAlignment * kNpyAlignment;
  const std::size_t header_len = total - preamble;
  dict.append(header_len - dict.size() - 1, ' ');
  dict += '\n';

  std::string out = "\x93NUMPY";
  out += static_cast<char>(1);
  out += static_cast<char>(0);
  out += static_cast<char>(header_len & 0xff);
  out += static_cast<char>((header_len >> 8) & 0xff);
  out += dict;
  return out;
}

void AppendLittleEndian(std::span<const double> values, std::string& out) {
  const std::size_t at = out.size();
  out.resize(at + values.size() * sizeof(double));
  char* dst = out.data() + at;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(dst, values.data(), values.size() * sizeof(double));
  } else {
    for (double v : values) {
      const auto bits = std::bit_cast<std::uint64_t>(v);
      for (int b = 0; b < 8; ++b) *dst++ = static_cast<char>((bits >> (8 * b)) & 0xff);
    }
  }
}

namespace {

// `values` rounded to floats, little-endian, into dst (4 bytes a value). On a little-endian host
// a block at a time through a float array, a loop the compiler vectorises (the same conversion,
// value by value, as static_cast<float>).
void Float32Into(std::span<const double> values, char* dst) {
  if constexpr (std::endian::native == std::endian::little) {
    constexpr std::size_t kBlock = 8;
    const double* from = values.data();
    const std::size_t n = values.size();
    std::size_t i = 0;
    for (; i + kBlock <= n; i += kBlock) {
      float block[kBlock];
      for (std::size_t j = 0; j < kBlock; ++j) block[j] = static_cast<float>(from[i + j]);
      std::memcpy(dst + i * sizeof(float), block, sizeof block);
    }
    for (; i < n; ++i) {
      const float f = static_cast<float>(from[i]);
      std::memcpy(dst + i * sizeof(float), &f, sizeof f);
    }
    return;
  }
  for (double v : values) {
    const auto bits = std::bit_cast<std::uint32_t>(static_cast<float>(v));
    for (int b = 0; b < 4; ++b) *dst++ = static_cast<char>((bits >> (8 * b)) & 0xff);
  }
}

}  // namespace

void AppendLittleEndianFloat32(std::span<const double> values, std::string& out) {
  const std::size_t at = out.size();
  out.resize(at + values.size() * sizeof(float));
  Float32Into(values, out.data() + at);
}

Status NpyGridWriter::Begin(const RegularGrid& grid, const WavelengthGrid& bands) {
  grid_ = grid;
  next_slice_ = 0;
  const std::size_t shape[4] = {grid.theta_i.count, grid.theta_o.count, grid.phi.count,
                                bands.count};
  const std::string header = NpyHeader(shape, type_);
  out_.write(header.data(), static_cast<std::streamsize>(header.size()));
  if (!out_) return IoError("writing the .npy header failed: is the disk full or read-only?");
  return Status::Ok();
}

Status NpyGridWriter::NextSlice(std::size_t theta_i_index) {
  if (theta_i_index != next_slice_) {
    return Internal("NpyGridWriter: slice " + std::to_string(theta_i_index) +
                    " arrived, expected " + std::to_string(next_slice_));
  }
  ++next_slice_;
  return Status::Ok();
}

Status NpyGridWriter::Written(std::size_t theta_i_index) {
  if (!out_) {
    return IoError("writing the .npy data failed at θi slice " + std::to_string(theta_i_index) +
                   ": is the disk full?");
  }
  return Status::Ok();
}

Status NpyGridWriter::WritePlane(std::size_t theta_i_index, std::span<const double> rows,
                                 std::size_t planes, std::size_t plane, std::size_t bands,
                                 std::span<const interp::InterpStatus> statuses,
                                 std::vector<double>& scratch) {
  if (type_ != NpyType::kFloat32) {
    return GridSink::WritePlane(theta_i_index, rows, planes, plane, bands, statuses, scratch);
  }
  BRDF_RETURN_IF_ERROR(NextSlice(theta_i_index));
  const std::size_t row_bytes = bands * sizeof(float);
  buffer_.resize(statuses.size() * row_bytes);
  for (std::size_t c = 0; c < statuses.size(); ++c) {
    Float32Into(rows.subspan((c * planes + plane) * bands, bands), buffer_.data() + c * row_bytes);
  }
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  return Written(theta_i_index);
}

Status NpyGridWriter::WriteSlice(std::size_t theta_i_index, std::span<const double> values,
                                 std::span<const interp::InterpStatus> /*statuses*/) {
  BRDF_RETURN_IF_ERROR(NextSlice(theta_i_index));
  if (type_ == NpyType::kFloat64 && std::endian::native == std::endian::little) {
    // The values are the file's bytes already: no copy.
    out_.write(reinterpret_cast<const char*>(values.data()),
               static_cast<std::streamsize>(values.size_bytes()));
  } else {
    buffer_.clear();
    if (type_ == NpyType::kFloat32) {
      AppendLittleEndianFloat32(values, buffer_);
    } else {
      AppendLittleEndian(values, buffer_);
    }
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  }
  return Written(theta_i_index);
}

Status NpyGridWriter::Finish(const GridReport& /*report*/) {
  if (next_slice_ != grid_.theta_i.count) {
    return Internal("NpyGridWriter: finished after " + std::to_string(next_slice_) + " of " +
                    std::to_string(grid_.theta_i.count) + " slices");
  }
  out_.flush();
  if (!out_) return IoError("flushing the .npy file failed: is the disk full?");
  return Status::Ok();
}

}  // namespace brdf::exports
