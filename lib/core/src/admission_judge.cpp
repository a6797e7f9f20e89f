#include "admission_judge.hpp"

#include <cstdio>
#include <limits>

#include "cosmic/can_background.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_timing.hpp"

namespace cosmic::admission_detail {
namespace {

// Largest NRT event the gateway accepts on an IP segment.
constexpr std::uint64_t kMaxIpEventBytes = 1 << 20;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double seconds_or_infinity(const std::optional<Nanos>& value) { return value ? to_seconds(*value) : kInfinity; }

bool segment_retransmits(const SegmentSpec& segment) {
  if (segment.type == SegmentType::can) return true;  // CAN retransmits within the fault hypothesis
  if (segment.type == SegmentType::lcm) return false;
  return segment.reliability == Reliability::reliable;
}

bool segment_realtime(const SegmentSpec& segment) { return segment.type == SegmentType::can || segment.realtime; }

void add_frame_fit(const ChannelSpec& channel, const SegmentSpec& segment, HopReport& h) {
  double limit = 0;
  if (segment.type == SegmentType::can) {
    const std::uint32_t capacity = max_frame_payload(segment.can);
    // A native frame is the event: no fragmentation, whatever the class.
    const bool fragmentable =
        channel.cls == ChannelClass::nrt && !channel.native_can(segment.name) && !channel.secoc_on(segment.name);
    limit = fragmentable && channel.payload_on(segment.name) > capacity
                ? static_cast<double>(kMaxFragments * (capacity - kFragmentHeaderBytes))
                : capacity;
  } else {
    limit = channel.cls == ChannelClass::nrt ? static_cast<double>(kMaxIpEventBytes)
                                             : static_cast<double>(segment.max_message_size - kIpOverheadBytes);
  }
  // What authentication adds takes room of the message like the payload.
  const auto value = static_cast<double>(channel.payload_on(segment.name) + (h.security ? h.security->bytes : 0));
  h.checks.push_back(Check{"frame_fit", value, limit, "B", "<=", value <= limit});
}

// "; background frames delaying it most: EngineData (0x0C0) 2.1 ms, ..." or nothing.
std::string background_text(const HopReport& h) {
  std::string text;
  for (const BackgroundDelay& d : h.background) {
    text += (text.empty() ? "; background frames delaying it most: " : ", ") + d.name + " (" +
            can_id_text(d.can_id, d.extended) + ") " + format_seconds(to_seconds(d.delay)) +
            (d.blocking ? " blocking" : "");
  }
  return text;
}

// A typed channel's hop (null: untyped): can its representation carry the type, and all of each
// field's range?
void add_representation_checks(const HopPayload* hop, HopReport& h) {
  if (hop == nullptr) return;
  h.representation = hop->form;
  const bool fits = hop->unfit.empty();
  h.checks.push_back(Check{"representation", fits ? 1.0 : 0.0, 1.0, "bool", ">=", fits});
  if (fits && !hop->narrowed.empty()) h.checks.push_back(Check{"range", 0.0, 1.0, "bool", ">=", false});
}

// An authenticated hop: what it adds, and whether the channel's messages can carry it there (a raw
// LCM message has no room for the trailer: nothing in it tells the tag from the contents).
void add_security_checks(const ChannelSpec& channel, const SegmentSpec& segment, HopReport& h) {
  h.security = hop_security(segment, channel);
  // DDS Security protects every sample of the participant, native topics too: nothing to check.
  if (!h.security || segment.type == SegmentType::dds) return;
  // SecOC: this project's layout and native identifiers; FAMOUSO's layout has no room for it.
  const bool carried = segment.type == SegmentType::can
                           ? segment.can.profile == CanProfile::cosmic || channel.native_can(segment.name)
                           : channel.native_on(segment.name) == nullptr && channel.lcm_encoding != LcmEncoding::raw;
  h.checks.push_back(Check{"authentication", carried ? 1.0 : 0.0, 1.0, "bool", ">=", carried});
}

// A replay segment is a publisher like any other (issue 37): the recording must hold the channel's
// events, and play them no closer together than the channel's minimum inter-arrival time allows.
void add_replay_checks(const ChannelSpec& channel, const SegmentSpec& segment, HopReport& h) {
  if (segment.type != SegmentType::replay || h.role != HopRole::publisher) return;
  const ReplayStream* stream = segment.replay.stream(channel.name);
  const double events = stream ? static_cast<double>(stream->events) : 0.0;
  h.checks.push_back(Check{"replay_events", events, 1.0, "events", ">=", events >= 1.0});
  if (!stream || !channel.period) return;
  // A loop of one event has no spacing of its own: it would be played back to back.
  const double spacing =
      stream->events < 2 ? (segment.replay.loop ? 0.0 : -1.0) : to_seconds(stream->tightest) / segment.replay.speed;
  if (spacing < 0) return;
  const double limit = to_seconds(*channel.period);
  h.checks.push_back(Check{"replay_rate", spacing, limit, "s", ">=", spacing >= limit});
}

std::string failure_text(const Check& check, const HopReport& h, const SegmentSpec& segment,
                         const ChannelSpec& channel) {
  const std::string on = " on " + h.segment;
  if (check.check == "replay_events") {
    return "the recording " + segment.replay.file + " replayed" + on + " holds no event of this channel" +
           (segment.replay.channels.empty() ? "" : " among the channels the segment selects");
  }
  if (check.check == "replay_rate") {
    return "the replay" + on + " sends events as close as " + format_seconds(check.value) +
           " apart (tightest recorded spacing at speed " + shortest_number_text(segment.replay.speed) +
           ") < the channel's minimum inter-arrival " + format_seconds(check.limit) +
           ": slow the replay (speed) or give the channel a period that covers the recording";
  }
  if (check.check == "authentication" && segment.type == SegmentType::can) {
    return "SecOC" + on +
           " needs this project's frame layout or a native identifier: FAMOUSO's frames (profile: famouso) cannot "
           "carry it";
  }
  if (check.check == "authentication") {
    return "raw LCM messages" + on +
           " cannot carry the authentication trailer the segment requires (auth): use encoding: envelope";
  }
  if (check.check == "representation") {
    return h.segment + " cannot carry the channel's type: " + channel.hop_on(h.segment)->unfit;
  }
  if (check.check == "range") {
    return h.segment + " (" + h.representation + ") saturates values: " + channel.hop_on(h.segment)->narrowed;
  }
  if (check.check == "frame_fit") {
    const bool native = h.can && h.can->native;
    // What security adds is named apart: "payload 6 B + SecOC 4 B > frame 8 B".
    const std::uint32_t added = h.security ? h.security->bytes : 0;
    const std::string what = added == 0 ? std::to_string(static_cast<long long>(check.value)) + " B"
                                        : std::to_string(static_cast<long long>(check.value) - added) + " B + " +
                                              (segment.type == SegmentType::can   ? "SecOC "
                                               : segment.type == SegmentType::dds ? "DDS Security "
                                                                                  : "trailer ") +
                                              std::to_string(added) + " B";
    return "payload " + what + " > " +
           (native                             ? "native frame "
            : segment.type == SegmentType::can ? "frame "
                                               : "message ") +
           std::to_string(static_cast<long long>(check.limit)) + " B" + on;
  }
  if (check.check == "utilization") {
    const bool background = segment.type == SegmentType::can && !segment.can.background.empty();
    const bool peers = segment.peer_load > 0;
    return "utilization " + format_percent(check.value) +
           (background ? " (background " + format_percent(background_utilization(segment.can)) + ")" : std::string()) +
           (peers ? " (other gateways " + format_percent(segment.peer_load) + ")" : std::string()) +
           " > max_utilization " + format_percent(check.limit) + on;
  }
  if (check.check == "response_time") {
    const bool costed = h.security && h.security->time;
    return "R " + std::string(costed ? "+ SecOC " : "") + "= " + format_seconds(check.value) + " > reaction_time " +
           format_seconds(check.limit) + on + background_text(h);
  }
  if (check.check == "latency") {
    const bool costed = h.security && h.security->time;
    return (costed ? "latency_bound + authentication " : "latency_bound ") + format_seconds(check.value) +
           " > reaction_time " + format_seconds(check.limit) + on;
  }
  if (check.check == "omission") {
    return "omission_degree " + std::to_string(static_cast<long long>(check.value)) + " < " +
           std::to_string(static_cast<long long>(check.limit)) + on + ", which does not retransmit";
  }
  return "hrt" + on + ", which declares no real-time guarantee (realtime: false)";
}

// An FMU publishes its output channels once per communication step (docs/fmu.md, "Timing and
// admission"): no faster than the channel's period (rate policing would drop what comes sooner) and
// often enough that subscribers never hold a value older than its temp_validity between two steps.
// The checks go on the FMU's publisher hop; `worsen(verdict, reason)` takes each failure.
template <typename Worsen>
void add_fmu_checks(const ChannelSpec& channel, ChannelReport& report, Worsen&& worsen) {
  for (const FmuPublisher& fmu : channel.fmu_publishers) {
    const auto hop = std::find_if(report.hops.begin(), report.hops.end(), [&](const HopReport& h) {
      return h.role == HopRole::publisher && h.segment == fmu.segment;
    });
    if (hop == report.hops.end()) continue;  // the configuration lists the FMU's segment among the publishers
    const std::string publishes = "fmu " + fmu.fmu + " publishes every " + format_duration(fmu.step) + " (its step)";
    if (channel.period) {
      const bool ok = fmu.step >= *channel.period;
      hop->checks.push_back(Check{"fmu_rate", to_seconds(fmu.step), to_seconds(*channel.period), "s", ">=", ok});
      if (!ok) {
        worsen(consequence_of("fmu_rate", channel.cls), publishes + ", faster than the period " +
                                                            format_duration(*channel.period) +
                                                            ": rate policing would drop its events");
      }
    }
    if (channel.temp_validity) {
      const bool ok = fmu.step <= *channel.temp_validity;
      hop->checks.push_back(
          Check{"fmu_validity", to_seconds(fmu.step), to_seconds(*channel.temp_validity), "s", "<=", ok});
      if (!ok) {
        worsen(consequence_of("fmu_validity", channel.cls),
               publishes + ", longer than temp_validity " + format_duration(*channel.temp_validity) +
                   ": between two steps subscribers hold a value older than its validity");
      }
    }
  }
}

}  // namespace

void Judge::judge(const ChannelSpec& channel, ChannelReport& report) const {
  auto worsen = [&](Verdict v, std::string reason) {
    report.verdict = std::max(report.verdict, v);
    report.reasons.push_back(std::move(reason));
  };
  for (HopReport& h : report.hops) {
    const SegmentSpec& segment = segment_named(segments_, h.segment);
    add_hop_checks(channel, segment, h);
    for (const Check& check : h.checks) {
      if (!check.ok) worsen(consequence_of(check.check, channel.cls), failure_text(check, h, segment, channel));
    }
  }
  add_fmu_checks(channel, report, worsen);
  EndToEnd& e2e = report.end_to_end;
  e2e.latency = end_to_end_latency(report);
  e2e.reaction_time = channel.reaction_time;
  e2e.temp_validity = channel.temp_validity;
  const double latency = seconds_or_infinity(e2e.latency);
  if (channel.cls != ChannelClass::nrt && channel.reaction_time && latency > to_seconds(*channel.reaction_time)) {
    e2e.latency_ok = false;
    worsen(consequence_of("latency", channel.cls), "end-to-end latency " + format_seconds(latency) +
                                                       " > reaction_time " + format_duration(*channel.reaction_time));
  }
  if (channel.temp_validity && latency >= to_seconds(*channel.temp_validity)) {
    e2e.validity_ok = false;
    worsen(consequence_of("validity", channel.cls), "end-to-end latency " + format_seconds(latency) +
                                                        " >= temp_validity " + format_duration(*channel.temp_validity) +
                                                        ": events would arrive stale");
  }
}

void Judge::add_hop_checks(const ChannelSpec& channel, const SegmentSpec& segment, HopReport& h) const {
  const HopPayload* hop = channel.type ? channel.hop_on(segment.name) : nullptr;
  add_representation_checks(hop, h);
  add_security_checks(channel, segment, h);
  add_replay_checks(channel, segment, h);
  // A hop that cannot carry the type has no message size: its frame is not judged.
  if (hop == nullptr || hop->unfit.empty()) add_frame_fit(channel, segment, h);
  if (channel.period) {
    const double load = loads_[static_cast<std::size_t>(&segment - segments_.data())];
    h.checks.push_back(
        Check{"utilization", load, segment.max_utilization, "ratio", "<=", load <= segment.max_utilization + 1e-12});
  }
  if (channel.cls != ChannelClass::nrt && channel.reaction_time) {
    const double value = seconds_or_infinity(h.latency);
    const double limit = to_seconds(*channel.reaction_time);
    const char* name = segment.type == SegmentType::can ? "response_time" : "latency";
    h.checks.push_back(Check{name, value, limit, "s", "<=", value <= limit});
  }
  const double min_omission = segment_retransmits(segment) ? 0.0 : 1.0;
  h.checks.push_back(Check{"omission", static_cast<double>(channel.omission_degree), min_omission, "events",
                           ">=", channel.omission_degree >= min_omission});
  if (channel.cls == ChannelClass::hrt) {
    const double capable = segment_realtime(segment) ? 1.0 : 0.0;
    h.checks.push_back(Check{"realtime", capable, 1.0, "bool", ">=", capable >= 1.0});
  }
}

std::optional<Nanos> Judge::end_to_end_latency(const ChannelReport& report) const {
  Nanos worst_publisher{0};
  Nanos worst_subscriber{0};
  for (const HopReport& h : report.hops) {
    if (!h.latency) return std::nullopt;
    Nanos& worst = h.role == HopRole::publisher ? worst_publisher : worst_subscriber;
    // A subscriber-side CAN response time already contains its release jitter (upstream
    // latency + residence): count only what the hop adds after the gateway releases the frame.
    // SecOC's protection is in that jitter but happens after the gateway's residence: it counts.
    const Nanos protect = h.can && h.security && h.security->time ? *h.security->time : Nanos(0);
    const Nanos added = h.can && h.role == HopRole::subscriber ? *h.latency - (h.can->jitter - protect) : *h.latency;
    worst = std::max(worst, added);
  }
  return worst_publisher + gateway_.residence_bound + worst_subscriber;
}

}  // namespace cosmic::admission_detail
