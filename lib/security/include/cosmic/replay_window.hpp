// Which sequence numbers of one sender have been accepted already (issue 36: LCM's replay
// protection), as IPsec's anti-replay window keeps them (RFC 4303, section 3.4.3): the highest
// number accepted and a bitmap of the kWidth numbers below it. A number above the highest is new;
// one within the window is new once; one below the window is refused, new or not (a datagram
// delayed behind kWidth later ones of the same sender).
//
// Threads: a value used by one thread (the segment's receive thread). No allocation.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace cosmic {

class ReplayWindow {
 public:
  static constexpr std::size_t kWidth = 256;

  // Whether `sequence` (from 1) was not accepted before and is not below the window; if so it is
  // accepted now. Only for a message whose authenticity is established: a forged number must never
  // move the window.
  bool accept(std::uint64_t sequence) noexcept;
  std::uint64_t highest() const noexcept { return highest_; }

 private:
  void shift(std::uint64_t by) noexcept;
  bool seen(std::uint64_t behind) const noexcept;
  void mark(std::uint64_t behind) noexcept;

  std::uint64_t highest_ = 0;
  // Bit i of the 256: highest_ - i was accepted. Word 0 holds i = 0..63.
  std::array<std::uint64_t, kWidth / 64> bits_{};
};

}  // namespace cosmic
