// DDS and LCM for a component: the gateway's adapters with the roles mirrored, so topics, envelope
// and QoS are exactly what cosmicd expects (one implementation of the mapping, not two).
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
    adapter_ = segment_.type == SegmentType::dds ? std::unique_ptr<SegmentAdapter>(make_dds_adapter(segment_, self_, log_))
                                                  : make_lcm_adapter(segment_, self_, log_);
    const Status s = adapter_->start(*this);
    if (!s.ok) error = s.error;
    return s.ok ? COSMIC_OK : COSMIC_E_TRANSPORT;
  }

  int announce(std::size_t index, const ChannelSpec& spec, int roles, int, std::string& error) override {
    LockGuard lock(mutex_);
    auto next = bindings_;
    if (roles & COSMIC_PUBLISH) next.push_back(ChannelBinding{binding_id(index), spec, HopRole::subscriber, std::nullopt});
    if (roles & COSMIC_SUBSCRIBE) next.push_back(ChannelBinding{binding_id(index), spec, HopRole::publisher, std::nullopt});
    const Status s = adapter_->configure(next);
    if (!s.ok) {
      error = s.error;
      return COSMIC_E_TRANSPORT;
    }
    bindings_ = std::move(next);
    return COSMIC_OK;
  }

  int send(std::size_t index, const EventHeader& header, std::span<const std::uint8_t> payload, std::string& error) override {
    // The component's events carry its own origin on DDS and LCM alike, so every gateway that
    // forwards them gives them the same identity (origin, sequence) and duplicates stay visible.
    EventHeader stamped = header;
    stamped.origin = self_.id;
    switch (adapter_->send(OutboundEvent{binding_id(index), stamped, payload})) {
      case SendStatus::sent: return COSMIC_OK;
      case SendStatus::queue_full: return COSMIC_E_AGAIN;
      case SendStatus::failed: break;
    }
    error = "the " + std::string(to_string(segment_.type)) + " transport refused the event: " + log_.last();
    return COSMIC_E_TRANSPORT;
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
  Mutex mutex_;
  std::vector<ChannelBinding> bindings_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace

std::unique_ptr<Transport> make_ip_transport(const SegmentSpec& segment) { return std::make_unique<IpTransport>(segment); }

}  // namespace cosmic::client_detail
