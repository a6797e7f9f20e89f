// What the configuration tests share: a parse result's errors as text, one per line, and the check
// that a document is refused with an expected error (its location and key path included).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "cosmic/config_loader.hpp"

namespace cosmic::test {

inline std::string errors_text(const ConfigResult& r) {
  std::string out;
  for (const auto& e : r.errors) out += e.to_string() + "\n";
  return out;
}

// `r` is refused and one of its errors contains `expected`.
inline void expect_refused_with(const ConfigResult& r, const std::string& expected) {
  EXPECT_FALSE(r.ok()) << expected;
  EXPECT_NE(errors_text(r).find(expected), std::string::npos) << "want: " << expected << "\ngot:\n" << errors_text(r);
}

}  // namespace cosmic::test
