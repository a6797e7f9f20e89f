// The wire formats of DDS topics, one per binding (DESIGN.md section 7): the envelope
// (cosmic::Envelope, this project's header plus the contents) and opaque (a native topic's
// serialized sample, any type, carried as is). The transport (dds_adapter.cpp) writes and takes
// sample(); the format fills it from an outbound event and reads it into an inbound one.
// Internal to the DDS adapter.
//
// Threads: each WriterEntry/ReaderEntry owns one format object and calls it under its own
// mutex (writer: the egress lane's send(), or a receive thread's in its place; reader: Fast DDS's
// receive thread).
#pragma once

#include <cstdint>
#include <memory>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "cosmic/dds_names.hpp"
#include "cosmic/event.hpp"
#include "cosmic/model.hpp"

namespace cosmic::dds_detail {

// Why an outbound event cannot go out in a format (hot path: no text, no allocation).
enum class FillRefusal {
  none,
  not_encapsulated,      // opaque: fewer than 4 bytes, or no CDR encapsulation identifier
  wrong_representation,  // opaque: the header names the other extended CDR version
};

enum class DecodeResult { event, too_large };

class DdsSampleFormat {
 public:
  virtual ~DdsSampleFormat() = default;
  // The sample DataWriter::write and DataReader::take_next_sample use.
  virtual void* sample() = 0;
  // Makes sample() carry `event`. `first_bytes` receives the event's first two bytes when the
  // refusal is about its encapsulation header (for the one log line the writer gives).
  virtual FillRefusal fill(const OutboundEvent& event, std::uint16_t& first_bytes) = 0;
  // Reads the sample just taken into `event` (channel, header, payload view into the sample).
  virtual DecodeResult decode(const eprosima::fastdds::dds::SampleInfo& info, std::uint64_t max_bytes,
                              InboundEvent& event) = 0;
  // Reserves buffer space for events of `bytes` (no allocation per event in steady state).
  virtual void reserve(std::size_t bytes) = 0;
  // Frees the buffer (a retired reader keeps its object, not its memory).
  virtual void release() = 0;
};

// The format of `topic` for `channel`: opaque for a native topic, the envelope otherwise.
std::unique_ptr<DdsSampleFormat> make_sample_format(const DdsTopicRef& topic, const ChannelSpec& channel);

}  // namespace cosmic::dds_detail
