#include "daemon/api/session_catalogue.h"

#include <algorithm>
#include <cctype>

#include "daemon/wire/values.h"

namespace brdf::daemon {
namespace {

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

}  // namespace

bool CatalogueFilter::Matches(const v1::Session& session) const {
  if (!rig.empty() && session.rig() != rig) return false;
  const v1::Sample& s = session.sample();
  if (!sample.empty() && s.id() != sample && Lower(s.name()) != Lower(sample)) return false;
  if (!material.empty() && Lower(s.material()) != Lower(material)) return false;
  if (!tag.empty() && std::find(s.tags().begin(), s.tags().end(), tag) == s.tags().end()) {
    return false;
  }
  const double created = ToUnixSeconds(session.created_at());
  if (created_after.has_value() && created < *created_after) return false;
  if (created_before.has_value() && !(created < *created_before)) return false;
  return true;
}

}  // namespace brdf::daemon
