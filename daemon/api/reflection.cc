#include "daemon/api/reflection.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>

#include <algorithm>

#include "daemon/api/common.h"

namespace brdf::daemon {
namespace {

namespace pb = google::protobuf;

// `file` and, depth first, the files it imports, each unless already in *sent.
template <class Response>
void AddFile(const pb::FileDescriptor* file, std::vector<std::string>* sent, Response* response) {
  if (std::find(sent->begin(), sent->end(), file->name()) != sent->end()) return;
  sent->push_back(file->name());
  pb::FileDescriptorProto proto;
  file->CopyTo(&proto);
  proto.SerializeToString(
      response->mutable_file_descriptor_response()->add_file_descriptor_proto());
  for (int i = 0; i < file->dependency_count(); ++i) AddFile(file->dependency(i), sent, response);
}

template <class Response>
void NotFound(const std::string& what, const std::string& name, Response* response) {
  auto* error = response->mutable_error_response();
  error->set_error_code(static_cast<int>(grpc::StatusCode::NOT_FOUND));
  error->set_error_message("reflection: no " + what + " \"" + PrintablePrefix(name) +
                           "\" in brdfd; list_services names what it serves");
}

}  // namespace

template <class Request, class Response>
void AnswerReflection(const std::vector<std::string>& services, const Request& request,
                      std::vector<std::string>* sent_files, Response* response) {
  const pb::DescriptorPool* pool = pb::DescriptorPool::generated_pool();
  response->set_valid_host(PrintablePrefix(request.host()));
  *response->mutable_original_request() = request;
  switch (request.message_request_case()) {
    case Request::kListServices:
      for (const std::string& name : services) {
        response->mutable_list_services_response()->add_service()->set_name(name);
      }
      return;
    case Request::kFileByFilename: {
      const pb::FileDescriptor* file = pool->FindFileByName(request.file_by_filename());
      if (file == nullptr) return NotFound("file", request.file_by_filename(), response);
      // The file asked for always goes out, even if this stream sent it before.
      sent_files->erase(std::remove(sent_files->begin(), sent_files->end(), file->name()),
                        sent_files->end());
      return AddFile(file, sent_files, response);
    }
    case Request::kFileContainingSymbol: {
      const pb::FileDescriptor* file =
          pool->FindFileContainingSymbol(request.file_containing_symbol());
      if (file == nullptr) return NotFound("symbol", request.file_containing_symbol(), response);
      sent_files->erase(std::remove(sent_files->begin(), sent_files->end(), file->name()),
                        sent_files->end());
      return AddFile(file, sent_files, response);
    }
    case Request::kFileContainingExtension: {
      const auto& ask = request.file_containing_extension();
      const pb::Descriptor* type = pool->FindMessageTypeByName(ask.containing_type());
      const pb::FieldDescriptor* extension =
          type == nullptr ? nullptr : pool->FindExtensionByNumber(type, ask.extension_number());
      if (extension == nullptr) {
        return NotFound("extension " + std::to_string(ask.extension_number()) + " of",
                        ask.containing_type(), response);
      }
      return AddFile(extension->file(), sent_files, response);
    }
    case Request::kAllExtensionNumbersOfType: {
      const pb::Descriptor* type =
          pool->FindMessageTypeByName(request.all_extension_numbers_of_type());
      if (type == nullptr) {
        return NotFound("message type", request.all_extension_numbers_of_type(), response);
      }
      std::vector<const pb::FieldDescriptor*> extensions;
      pool->FindAllExtensions(type, &extensions);
      auto* out = response->mutable_all_extension_numbers_response();
      out->set_base_type_name(type->full_name());
      for (const pb::FieldDescriptor* e : extensions) out->add_extension_number(e->number());
      return;
    }
    default: {
      auto* error = response->mutable_error_response();
      error->set_error_code(static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT));
      error->set_error_message(
          "reflection: the request asks for nothing brdfd knows (set list_services, "
          "file_by_filename, file_containing_symbol, file_containing_extension or "
          "all_extension_numbers_of_type)");
      return;
    }
  }
}

template void AnswerReflection(const std::vector<std::string>&,
                               const grpc::reflection::v1::ServerReflectionRequest&,
                               std::vector<std::string>*,
                               grpc::reflection::v1::ServerReflectionResponse*);
template void AnswerReflection(const std::vector<std::string>&,
                               const grpc::reflection::v1alpha::ServerReflectionRequest&,
                               std::vector<std::string>*,
                               grpc::reflection::v1alpha::ServerReflectionResponse*);

}  // namespace brdf::daemon
