#include "cosmic/admission.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "cosmic/can_timing.hpp"
#include "cosmic/can_wire.hpp"

namespace cosmic {
namespace {

// A channel without a declared rate still occupies the bus (blocking), but reserves nothing.
constexpr Nanos kUnratedPeriod{3'600'000'000'000};
// Jitter standing in for an unbounded upstream latency: makes the analysis report unbounded.
constexpr Nanos kUnboundedJitter{100'000'000'000};
constexpr int kMaxJitterIterations = 32;
// Largest NRT event the gateway accepts on an IP segment.
constexpr std::uint64_t kMaxIpEventBytes = 1 << 20;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct HopRef {
  std::size_t channel;
  std::size_t hop;
};

double seconds_or_infinity(const std::optional<Nanos>& value) { return value ? to_seconds(*value) : kInfinity; }


Nanos deadline_key(const ChannelSpec& channel) {
  if (channel.reaction_time) return *channel.reaction_time;
  if (channel.period) return *channel.period;
  return kUnratedPeriod;
}

bool segment_retransmits(const SegmentSpec& segment) {
  if (segment.type == SegmentType::can) return true;  // CAN retransmits within the fault hypothesis
  if (segment.type == SegmentType::lcm) return false;
  return segment.reliability == Reliability::reliable;
}

bool segment_realtime(const SegmentSpec& segment) {
  return segment.type == SegmentType::can || segment.realtime;
}

class Evaluator {
 public:
  Evaluator(const GatewaySpec& gateway, std::span<const SegmentSpec> segments, std::span<const ChannelSpec> channels,
            const EtagMap& etags)
      : gateway_(gateway), segments_(segments), channels_(channels), etags_(etags) {}

  Evaluation run() {
    create_hops();
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      if (segments_[s].type == SegmentType::can) plan_can_segment(s);
    }
    iterate_latencies();
    compute_loads();
    for (std::size_t c = 0; c < channels_.size(); ++c) judge_channel(c);
    return Evaluation{std::move(reports_), std::move(loads_)};
  }

 private:
  const SegmentSpec& segment_named(const std::string& name) const {
    return *std::find_if(segments_.begin(), segments_.end(), [&](const auto& s) { return s.name == name; });
  }

  std::size_t segment_index(const std::string& name) const {
    return static_cast<std::size_t>(
        std::find_if(segments_.begin(), segments_.end(), [&](const auto& s) { return s.name == name; }) -
        segments_.begin());
  }

  HopReport& hop(const HopRef& ref) { return reports_[ref.channel].hops[ref.hop]; }

  void create_hops() {
    hops_by_segment_.assign(segments_.size(), {});
    for (std::size_t c = 0; c < channels_.size(); ++c) {
      const ChannelSpec& channel = channels_[c];
      ChannelReport report;
      report.name = channel.name;
      report.cls = channel.cls;
      auto add = [&](const std::string& segment, HopRole role) {
        hops_by_segment_[segment_index(segment)].push_back(HopRef{c, report.hops.size()});
        report.hops.push_back(HopReport{segment, role, std::nullopt, std::nullopt, {}});
      };
      for (const auto& p : channel.publishers) add(p, HopRole::publisher);
      for (const auto& s : channel.subscribers) add(s, HopRole::subscriber);
      reports_.push_back(std::move(report));
    }
  }

  // Priorities (band, then deadline-monotonic), identifiers and frame times of one CAN bus.
  void plan_can_segment(std::size_t s) {
    const CanSegmentProperties& bus = segments_[s].can;
    std::vector<HopRef> ordered = hops_by_segment_[s];
    std::sort(ordered.begin(), ordered.end(), [&](const HopRef& a, const HopRef& b) {
      const ChannelSpec& ca = channels_[a.channel];
      const ChannelSpec& cb = channels_[b.channel];
      return std::tuple(static_cast<int>(ca.cls), deadline_key(ca), ca.subject) <
             std::tuple(static_cast<int>(cb.cls), deadline_key(cb), cb.subject);
    });
    const std::uint32_t capacity = max_frame_payload(bus);
    for (std::size_t i = 0; i < ordered.size(); ++i) {
      const ChannelSpec& channel = channels_[ordered[i].channel];
      std::size_t rank = 0;
      std::size_t count = 0;
      for (std::size_t j = 0; j < ordered.size(); ++j) {
        if (channels_[ordered[j].channel].cls != channel.cls) continue;
        if (j < i) ++rank;
        ++count;
      }
      CanHopPlan plan;
      plan.priority = band_priority(channel.cls, rank, count);
      const auto etag = etags_.find(channel.name);
      plan.etag = etag == etags_.end() ? 0 : etag->second;
      plan.can_id = encode_can_id(CanIdentifier{plan.priority, gateway_.can_node_id, plan.etag});
      const bool fits = channel.payload <= capacity;
      plan.frames_per_event = fits ? 1 : fragments_needed(channel.payload, capacity);
      const auto data_bytes = static_cast<std::uint32_t>(fits ? channel.payload : capacity);
      plan.frame_bytes = bus.fd ? fd_padded_length(data_bytes) : data_bytes;
      plan.transmission = frame_time(bus, plan.frame_bytes, CanIdFormat::extended29);
      hop(ordered[i]).can = plan;
    }
  }

  Nanos stream_period(const ChannelSpec& channel, const CanHopPlan& plan) const {
    const Nanos period = channel.period.value_or(kUnratedPeriod);
    return std::max(Nanos(1), period / plan.frames_per_event);
  }

  void analyse_can_segment(std::size_t s) {
    std::vector<CanStream> streams;
    for (const HopRef& ref : hops_by_segment_[s]) {
      const CanHopPlan& plan = *hop(ref).can;
      streams.push_back(CanStream{plan.can_id, plan.transmission, stream_period(channels_[ref.channel], plan), plan.jitter});
    }
    const auto results = response_times(streams, bus_timing(segments_[s].can));
    for (std::size_t i = 0; i < results.size(); ++i) {
      HopReport& h = hop(hops_by_segment_[s][i]);
      h.can->response_time = results[i];
      h.latency = results[i];
    }
  }

  // Worst latency of the channel's publisher hops.
  std::optional<Nanos> publisher_latency(std::size_t c) const {
    Nanos worst{0};
    for (const HopReport& h : reports_[c].hops) {
      if (h.role != HopRole::publisher) continue;
      if (!h.latency) return std::nullopt;
      worst = std::max(worst, *h.latency);
    }
    return worst;
  }

  // Subscriber-side CAN streams are released by the gateway up to (upstream latency + residence)
  // after the event occurred: that is their jitter. Upstream CAN latencies depend on jitters in
  // turn, so iterate to the fixed point (holistic analysis).
  void iterate_latencies() {
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      if (segments_[s].type == SegmentType::can) continue;
      for (const HopRef& ref : hops_by_segment_[s]) hop(ref).latency = segments_[s].latency_bound;
    }
    for (int iteration = 0; iteration < kMaxJitterIterations; ++iteration) {
      for (std::size_t s = 0; s < segments_.size(); ++s) {
        if (segments_[s].type == SegmentType::can) analyse_can_segment(s);
      }
      if (!update_jitters()) return;
    }
    // No fixed point: the jitters keep growing, so the subscriber-side CAN hops are unbounded.
    for (auto& report : reports_) {
      for (auto& h : report.hops) {
        if (h.can && h.role == HopRole::subscriber) h.latency = h.can->response_time = std::nullopt;
      }
    }
  }

  bool update_jitters() {
    bool changed = false;
    for (std::size_t c = 0; c < reports_.size(); ++c) {
      const auto upstream = publisher_latency(c);
      const Nanos jitter = upstream ? std::min(kUnboundedJitter, *upstream + gateway_.residence_bound) : kUnboundedJitter;
      for (HopReport& h : reports_[c].hops) {
        if (!h.can || h.role != HopRole::subscriber || h.can->jitter == jitter) continue;
        h.can->jitter = jitter;
        changed = true;
      }
    }
    return changed;
  }

  double hop_load(const SegmentSpec& segment, const ChannelSpec& channel, const HopReport& h) const {
    if (!channel.period) return 0.0;
    const double period_s = to_seconds(*channel.period);
    if (segment.type == SegmentType::can) {
      return to_seconds(h.can->transmission) * h.can->frames_per_event / period_s;
    }
    const double bits = static_cast<double>(channel.payload + kIpOverheadBytes) * 8.0;
    return bits / period_s / static_cast<double>(segment.bandwidth.bits_per_second);
  }

  void compute_loads() {
    for (std::size_t s = 0; s < segments_.size(); ++s) {
      double load = 0.0;
      for (const HopRef& ref : hops_by_segment_[s]) load += hop_load(segments_[s], channels_[ref.channel], hop(ref));
      loads_.push_back(SegmentLoad{segments_[s].name, segments_[s].type, load, segments_[s].max_utilization});
    }
  }

  void add_frame_fit(const ChannelSpec& channel, const SegmentSpec& segment, HopReport& h) {
    double limit = 0;
    if (segment.type == SegmentType::can) {
      const std::uint32_t capacity = max_frame_payload(segment.can);
      limit = channel.cls == ChannelClass::nrt && channel.payload > capacity
                  ? static_cast<double>(kMaxFragments * (capacity - kFragmentHeaderBytes))
                  : capacity;
    } else {
      limit = channel.cls == ChannelClass::nrt ? static_cast<double>(kMaxIpEventBytes)
                                               : static_cast<double>(segment.max_message_size - kIpOverheadBytes);
    }
    const auto value = static_cast<double>(channel.payload);
    h.checks.push_back(Check{"frame_fit", value, limit, "B", "<=", value <= limit});
  }

  void add_hop_checks(std::size_t c, HopReport& h) {
    const ChannelSpec& channel = channels_[c];
    const SegmentSpec& segment = segment_named(h.segment);
    add_frame_fit(channel, segment, h);
    if (channel.period) {
      const SegmentLoad& load = loads_[segment_index(h.segment)];
      h.checks.push_back(Check{"utilization", load.utilization, load.max_utilization, "ratio", "<=",
                               load.utilization <= load.max_utilization + 1e-12});
    }
    if (channel.cls != ChannelClass::nrt && channel.reaction_time) {
      const double value = seconds_or_infinity(h.latency);
      const double limit = to_seconds(*channel.reaction_time);
      const char* name = segment.type == SegmentType::can ? "response_time" : "latency";
      h.checks.push_back(Check{name, value, limit, "s", "<=", value <= limit});
    }
    const double min_omission = segment_retransmits(segment) ? 0.0 : 1.0;
    h.checks.push_back(Check{"omission", static_cast<double>(channel.omission_degree), min_omission, "events", ">=",
                             channel.omission_degree >= min_omission});
    if (channel.cls == ChannelClass::hrt) {
      const double capable = segment_realtime(segment) ? 1.0 : 0.0;
      h.checks.push_back(Check{"realtime", capable, 1.0, "bool", ">=", capable >= 1.0});
    }
  }

  std::optional<Nanos> end_to_end_latency(std::size_t c) const {
    Nanos worst_publisher{0};
    Nanos worst_subscriber{0};
    for (const HopReport& h : reports_[c].hops) {
      if (!h.latency) return std::nullopt;
      Nanos& worst = h.role == HopRole::publisher ? worst_publisher : worst_subscriber;
      // A subscriber-side CAN response time already contains its release jitter (upstream
      // latency + residence): count only what the hop adds after the gateway releases the frame.
      const Nanos added = h.can && h.role == HopRole::subscriber ? *h.latency - h.can->jitter : *h.latency;
      worst = std::max(worst, added);
    }
    return worst_publisher + gateway_.residence_bound + worst_subscriber;
  }

  static std::string failure_text(const Check& check, const HopReport& h, const SegmentSpec& segment) {
    const std::string on = " on " + h.segment;
    if (check.check == "frame_fit") {
      return "payload " + std::to_string(static_cast<long long>(check.value)) + " B > " +
             (segment.type == SegmentType::can ? "frame " : "message ") +
             std::to_string(static_cast<long long>(check.limit)) + " B" + on;
    }
    if (check.check == "utilization") {
      return "utilization " + format_percent(check.value) + " > max_utilization " + format_percent(check.limit) + on;
    }
    if (check.check == "response_time") {
      return "R = " + format_seconds(check.value) + " > reaction_time " + format_seconds(check.limit) + on;
    }
    if (check.check == "latency") {
      return "latency_bound " + format_seconds(check.value) + " > reaction_time " + format_seconds(check.limit) + on;
    }
    if (check.check == "omission") {
      return "omission_degree " + std::to_string(static_cast<long long>(check.value)) + " < " +
             std::to_string(static_cast<long long>(check.limit)) + on + ", which does not retransmit";
    }
    return "hrt" + on + ", which declares no real-time guarantee (realtime: false)";
  }

  // How a failing criterion affects the verdict of a channel of this class.
  static Verdict consequence(const std::string& check, ChannelClass cls) {
    if (cls == ChannelClass::hrt || check == "frame_fit") return Verdict::rejected;
    return Verdict::degraded;
  }

  void judge_channel(std::size_t c) {
    const ChannelSpec& channel = channels_[c];
    ChannelReport& report = reports_[c];
    auto worsen = [&](Verdict v, std::string reason) {
      report.verdict = std::max(report.verdict, v);
      report.reasons.push_back(std::move(reason));
    };
    for (HopReport& h : report.hops) {
      add_hop_checks(c, h);
      for (const Check& check : h.checks) {
        if (!check.ok) worsen(consequence(check.check, channel.cls), failure_text(check, h, segment_named(h.segment)));
      }
    }
    EndToEnd& e2e = report.end_to_end;
    e2e.latency = end_to_end_latency(c);
    e2e.reaction_time = channel.reaction_time;
    e2e.temp_validity = channel.temp_validity;
    const double latency = seconds_or_infinity(e2e.latency);
    if (channel.cls != ChannelClass::nrt && channel.reaction_time && latency > to_seconds(*channel.reaction_time)) {
      e2e.latency_ok = false;
      worsen(consequence("latency", channel.cls), "end-to-end latency " + format_seconds(latency) +
                                                      " > reaction_time " + format_duration(*channel.reaction_time));
    }
    if (channel.temp_validity && latency >= to_seconds(*channel.temp_validity)) {
      e2e.validity_ok = false;
      worsen(consequence("validity", channel.cls), "end-to-end latency " + format_seconds(latency) +
                                                       " >= temp_validity " + format_duration(*channel.temp_validity) +
                                                       ": events would arrive stale");
    }
  }

  const GatewaySpec& gateway_;
  std::span<const SegmentSpec> segments_;
  std::span<const ChannelSpec> channels_;
  const EtagMap& etags_;
  std::vector<std::vector<HopRef>> hops_by_segment_;
  std::vector<ChannelReport> reports_;
  std::vector<SegmentLoad> loads_;
};

}  // namespace

const char* to_string(Verdict value) {
  switch (value) {
    case Verdict::bound: return "bound";
    case Verdict::degraded: return "degraded";
    case Verdict::rejected: return "rejected";
  }
  return "?";
}

const char* to_string(HopRole value) { return value == HopRole::publisher ? "publisher" : "subscriber"; }

bool AdmissionReport::any_rejected() const {
  return std::any_of(channels.begin(), channels.end(), [](const auto& c) { return c.verdict == Verdict::rejected; });
}

const ChannelReport* AdmissionReport::find(const std::string& name) const {
  const auto it = std::find_if(channels.begin(), channels.end(), [&](const auto& c) { return c.name == name; });
  return it == channels.end() ? nullptr : &*it;
}

Evaluation evaluate(const GatewaySpec& gateway, std::span<const SegmentSpec> segments,
                    std::span<const ChannelSpec> channels, const EtagMap& etags) {
  return Evaluator(gateway, segments, channels, etags).run();
}

}  // namespace cosmic
