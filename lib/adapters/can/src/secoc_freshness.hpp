// The SecOC freshness of one CAN segment's channels (issue 36, item 4): the sending and receiving
// state of every SecOC hop (secoc_streams.hpp), kept across configure() (a reload never moves a
// counter back), shared by the adapters that attach the segment in turn (a reload that replaces
// the adapter continues the same counters: make_can_secoc_state in cosmic/can_adapter.hpp), and
// persisted across restarts in a file of the gateway's state directory
// (`<state directory>/secoc-<segment>.json`, docs/security.md).
//
// The file: {"version": 1, "senders": {"CHANNEL/DATA_ID": LEASE}, "receivers": {"CHANNEL/SENDER":
// LAST}}: a sender's lease (every value it used is at most LEASE; a restart starts from it) and a
// receiver's last accepted value per sender (secoc_source). Written atomically (temporary file,
// fsync, rename, fsync of the directory), one write at a time, by the store's thread `fv:SEGMENT`
// (when a sender used half its lease: the lane pokes the thread; once a second while receivers
// accept frames), by configure() for a new sender's first lease, and at the last detach() (a clean
// stop), which cuts every lease back to the value last used, so a clean restart skips nothing. A
// start's first lease is small (secoc_start_step) until the sender sent a frame. A receiver's
// values of the last second before a crash are lost: frames it accepted then could be accepted
// once more after the restart (docs/security.md says so). A write that failed is retried at most
// once a second.
//
// Without a file (the adapter's tests) nothing is persisted and senders are not held to a lease.
//
// Threads: sender(), receiver(), persist_now(), attach() and detach() on the control thread
// (configure, start, stop); poke() on any lane; the rest on the store's thread.
#pragma once

#include <atomic>
#include <chrono>
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

// Whether two hop settings make the same MACs (key, sizes, data ID): `cost` and the key file's
// name change nothing on the wire.
bool same_secoc_mac(const SecocSpec& a, const SecocSpec& b);

class SecocFreshness {
 public:
  SecocFreshness(std::string file, std::string log_prefix, std::string thread_name, Logger& log);
  ~SecocFreshness();
  SecocFreshness(const SecocFreshness&) = delete;
  SecocFreshness& operator=(const SecocFreshness&) = delete;

  // The channel's sending state for frames of `data_id`: the one kept (its counter continues; a
  // changed key or sizes retire it and make a new one from its last value), else a new one from
  // the file's lease; else why not (the file cannot be read, the parameters are wrong).
  Result<std::shared_ptr<SecocTx>> sender(const std::string& channel, const SecocSpec& spec, std::uint32_t data_id);
  // The channel's receiving state, likewise; else why not.
  Result<std::shared_ptr<SecocRx>> receiver(const std::string& channel, const SecocSpec& spec, bool layout);
  // Persists what is due now (a new sender's first lease) and starts the store's thread when there
  // is anything to keep; false, with the reason in the log and last_error(), when it could not be
  // written. Control thread.
  bool persist_now();
  std::string last_error() const;
  // A sender used half its lease: persist a new one soon. Any thread, no lock; one write(2).
  void poke() noexcept;
  // An adapter uses the store / no longer does: the last to leave ends the thread, cuts every
  // lease back to its last used value and persists (a clean stop). Control thread.
  void attach();
  void detach();

 private:
  struct Streams {
    std::map<std::string, std::shared_ptr<SecocTx>> senders;    // "CHANNEL/DATA_ID"
    std::map<std::string, std::shared_ptr<SecocRx>> receivers;  // CHANNEL
  };
  Result<void> load() COSMIC_REQUIRES(mutex_);
  Result<void> parse(const std::string& content) COSMIC_REQUIRES(mutex_);
  // Writes the file with the senders' leases moved on where due; true when written or unchanged.
  bool persist(bool retiring);
  void run();
  void stop_thread();

  const std::string file_;
  const std::string prefix_;
  const std::string thread_name_;
  Logger& log_;
  const int wake_fd_;  // eventfd: poke() wakes the thread (-1 without a file, or when none could be had)

  mutable Mutex mutex_;  // the streams and what was read: control thread against the store's thread
  bool loaded_ COSMIC_GUARDED_BY(mutex_) = false;
  std::string load_error_ COSMIC_GUARDED_BY(mutex_);
  std::map<std::string, std::uint64_t> file_senders_ COSMIC_GUARDED_BY(mutex_);    // as read, then written
  std::map<std::string, std::uint64_t> file_receivers_ COSMIC_GUARDED_BY(mutex_);  // CHANNEL/SENDER
  Streams streams_ COSMIC_GUARDED_BY(mutex_);
  int users_ COSMIC_GUARDED_BY(mutex_) = 0;

  // One writer of the file at a time, from the snapshot of the streams to the leases granted.
  mutable std::mutex write_mutex_;
  std::string written_;  // the file's content as last written
  std::string write_error_;
  std::chrono::steady_clock::time_point retry_after_{};

  std::atomic<bool> poked_{false};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace cosmic::can_detail
