#include "dds_sample_format.hpp"

#include <cosmic_dds_idl/Envelope.h>

#include "cosmic/dds_encapsulation.hpp"
#include "dds_opaque_type.hpp"

namespace cosmic::dds_detail {
namespace {

namespace dds = eprosima::fastdds::dds;

// The RTPS sequence number of the sample in its writer, truncated to the envelope's 32 bits.
std::uint32_t writer_sequence(const dds::SampleInfo& info) {
  return static_cast<std::uint32_t>(info.sample_identity.sequence_number().to64long());
}

class EnvelopeFormat final : public DdsSampleFormat {
 public:
  void* sample() override { return &envelope_; }
  FillRefusal fill(const OutboundEvent& event, std::uint16_t&) override {
    envelope_.subject(event.header.subject);
    envelope_.origin(event.header.origin);
    envelope_.sequence(event.header.sequence);
    envelope_.hop_count(event.header.hop_count);
    envelope_.created_ns(event.header.created_ns);
    envelope_.age_ns(event.header.age_ns);
    envelope_.payload().assign(event.payload.begin(), event.payload.end());  // reuses capacity
    return FillRefusal::none;
  }
  DecodeResult decode(const dds::SampleInfo& info, std::uint64_t max_bytes, InboundEvent& event) override {
    // An envelope carrying this gateway's origin from another participant (a loop through
    // another gateway, or a spoof) goes on: the router counts and drops it (ingress check).
    const cosmic::Envelope& env = envelope_;
    if (env.payload().size() > max_bytes) return DecodeResult::too_large;
    event.header.subject = env.subject();
    event.header.origin = env.origin();
    // A native publisher (origin 0) has no envelope sequence of ours: its writer's own sample
    // sequence number takes its place, so a loss on the hop from it stays visible downstream.
    event.header.sequence = env.origin() == 0 ? writer_sequence(info) : env.sequence();
    event.header.hop_count = env.hop_count();
    event.header.created_ns = env.created_ns();
    event.header.age_ns = env.age_ns();
    event.payload = std::span<const std::uint8_t>(env.payload().data(), env.payload().size());
    event.identity = FormatIdentity{};  // the whole header travels
    return DecodeResult::event;
  }
  void reserve(std::size_t bytes) override { envelope_.payload().reserve(bytes); }
  void release() override { envelope_.payload() = {}; }

 private:
  cosmic::Envelope envelope_;
};

// A native topic's sample: the contents are the serialized sample itself. It carries no origin,
// sequence, hop count or age: the router treats it as a native source (origin 0), numbered by its
// writer's RTPS sequence; the transport drops this gateway's own writes by GUID prefix.
class OpaqueFormat final : public DdsSampleFormat {
 public:
  OpaqueFormat(std::uint64_t subject, DdsRepresentation representation)
      : subject_(subject), representation_(representation) {}
  void* sample() override { return &sample_; }
  FillRefusal fill(const OutboundEvent& event, std::uint16_t& first_bytes) override {
    const std::optional<DdsEncapsulation> header = read_dds_encapsulation(event.payload);
    if (!header || header->representation != representation_) {
      first_bytes =
          event.payload.size() >= 2 ? static_cast<std::uint16_t>((event.payload[0] << 8) | event.payload[1]) : 0;
      return header ? FillRefusal::wrong_representation : FillRefusal::not_encapsulated;
    }
    sample_.bytes.assign(event.payload.begin(), event.payload.end());
    return FillRefusal::none;
  }
  DecodeResult decode(const dds::SampleInfo& info, std::uint64_t max_bytes, InboundEvent& event) override {
    if (sample_.bytes.size() > max_bytes) return DecodeResult::too_large;
    event.header = EventHeader{};
    event.header.subject = subject_;
    event.header.sequence = writer_sequence(info);
    event.payload = std::span<const std::uint8_t>(sample_.bytes.data(), sample_.bytes.size());
    // No origin, sequence or hop count of its own; no copy of ours comes back (dropped by GUID
    // prefix), so no fingerprint guard either.
    event.identity = FormatIdentity{false, false, false, false};
    return DecodeResult::event;
  }
  void reserve(std::size_t bytes) override { sample_.bytes.reserve(bytes); }
  void release() override { sample_.bytes = {}; }

 private:
  std::uint64_t subject_;
  DdsRepresentation representation_;
  OpaqueSample sample_;
};

}  // namespace

std::unique_ptr<DdsSampleFormat> make_sample_format(const DdsTopicRef& topic, const ChannelSpec& channel) {
  if (topic.native) return std::make_unique<OpaqueFormat>(channel.subject, topic.representation);
  return std::make_unique<EnvelopeFormat>();
}

}  // namespace cosmic::dds_detail
