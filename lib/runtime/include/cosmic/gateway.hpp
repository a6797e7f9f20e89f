// The running gateway: the knowledge base, one adapter per segment, the router and its thread,
// and the binding operations (start, bind, unbind, reload) that keep the three consistent.
//
// Threads: every public method is called by the one control thread; the router runs on its own
// thread started by start(); adapters run their own receive threads.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/knowledge_base.hpp"
#include "cosmic/log.hpp"
#include "cosmic/router.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

using AdapterFactory =
    std::function<std::unique_ptr<SegmentAdapter>(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log)>;

struct BindResult {
  bool applied = false;                 // false: nothing changed
  std::vector<ChannelReport> channels;  // verdict of each requested channel
  std::string error;                    // why nothing changed, when not a rejection
};

struct SegmentInfo {
  SegmentSpec spec;
  HealthReport health;
  AdapterStatistics adapter;
  double utilization = 0;
  std::size_t channels = 0;
  std::uint64_t unrouted = 0;
};

class Gateway {
 public:
  static constexpr std::size_t kMaxSegments = 64;

  Gateway(AdapterFactory factory, Logger& log, std::uint64_t gateway_id);
  ~Gateway();
  Gateway(const Gateway&) = delete;
  Gateway& operator=(const Gateway&) = delete;

  // Creates and starts the adapters, binds every channel through admission (rejected ones are
  // reported and left unbound), starts the router thread. Fails only when an adapter cannot be
  // created; segments that start but are unhealthy are reported by health.
  BindResult start(const Config& config);
  // Binds the channels together, or none of them when any is rejected.
  BindResult bind(const std::vector<ChannelSpec>& channels);
  // False when no such channel is bound.
  bool unbind(const std::string& name);
  // Validated configuration in, running one swapped: unchanged segments and channels keep
  // flowing. On failure the running configuration stays untouched.
  BindResult reload(const Config& config);
  void stop();

  // Reads adapter health into the knowledge base (call periodically).
  void refresh_health();

  const GatewayIdentity& identity() const { return identity_; }
  const Config& config() const { return config_; }
  const KnowledgeBase& knowledge_base() const { return *kb_; }
  AdmissionReport admission() const { return kb_->report(); }
  std::vector<SegmentInfo> segments() const;
  std::vector<ChannelStatsSnapshot> channel_stats() const { return router_->snapshot(); }
  const Router& router() const { return *router_; }
  bool all_segments_up() const;
  // Discovered remote endpoints of a bound channel on a segment (see SegmentAdapter).
  std::optional<std::size_t> matched_peers(const std::string& segment, const std::string& channel) const;

 private:
  struct SegmentSlot {
    std::size_t index = 0;
    SegmentSpec spec;
    std::unique_ptr<SegmentAdapter> adapter;
  };

  std::optional<std::string> configure_adapters();
  void apply_routes();
  ChannelId id_for(const ChannelSpec& spec);
  // Lowest slot index used neither by a running segment nor by one in `also_taken`.
  std::size_t free_slot(const std::set<std::size_t>& also_taken = {}) const;
  static std::unique_ptr<KnowledgeBase> knowledge_base_for(const Config& config);

  AdapterFactory factory_;
  Logger& log_;
  GatewayIdentity identity_;
  Config config_;
  std::unique_ptr<KnowledgeBase> kb_;
  std::unique_ptr<Router> router_;
  std::thread router_thread_;
  std::map<std::string, SegmentSlot> slots_;  // by segment name
  std::map<std::string, std::pair<ChannelSpec, ChannelId>> channel_ids_;
  ChannelId next_channel_id_ = 1;
};

}  // namespace cosmic
