// cosmicd's recording (issue 37, docs/recording.md): the `recording:` section of the configuration
// turned into a cosmic::Recorder attached to the gateway, started at start when `start` is true, and
// the control commands record_start, record_stop and record_status. The CAN segments listed in
// `candump` are logged alongside in candump -l format while recording is on (a
// cosmic::CandumpRecorder fed by each CAN adapter's wire tap, which wire_tap() hands out).
//
// A reload applies the new section: recording stays as it was (started or stopped) unless the
// section was added or removed; the new directory, compression, chunking and rotation take effect
// at once (the current file is finished and a new one opened), the channel selection at once, the
// queue's size (`memory`) at the next start of cosmicd. The recorder, once made, lives as long as
// the process: the router may hold its hook until then.
//
// Threads: the control thread only (the recorder's own thread writes).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <set>
#include <vector>

#include "cosmic/candump_recorder.hpp"
#include "cosmic/gateway.hpp"
#include "cosmic/recorder.hpp"

namespace cosmicd {

class RecordingService {
 public:
  explicit RecordingService(cosmic::Logger& log) : log_(log) {}
  RecordingService(const RecordingService&) = delete;
  RecordingService& operator=(const RecordingService&) = delete;

  // At start and after every reload, with the configuration the gateway now runs.
  void configure(cosmic::Gateway& gateway, const cosmic::Config& config);
  // Control commands: the answers, "ok" included.
  nlohmann::json start();
  nlohmann::json stop();
  nlohmann::json status() const;
  // For /metrics: nullopt while there is no recorder (no recording: section since the start).
  std::optional<cosmic::RecorderStatus> recorder_status() const {
    return recorder_ ? std::optional(recorder_->status()) : std::nullopt;
  }
  // Before the gateway stops: the current file is finished.
  void shut_down();
  // The tap a CAN segment's adapter is made with (the same one for every adapter of that segment,
  // for the life of the process); null for other segments. The adapter factory calls it.
  std::shared_ptr<cosmic::WireTap> wire_tap(const cosmic::SegmentSpec& segment);

 private:
  void on_routes(const std::vector<cosmic::Route>& routes);
  void select(bool recording);
  // The MCAP recorder and the CAN logs started together: an error, and neither running, when one fails.
  cosmic::Result<void> start_both();
  void stop_both();
  std::vector<cosmic::CandumpSegment> candump_segments();

  cosmic::Logger& log_;
  cosmic::Gateway* gateway_ = nullptr;
  cosmic::RecordingSpec spec_;
  std::unique_ptr<cosmic::Recorder> recorder_;
  std::vector<cosmic::Route> last_routes_;                           // the gateway's table as last applied
  std::map<std::string, std::shared_ptr<cosmic::CandumpTap>> taps_;  // by CAN segment name
  std::map<std::string, std::string> interfaces_;                    // CAN segment name -> interface
  std::unique_ptr<cosmic::CandumpRecorder> candump_;                 // once `candump` lists a segment
  std::set<std::string> warned_json_;  // "channel\nreason" of typed channels said to fall back to JSON
  bool recording_ = false;
};

}  // namespace cosmicd
