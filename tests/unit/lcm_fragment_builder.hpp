// A fragment as parse_lcm_datagram would give it, for the reassembler's edge cases that no valid
// datagram sequence reaches directly (lcm_udpm_test.cpp, lcm_reassembly_test.cpp).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "cosmic/lcm_udpm.hpp"

namespace cosmic {

inline LcmDatagram make_fragment(std::uint32_t sequence, std::uint32_t message_size, std::uint32_t offset,
                                 std::uint16_t no, std::uint16_t count, std::span<const std::uint8_t> data,
                                 std::string_view channel = {}) {
  LcmDatagram d;
  d.fragment = true;
  d.sequence = sequence;
  d.channel = channel;
  d.message_size = message_size;
  d.fragment_offset = offset;
  d.fragment_no = no;
  d.fragment_count = count;
  d.data = data;
  return d;
}

}  // namespace cosmic
