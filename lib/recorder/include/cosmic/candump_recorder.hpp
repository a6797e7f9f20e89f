// CAN logs (issue 37, docs/recording.md "CAN logs"): every frame a CAN segment's adapter receives
// and sends, written as `candump -l` lines (cosmic/candump_log.hpp) that `canplayer` replays, one
// file per segment: DIRECTORY/GATEWAY-SEGMENT-YYYYMMDD-HHMMSS-N.log (UTC), a new one when a file
// reaches `rotate.size` or has been written for `rotate.duration`, and at every start.
//
// Each segment has a CandumpTap, the WireTap its adapter is made with (cosmic/wire_tap.hpp). While
// the recorder records that segment the tap copies each frame with its time into the recorder's
// bounded many-to-one queue (cosmic/record_ring.hpp, a quarter of `recording.memory`) or counts it
// dropped when the queue is full; otherwise it does nothing. One writer thread ("candump", nice 19)
// takes the frames every 20 ms and appends their lines to the segment's file.
//
// Ownership: the owner keeps the recorder alive while any adapter may call a tap attached to it
// (cosmicd: for the life of the process); taps are shared with the adapters and outlive them.
// Threads: CandumpTap::on_wire() on the adapters' threads (never blocks, allocates or does I/O);
// every CandumpRecorder call on one control thread; the writer thread is the recorder's own. The
// control calls and the writer share one mutex, so a call may wait for one file write.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cosmic/log.hpp"
#include "cosmic/model.hpp"
#include "cosmic/record_ring.hpp"
#include "cosmic/result.hpp"
#include "cosmic/wire_tap.hpp"

namespace cosmic {

class CandumpRecorder;

// One segment's tap: made once per segment and given to each adapter of that segment in turn.
class CandumpTap final : public WireTap {
 public:
  void on_wire(const WireUnit& unit) noexcept override;

 private:
  friend class CandumpRecorder;
  // Set by the recorder while it records this segment: where the frames go, and the segment's
  // slot and the recording's session (one word, so a frame never pairs one with the other's
  // predecessor), by which the writer tells an old recording's late frames apart.
  std::atomic<CandumpRecorder*> recorder_{nullptr};
  std::atomic<std::uint64_t> slot_and_session_{0};
};

// A segment to log: its name (in the file name) and CAN interface (in every line).
struct CandumpSegment {
  std::string name;
  std::string interface;
  std::shared_ptr<CandumpTap> tap;
};

struct CandumpStatus {
  bool recording = false;
  std::vector<std::string> files_open;  // being written, one per segment
  std::uint64_t files = 0;              // opened since the recorder was made
  std::uint64_t lines = 0;              // written, in all files
  std::uint64_t bytes = 0;              // written, in all files
  std::uint64_t dropped_full = 0;       // frames offered while the queue had no room
  std::uint64_t dropped_failed = 0;     // frames taken while their file could not be written
  std::string last_error;               // the last open or write failure; empty when none
};

class CandumpRecorder {
 public:
  // Starts the writer thread; logging begins with start(). `spec`: directory, rotation, memory.
  CandumpRecorder(const RecordingSpec& spec, std::string gateway, Logger& log);
  ~CandumpRecorder();
  CandumpRecorder(const CandumpRecorder&) = delete;
  CandumpRecorder& operator=(const CandumpRecorder&) = delete;

  // Opens a file for each segment (the directory is made if missing) and attaches their taps; an
  // error, and nothing logged, when a file cannot be opened. A recording in progress is stopped first.
  Result<void> start(std::vector<CandumpSegment> segments);
  // Detaches the taps, writes what is queued and closes the files.
  void stop();
  // Directory and rotation from the next file on; the queue keeps its size.
  void reconfigure(const RecordingSpec& spec);
  CandumpStatus status() const;

 private:
  friend class CandumpTap;
  struct SegmentLog;
  // Taps: queue one frame or count it dropped.
  void offer(std::uint64_t slot_and_session, const WireUnit& unit) noexcept;
  void run();
  // With mutex_ held: take what is queued, write it, rotate what is due.
  void write_queued(bool rotate_due);
  void take(std::span<const std::uint8_t> record);
  void flush(SegmentLog& log);
  Result<void> open(SegmentLog& log);
  void close(SegmentLog& log);
  void fail(SegmentLog& log, const std::string& why);

  std::string gateway_;
  Logger& log_;
  RecordRing ring_;
  std::atomic<std::uint64_t> dropped_full_{0};

  mutable std::mutex mutex_;  // everything below; ring_ is read under it only (one reader at a time)
  std::condition_variable wake_;
  bool quit_ = false;
  RecordingSpec spec_;
  std::vector<SegmentLog> logs_;  // the recording's segments, by slot
  std::uint32_t session_ = 0;     // bumped by every start()
  std::uint64_t numbered_ = 0;
  std::uint64_t files_ = 0, lines_ = 0, bytes_ = 0, dropped_failed_ = 0;
  std::string last_error_;
  std::thread thread_;  // last: started once everything above is
};

}  // namespace cosmic
