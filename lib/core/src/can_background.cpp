#include "cosmic/can_background.hpp"

#include <algorithm>
#include <cstdio>

namespace cosmic {
CanIdFormat id_format(const CanBackgroundFrame& frame) {
  return frame.extended ? CanIdFormat::extended29 : CanIdFormat::standard11;
}

std::string can_id_text(std::uint32_t id, bool extended) {
  char text[16];
  std::snprintf(text, sizeof text, extended ? "0x%08X" : "0x%03X", id);
  return text;
}

std::vector<CanStream> background_streams(const CanSegmentProperties& bus) {
  std::vector<CanStream> streams;
  streams.reserve(bus.background.size());
  for (const CanBackgroundFrame& f : bus.background) {
    const CanIdFormat format = id_format(f);
    streams.push_back(
        CanStream{arbitration_key(f.can_id, format), frame_time(bus, f.length, format), f.period, f.jitter});
  }
  return streams;
}

double background_utilization(const CanSegmentProperties& bus) { return utilization(background_streams(bus)); }

std::vector<BackgroundDelay> dominant_background(const CanSegmentProperties& bus, std::span<const CanStream> streams,
                                                 const CanStream& stream, std::optional<Nanos> response, Nanos horizon,
                                                 std::size_t top) {
  const std::int64_t tau = bit_time(bus.bitrate).count();
  const std::int64_t queuing =
      response ? std::max<std::int64_t>(0, (*response - stream.jitter - stream.transmission).count()) : horizon.count();
  std::vector<BackgroundDelay> delays;
  std::optional<std::size_t> longest_lower;
  for (std::size_t i = 0; i < streams.size(); ++i) {
    const CanStream& k = streams[i];
    const CanBackgroundFrame& f = bus.background[i];
    if (k.can_id < stream.can_id) {
      const std::int64_t releases =
          std::max<std::int64_t>(1, ceil_div(queuing + k.jitter.count() + tau, k.period.count()));
      delays.push_back(BackgroundDelay{f.name, f.can_id, f.extended, Nanos(releases * k.transmission.count()), false});
    } else if (k.can_id > stream.can_id && (!longest_lower || k.transmission > streams[*longest_lower].transmission)) {
      longest_lower = i;
    }
  }
  if (longest_lower) {
    const CanBackgroundFrame& f = bus.background[*longest_lower];
    delays.push_back(BackgroundDelay{f.name, f.can_id, f.extended, streams[*longest_lower].transmission, true});
  }
  std::stable_sort(delays.begin(), delays.end(), [](const auto& a, const auto& b) { return a.delay > b.delay; });
  if (delays.size() > top) delays.resize(top);
  return delays;
}

}  // namespace cosmic
