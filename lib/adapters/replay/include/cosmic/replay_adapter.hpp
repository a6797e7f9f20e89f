// A replay segment (issue 37, `type: replay`, docs/recording.md): a source that publishes a
// recording into the channels bound on it as publishers, each event at its recorded spacing divided
// by `speed`, from `start_offset` into the recording, and again from the start with `loop`. To the
// router it is a segment like any other: its events enter by the same ingress checks and policing,
// with this gateway as their origin and new sequence numbers; so `bind --replace` can swap it in for
// a live sensor's segment and back. A typed channel's events, recorded as JSON, are read back into
// the compact layout (cosmic/json_event_reader.hpp); one that does not read counts as a receive
// error. A pass starts when the segment first carries a channel of the
// recording (or again after it carried none).
//
// It reports how far it ran from the recorded timing: each event's lateness (delivered minus due),
// p50, p99 and max over the current pass, as transport counters (`cosmicctl segments`) and in its
// health detail.
//
// Threads: the SegmentAdapter calls on the control thread; one thread of its own ("replay:NAME")
// reads the file and calls the sink.
#pragma once

#include <memory>

#include "cosmic/log.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

std::unique_ptr<SegmentAdapter> make_replay_adapter(const SegmentSpec& segment, Logger& log);

}  // namespace cosmic
