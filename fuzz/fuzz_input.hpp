// Reads typed values off the front of a fuzz input; past the end every read yields zero, so a
// target never needs to check lengths itself.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>

namespace cosmic::fuzz {

class FuzzInput {
 public:
  FuzzInput(const std::uint8_t* data, std::size_t size) : rest_(data, size) {}

  bool empty() const { return rest_.empty(); }
  std::uint8_t byte() {
    if (rest_.empty()) return 0;
    const std::uint8_t b = rest_.front();
    rest_ = rest_.subspan(1);
    return b;
  }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | byte();
    return v;
  }
  // Up to `count` bytes (fewer at the end of the input).
  std::span<const std::uint8_t> bytes(std::size_t count) {
    const std::size_t n = count < rest_.size() ? count : rest_.size();
    const auto out = rest_.first(n);
    rest_ = rest_.subspan(n);
    return out;
  }

 private:
  std::span<const std::uint8_t> rest_;
};

// A broken invariant is a finding: say which, and abort so libFuzzer saves the input.
// (clang-14 with libstdc++ 12 has no std::source_location: the builtins it rests on.)
inline void require(bool condition, const char* file = __builtin_FILE(), int line = __builtin_LINE()) {
  if (condition) return;
  std::fprintf(stderr, "broken invariant at %s:%d\n", file, line);
  std::abort();
}

}  // namespace cosmic::fuzz
