// An answer's `not_estimated` list written into the strings an earlier answer left in it: a batch
// answers thousands of directions into the same message, and its entries' storage is reused
// instead of allocated for each answer. Add and AddUnique write the next entry; Finish drops
// what the earlier answer had beyond this one's. The list must not be touched otherwise in
// between.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace brdf::uncertainty {

class NoteList {
 public:
  explicit NoteList(std::vector<std::string>& list) : list_(list) {}

  void Add(std::string_view entry) {
    if (used_ < list_.size()) {
      list_[used_].assign(entry);
    } else {
      list_.emplace_back(entry);
    }
    ++used_;
  }

  // Add unless this answer's entries already hold it (a shared input met through two vertices).
  void AddUnique(std::string_view entry) {
    const auto first = list_.begin(), last = first + static_cast<std::ptrdiff_t>(used_);
    if (std::find(first, last, entry) == last) Add(entry);
  }

  void Finish() { list_.resize(used_); }

 private:
  std::vector<std::string>& list_;
  std::size_t used_ = 0;
};

}  // namespace brdf::uncertainty
