#include "cosmic/replay_window.hpp"

namespace cosmic {

bool ReplayWindow::accept(std::uint64_t sequence) noexcept {
  if (sequence == 0) return false;  // numbers start at 1
  if (sequence > highest_) {
    shift(sequence - highest_);
    highest_ = sequence;
    mark(0);
    return true;
  }
  const std::uint64_t behind = highest_ - sequence;
  if (behind >= kWidth || seen(behind)) return false;
  mark(behind);
  return true;
}

void ReplayWindow::shift(std::uint64_t by) noexcept {
  if (by >= kWidth) {
    bits_.fill(0);
    return;
  }
  const std::size_t words = static_cast<std::size_t>(by / 64);
  const unsigned bits = static_cast<unsigned>(by % 64);
  // Towards higher i: what was `behind` i is `behind` i + by now.
  for (std::size_t w = bits_.size(); w-- > 0;) {
    std::uint64_t value = 0;
    if (w >= words) {
      value = bits_[w - words] << bits;
      if (bits != 0 && w > words) value |= bits_[w - words - 1] >> (64 - bits);
    }
    bits_[w] = value;
  }
}

bool ReplayWindow::seen(std::uint64_t behind) const noexcept { return (bits_[behind / 64] >> (behind % 64) & 1u) != 0; }

void ReplayWindow::mark(std::uint64_t behind) noexcept { bits_[behind / 64] |= std::uint64_t{1} << (behind % 64); }

}  // namespace cosmic
