#include "daemon/api/batch_request.h"

#include <google/protobuf/arena.h>
#include <grpcpp/impl/codegen/proto_utils.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>
#include <new>

namespace brdf::daemon {

namespace {

// The parse's arena blocks, mapped for it and unmapped when it ends: a parsed batch is ~10 MB of
// small messages, and blocks taken from malloc could stay in the allocator's per-thread arenas
// after the parse (each of brdfd's handler threads keeping one batch's worth).
void* MapBlock(std::size_t bytes) {
  void* block = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (block == MAP_FAILED) throw std::bad_alloc();
  return block;
}
void UnmapBlock(void* block, std::size_t bytes) {
  munmap(block, bytes);
}

constexpr std::size_t kParseBlockBytes = std::size_t{1} << 20;

}  // namespace

QueryAngles AnglesOf(const v1::DirectionQuery& query) {
  QueryAngles out;
  out.form = query.direction_case();
  if (out.form == v1::DirectionQuery::kIso) {
    out.angles = {query.iso().theta_i(), query.iso().theta_o(), query.iso().phi(), 0};
  } else if (out.form == v1::DirectionQuery::kFour) {
    out.angles = {query.four().theta_i(), query.four().phi_i(), query.four().theta_o(),
                  query.four().phi_o()};
  }
  return out;
}

void ToQuery(const QueryAngles& angles, v1::DirectionQuery* query) {
  const std::array<double, 4>& a = angles.angles;
  if (angles.form == v1::DirectionQuery::kIso) {
    v1::IsoDirection* iso = query->mutable_iso();
    iso->set_theta_i(a[0]);
    iso->set_theta_o(a[1]);
    iso->set_phi(a[2]);
  } else if (angles.form == v1::DirectionQuery::kFour) {
    v1::Directions* four = query->mutable_four();
    four->set_theta_i(a[0]);
    four->set_phi_i(a[1]);
    four->set_theta_o(a[2]);
    four->set_phi_o(a[3]);
  } else {
    query->clear_direction();
  }
}

void PackedDirections::Assign(
    const google::protobuf::RepeatedPtrField<v1::DirectionQuery>& queries) {
  const bool four = std::any_of(queries.begin(), queries.end(), [](const v1::DirectionQuery& q) {
    return q.direction_case() == v1::DirectionQuery::kFour;
  });
  stride_ = four ? 4 : 3;
  forms_.clear();
  angles_.clear();
  forms_.reserve(static_cast<std::size_t>(queries.size()));
  angles_.reserve(stride_ * static_cast<std::size_t>(queries.size()));
  for (const v1::DirectionQuery& query : queries) {
    const QueryAngles q = AnglesOf(query);
    forms_.push_back(static_cast<std::uint8_t>(q.form));
    angles_.insert(angles_.end(), q.angles.begin(),
                   q.angles.begin() + static_cast<std::ptrdiff_t>(stride_));
  }
}

QueryAngles PackedDirections::operator[](std::size_t i) const {
  QueryAngles q;
  q.form = static_cast<v1::DirectionQuery::DirectionCase>(forms_[i]);
  std::copy_n(angles_.begin() + static_cast<std::ptrdiff_t>(i * stride_), stride_,
              q.angles.begin());
  return q;
}

grpc::Status ReadBatchRequest(BatchStreamer& streamer, BatchRequest* out) {
  grpc::ByteBuffer wire;
  if (!streamer.Read(&wire)) {
    return grpc::Status(grpc::StatusCode::INTERNAL,
                        "InterpolateBatch: the request could not be read; send an "
                        "InterpolateBatchRequest");
  }
  google::protobuf::ArenaOptions options;
  options.start_block_size = kParseBlockBytes;
  options.max_block_size = kParseBlockBytes;
  options.block_alloc = MapBlock;
  options.block_dealloc = UnmapBlock;
  google::protobuf::Arena arena(options);
  auto* parsed = google::protobuf::Arena::CreateMessage<v1::InterpolateBatchRequest>(&arena);
  // gRPC's own parse (its error as its generated handler gives it); it frees the wire bytes.
  if (grpc::Status st =
          grpc::SerializationTraits<v1::InterpolateBatchRequest>::Deserialize(&wire, parsed);
      !st.ok()) {
    return st;
  }
  out->directions.Assign(parsed->directions());
  parsed->clear_directions();
  out->settings.CopyFrom(*parsed);
  return grpc::Status::OK;
}

}  // namespace brdf::daemon
