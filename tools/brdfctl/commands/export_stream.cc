#include "tools/brdfctl/commands/export_stream.h"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>

#include "brdf/v1/brdf.grpc.pb.h"
#include "core/export/chunk_wire.h"

namespace brdf::ctl {
namespace {

namespace chunk_wire = exports::chunk_wire;

// The method's path, "/brdf.v1.Data/Export", from the generated service's name.
const char* ExportMethodPath() {
  static const std::string path = "/" + std::string(v1::Data::service_full_name()) + "/Export";
  return path.c_str();
}

// Reads a message's bytes across its slices, without copying them.
class SliceCursor {
 public:
  explicit SliceCursor(const std::vector<grpc::Slice>& slices) : slices_(slices) {}

  std::uint64_t position() const { return position_; }

  bool Byte(std::uint8_t* b) {
    while (slice_ < slices_.size() && at_ == slices_[slice_].size()) Next();
    if (slice_ == slices_.size()) return false;
    *b = slices_[slice_].begin()[at_++];
    ++position_;
    return true;
  }

  bool Varint(std::uint64_t* v) {
    return exports::chunk_wire::GetVarint([this](std::uint8_t* b) { return Byte(b); }, v);
  }

  // The next `n` bytes as pieces of the slices.
  bool Take(std::uint64_t n, std::vector<std::string_view>* pieces) {
    while (n > 0) {
      if (slice_ == slices_.size()) return false;
      const grpc::Slice& s = slices_[slice_];
      const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(n, s.size() - at_));
      if (take > 0) pieces->emplace_back(reinterpret_cast<const char*>(s.begin()) + at_, take);
      at_ += take;
      position_ += take;
      n -= take;
      if (at_ == s.size()) Next();
    }
    return true;
  }

 private:
  void Next() {
    ++slice_;
    at_ = 0;
  }

  const std::vector<grpc::Slice>& slices_;
  std::size_t slice_ = 0;
  std::size_t at_ = 0;
  std::uint64_t position_ = 0;
};

// A data message as brdfd lays it out (core/export/chunk_wire.h): ExportChunk holding only
// ExportData, whose fields are offset, content and part. False for anything else (protobuf
// parses it).
bool ParseDataInPlace(std::uint64_t total, ExportMessage* out) {
  SliceCursor in(out->slices);
  std::uint64_t tag = 0;
  std::uint64_t length = 0;
  if (!in.Varint(&tag) || tag != chunk_wire::kChunkData || !in.Varint(&length) ||
      in.position() + length != total) {
    return false;
  }
  while (in.position() < total) {
    std::uint64_t n = 0;
    if (!in.Varint(&tag)) return false;
    if (tag == chunk_wire::kDataOffset) {
      if (!in.Varint(&out->offset)) return false;
    } else if (tag == chunk_wire::kDataContent) {
      out->content.clear();
      if (!in.Varint(&n) || !in.Take(n, &out->content)) return false;
      out->content_size = n;
    } else if (tag == chunk_wire::kDataPart) {
      std::vector<std::string_view> name;
      if (!in.Varint(&n) || n > 256 || !in.Take(n, &name)) return false;
      out->part.clear();
      for (std::string_view piece : name) out->part.append(piece);
    } else {
      return false;
    }
  }
  return in.position() == total;
}

}  // namespace

bool ParseExportMessage(grpc::ByteBuffer& buffer, ExportMessage* out) {
  *out = ExportMessage();
  const std::uint64_t total = buffer.Length();
  if (buffer.Dump(&out->slices).ok() && ParseDataInPlace(total, out)) {
    out->data = true;
    return true;
  }
  *out = ExportMessage();
  if (!grpc::SerializationTraits<v1::ExportChunk>::Deserialize(&buffer, &out->chunk).ok()) {
    return false;
  }
  if (out->chunk.has_data()) {
    v1::ExportData& data = *out->chunk.mutable_data();
    out->data = true;
    out->offset = data.offset();
    out->part = data.part();
    out->owned = std::move(*data.mutable_content());
    out->content_size = out->owned.size();
    if (!out->owned.empty()) out->content.emplace_back(out->owned);
  }
  return true;
}

ExportStreamReader::ExportStreamReader(const std::shared_ptr<grpc::Channel>& channel,
                                       grpc::ClientContext* context,
                                       const v1::ExportRequest& request)
    : method_(ExportMethodPath(), grpc::internal::RpcMethod::SERVER_STREAMING, channel),
      reader_(grpc::internal::ClientReaderFactory<grpc::ByteBuffer>::Create(channel.get(), method_,
                                                                            context, request)) {}

bool ExportStreamReader::Read(ExportMessage* out) {
  if (malformed_ || !reader_->Read(&buffer_)) return false;
  malformed_ = !ParseExportMessage(buffer_, out);
  buffer_.Clear();
  return !malformed_;
}

ExportFile::~ExportFile() {
  Close();
}

bool ExportFile::Open(const std::string& path) {
  Close();
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  ok_ = fd_ >= 0;
  return ok_;
}

bool ExportFile::Write(const std::vector<std::string_view>& pieces) {
  std::vector<iovec> io;
  io.reserve(pieces.size());
  for (std::string_view p : pieces) {
    io.push_back(iovec{const_cast<char*>(p.data()), p.size()});
  }
  std::size_t first = 0;
  while (ok_ && first < io.size()) {
    const int count = static_cast<int>(std::min<std::size_t>(io.size() - first, IOV_MAX));
    const ssize_t wrote = ::writev(fd_, io.data() + first, count);
    if (wrote < 0) {
      ok_ = errno == EINTR;
      continue;
    }
    // Past the pieces written whole, then into the one written in part.
    std::size_t left = static_cast<std::size_t>(wrote);
    while (first < io.size() && left >= io[first].iov_len) left -= io[first++].iov_len;
    if (left > 0) {
      io[first].iov_base = static_cast<char*>(io[first].iov_base) + left;
      io[first].iov_len -= left;
    }
  }
  return ok_;
}

bool ExportFile::Close() {
  if (fd_ >= 0) {
    if (::close(fd_) != 0) ok_ = false;
    fd_ = -1;
  }
  return ok_;
}

}  // namespace brdf::ctl
