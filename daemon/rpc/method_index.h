// A method's index among its service's methods, as gRPC's generated service numbers them (the
// proto's order), read from the service's descriptor: a handler registered by index for one
// method (MarkMethodStreamed, daemon/api/data.h and batch_request.h) stays on that method when
// brdf.proto's methods are reordered.
#pragma once

#include <google/protobuf/descriptor.h>

namespace brdf::daemon {

// `service`: its full name (the generated class's service_full_name()); `method` one of its
// methods' names (a name the service lacks is a programming error).
inline int MethodIndex(const char* service, const char* method) {
  return google::protobuf::DescriptorPool::generated_pool()
      ->FindServiceByName(service)
      ->FindMethodByName(method)
      ->index();
}

}  // namespace brdf::daemon
