// The sizes of authenticated LCM (issue 36; the trailer itself: cosmic/lcm_auth.hpp in the
// security library), for those that count bytes without computing a tag: the configuration's key
// bounds and admission's message sizes.
#pragma once

#include <cstddef>

namespace cosmic {

inline constexpr std::size_t kLcmAuthTagSize = 16;                               // HMAC-SHA256, truncated
inline constexpr std::size_t kLcmAuthTrailerSize = 8 + 8 + 8 + kLcmAuthTagSize;  // sender, sequence, sent_ns: 40
// Keys: HMAC-SHA256's block is 64 bytes, and fewer than 16 bytes are too easily guessed.
inline constexpr std::size_t kLcmAuthMinKeyBytes = 16;
inline constexpr std::size_t kLcmAuthMaxKeyBytes = 64;

}  // namespace cosmic
