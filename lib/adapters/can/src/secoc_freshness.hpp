// The SecOC freshness of one CAN segment's channels (issue 36, item 4): the sending and receiving
// state of every SecOC hop (secoc_streams.hpp), kept across configure() (a reload never moves a
// counter back) and persisted across restarts in a file of the gateway's state directory
// (`<state directory>/secoc-<segment>.json`, docs/security.md). Internal to the CAN adapter.
//
// The file: {"version": 1, "senders": {"CHANNEL/DATA_ID": LEASE}, "receivers": {"CHANNEL/DATA_ID":
// LAST}}: a sender's lease (every value it used is at most LEASE; a restart starts past it) and a
// receiver's last accepted value. Written atomically (temporary file, fsync, rename, fsync of the
// directory) by the store's thread `fv:SEGMENT`: when a sender used half its lease (the lane pokes
// the thread) and once a second while receivers accept frames; once more at stop().
// A receiver's values of the last interval before a crash are lost: frames it accepted then could
// be accepted once more after the restart (docs/security.md says so).
//
// Without a file (no state directory, the adapter's tests) nothing is persisted and senders are
// not held to a lease.
//
// Threads: sender(), receiver(), persist_now() and stop() on the control thread (configure, stop);
// poke() on any lane; the rest on the store's thread. The streams are shared with the tables.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "cosmic/log.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/result.hpp"
#include "secoc_streams.hpp"

namespace cosmic::can_detail {

class SecocFreshness {
 public:
  SecocFreshness(std::string file, std::string log_prefix, std::string thread_name, Logger& log);
  ~SecocFreshness();
  SecocFreshness(const SecocFreshness&) = delete;
  SecocFreshness& operator=(const SecocFreshness&) = delete;

  // The channel's sending state for frames of `data_id`: the one kept (its counter continues; a
  // changed key or parameters make a new one from the same counter), else a new one from the
  // file's lease; else why not (the file cannot be read, the parameters are wrong).
  Result<std::shared_ptr<SecocTx>> sender(const std::string& channel, const SecocSpec& spec, std::uint32_t data_id);
  // The channel's receiving state, likewise; else why not.
  Result<std::shared_ptr<SecocRx>> receiver(const std::string& channel, const SecocSpec& spec, bool layout);
  // Persists what is due now and starts the store's thread when there is anything to keep. An
  // error is logged; the senders then stay within their last lease. Control thread.
  void persist_now();
  // A sender used half its lease: persist a new one soon. Any thread, no lock, no system call
  // unless the thread waits.
  void poke() noexcept;
  // Ends the thread and persists a last time. Control thread.
  void stop();

 private:
  struct Streams {
    std::map<std::string, std::shared_ptr<SecocTx>> senders;    // "CHANNEL/DATA_ID"
    std::map<std::string, std::shared_ptr<SecocRx>> receivers;  // CHANNEL
  };
  Result<void> load() COSMIC_REQUIRES(mutex_);
  Streams streams() const COSMIC_EXCLUDES(mutex_);
  // Writes the file with the senders' leases moved on where due; true when written (or nothing to do).
  bool persist(bool force) COSMIC_EXCLUDES(mutex_);
  void run();

  const std::string file_;
  const std::string prefix_;
  const std::string thread_name_;
  Logger& log_;

  mutable Mutex mutex_;  // control thread against the store's thread; never held across I/O
  bool loaded_ COSMIC_GUARDED_BY(mutex_) = false;
  std::string load_error_ COSMIC_GUARDED_BY(mutex_);
  std::map<std::string, std::uint64_t> file_senders_ COSMIC_GUARDED_BY(mutex_);    // as read at start
  std::map<std::string, std::uint64_t> file_receivers_ COSMIC_GUARDED_BY(mutex_);  // CHANNEL/DATA_ID
  Streams streams_ COSMIC_GUARDED_BY(mutex_);

  std::mutex write_mutex_;  // one writer of the file at a time (the thread, or persist_now/stop)
  std::string written_;     // the file's content as last written (under write_mutex_)
  bool write_error_logged_ = false;

  int wake_fd_ = -1;  // eventfd: poke() wakes the thread; made before the thread starts
  std::atomic<bool> poked_{false};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace cosmic::can_detail
