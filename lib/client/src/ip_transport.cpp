// DDS and LCM for a component: the gateway's adapters with the roles mirrored, so topics, envelope
// and QoS are exactly what cosmicd expects (one implementation of the mapping, not two).
#include <fastrtps/config.h>

#include <random>
#include <vector>

#include "cosmic/client.h"
#include "cosmic/dds_adapter.hpp"
#include "cosmic/lcm_adapter.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/thread_annotations.hpp"
#include "transport.hpp"

namespace cosmic::client_detail {
namespace {

// Keeps the adapters' last warning for cosmic_last_error(); the library never prints.
class QuietLogger : public Logger {
 public:
  void log(LogLevel level, std::string_view message) override {
    if (level < LogLevel::warning) return;
    LockGuard lock(mutex_);
    last_ = message;
  }
  std::string last() {
    LockGuard lock(mutex_);
    return last_;
  }

 private:
  Mutex mutex_;
  std::string last_ COSMIC_GUARDED_BY(mutex_);
};

// A channel announced as `index` is binding id index + 1 in both roles (publisher: the adapter
// sends; subscriber: the adapter receives), as the gateway binds a channel it both receives and
// sends on one segment: LCM carries one channel name under one id only.
ChannelId binding_id(std::size_t index) { return static_cast<ChannelId>(index + 1); }
std::size_t index_of(ChannelId id) { return static_cast<std::size_t>(id - 1); }

// Fast DDS before 2.10 matches a participant's reader with its own writer of the same topic (the
// adapter sets fastdds.ignore_local_endpoints, which takes effect from 2.10 on): a channel announced
// with both roles is matched once by itself in each role, and that match carries nothing between
// the component and the gateway. tests/model/client_test.cpp checks that such a channel without a
// peer is not ready.
#if FASTRTPS_VERSION_MAJOR < 2 || (FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR < 10)
constexpr std::size_t kOwnMatchesWithBothRoles = 1;
#else
constexpr std::size_t kOwnMatchesWithBothRoles = 0;
#endif

// The adapter's role for the component's endpoint of `role`: the component's publication is the
// adapter's sending side (HopRole::subscriber, a writer), its subscription the receiving one.
HopRole hop_role_of(int role) { return role == COSMIC_PUBLISH ? HopRole::subscriber : HopRole::publisher; }

class IpTransport final : public Transport, private EventSink {
 public:
  explicit IpTransport(const SegmentSpec& segment) : segment_(segment) {
    std::random_device random;
    self_.id = (static_cast<std::uint64_t>(random()) << 32 | random()) | 1;  // never 0
    self_.name = "cosmic-client";
  }
  ~IpTransport() override {
    if (adapter_) adapter_->stop();
  }

  int start(Delivery& delivery, std::string& error) override {
    delivery_ = &delivery;
    if (segment_.type == SegmentType::dds) {
      auto dds = make_dds_segment_adapter(segment_, self_, log_);
      dds_ = dds.get();
      adapter_ = std::move(dds);
    } else {
      adapter_ = make_lcm_adapter(segment_, self_, log_);
    }
    const Status s = adapter_->start(*this);
    if (!s.ok) error = s.error;
    return s.ok ? COSMIC_OK : COSMIC_E_TRANSPORT;
  }

  int announce(std::size_t index, const ChannelSpec& spec, int roles, int, std::string& error) override {
    LockGuard lock(mutex_);
    auto next = bindings_;
    if (roles & COSMIC_PUBLISH)
      next.push_back(ChannelBinding{binding_id(index), spec, hop_role_of(COSMIC_PUBLISH), std::nullopt});
    if (roles & COSMIC_SUBSCRIBE)
      next.push_back(ChannelBinding{binding_id(index), spec, hop_role_of(COSMIC_SUBSCRIBE), std::nullopt});
    const Status s = adapter_->configure(next);
    if (!s.ok) {
      error = s.error;
      return COSMIC_E_TRANSPORT;
    }
    bindings_ = std::move(next);
    return COSMIC_OK;
  }

  int send(std::size_t index, const EventHeader& header, std::span<const std::uint8_t> payload,
           std::string& error) override {
    // The component's events carry its own origin on DDS and LCM alike, so every gateway that
    // forwards them gives them the same identity (origin, sequence) and duplicates stay visible.
    EventHeader stamped = header;
    stamped.origin = self_.id;
    switch (adapter_->send(OutboundEvent{binding_id(index), stamped, payload})) {
      case SendStatus::sent:
        return COSMIC_OK;
      case SendStatus::queue_full:
        return COSMIC_E_AGAIN;
      case SendStatus::failed:
        break;
    }
    error = "the " + std::string(to_string(segment_.type)) + " transport refused the event: " + log_.last();
    return COSMIC_E_TRANSPORT;
  }

  // DDS: the matches of the component's writer or reader, without its own; LCM has no discovery.
  std::optional<std::size_t> matched(std::size_t index, int role) const override {
    if (!dds_) return std::nullopt;
    const ChannelId id = binding_id(index);
    int roles = 0;
    {
      LockGuard lock(mutex_);
      for (const ChannelBinding& b : bindings_) {
        if (b.id == id) roles |= b.role == HopRole::subscriber ? COSMIC_PUBLISH : COSMIC_SUBSCRIBE;
      }
    }
    if (!(roles & role)) return 0;
    const std::size_t all = dds_->matched_endpoints(id, hop_role_of(role));
    const std::size_t own = roles == (COSMIC_PUBLISH | COSMIC_SUBSCRIBE) ? kOwnMatchesWithBothRoles : 0;
    return all > own ? all - own : 0;
  }

 private:
  void on_event(const InboundEvent& event) override {
    // Only channels announced to subscribe are bound for receiving.
    if (event.channel != kNoChannel) delivery_->deliver(index_of(event.channel), event.header, event.payload);
  }
  void on_problem(ChannelId, InboundProblem) override {}

  SegmentSpec segment_;
  GatewayIdentity self_;
  QuietLogger log_;
  Delivery* delivery_ = nullptr;
  std::unique_ptr<SegmentAdapter> adapter_;
  DdsSegmentAdapter* dds_ = nullptr;  // adapter_ on a DDS segment, for its per-role matches
  mutable Mutex mutex_;
  std::vector<ChannelBinding> bindings_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace

std::unique_ptr<Transport> make_ip_transport(const SegmentSpec& segment) {
  return std::make_unique<IpTransport>(segment);
}

}  // namespace cosmic::client_detail
