// Internal to storage/: unwraps a Result<T> into `lhs` or returns its Status from the enclosing
// function. (core/status.h has BRDF_RETURN_IF_ERROR for Status only.)
#pragma once

#include <utility>

#define BRDF_STORAGE_CONCAT_INNER(a, b) a##b
#define BRDF_STORAGE_CONCAT(a, b) BRDF_STORAGE_CONCAT_INNER(a, b)
#define BRDF_STORAGE_ASSIGN_OR_RETURN(lhs, expr) \
  BRDF_STORAGE_ASSIGN_OR_RETURN_IMPL(BRDF_STORAGE_CONCAT(brdf_storage_result_, __LINE__), lhs, expr)
#define BRDF_STORAGE_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                       \
  if (!tmp.ok()) return tmp.status();                      \
  lhs = std::move(tmp).value()
