// Snapshots for /metrics taken on demand (docs/metrics.md): nothing is copied out of the gateway
// while nobody scrapes.
//
// A scrape (on an HTTP thread) calls get(). When the last snapshot is younger than `reuse_for` it
// is served again; otherwise the relay asks for a fresh one through `ask` (cosmicd posts a task
// to its control loop, the only thread that may read the Gateway), and the control thread hands it
// over with publish(). Scrapes that arrive while a snapshot is asked for share that one: at most one
// request is outstanding. So the control thread copies the gateway at most once per `reuse_for`,
// however many scrapes arrive, and never while nobody scrapes. A scrape waits at most `wait_for`
// (the control thread may be busy); then it gets the last snapshot there is, or none.
//
// Threads: get() from any thread; publish(), attach() and detach() from the owner's thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <utility>

namespace cosmicd {

template <typename Snapshot>
class SnapshotRelay {
 public:
  using Clock = std::chrono::steady_clock;

  struct Options {
    Clock::duration reuse_for = std::chrono::milliseconds(100);
    Clock::duration wait_for = std::chrono::milliseconds(500);
    std::function<Clock::time_point()> now = [] { return Clock::now(); };  // tests move time
  };

  explicit SnapshotRelay(Options options = {}) : options_(std::move(options)) {}

  // `ask` is called with the relay's lock held, from a scrape's thread: it must only arrange for
  // publish() to be called soon (queue a task), never call into the relay itself.
  void attach(std::function<void()> ask) {
    std::lock_guard lock(mutex_);
    ask_ = std::move(ask);
  }

  // After this nothing is asked any more and waiting scrapes are answered at once (with the last
  // snapshot): call it before whatever `ask` refers to goes away.
  void detach() {
    {
      std::lock_guard lock(mutex_);
      ask_ = nullptr;
      asking_ = false;
    }
    published_signal_.notify_all();
  }

  // A snapshot for one scrape: fresh (taken after the last `reuse_for`) unless the owner did not
  // answer within `wait_for`; null when there has never been one.
  std::shared_ptr<const Snapshot> get() {
    std::unique_lock lock(mutex_);
    if (latest_ && options_.now() - taken_at_ < options_.reuse_for) return latest_;
    if (!ask_) return latest_;
    const std::uint64_t wanted = published_ + 1;
    if (!asking_) {
      asking_ = true;
      ++asked_;
      ask_();
    }
    published_signal_.wait_for(lock, options_.wait_for, [&] { return published_ >= wanted || !ask_; });
    return latest_;
  }

  // The owner's answer to `ask`.
  void publish(Snapshot snapshot) {
    auto shared = std::make_shared<const Snapshot>(std::move(snapshot));
    {
      std::lock_guard lock(mutex_);
      latest_ = std::move(shared);
      taken_at_ = options_.now();
      ++published_;
      asking_ = false;
    }
    published_signal_.notify_all();
  }

  // How many snapshots were asked for so far.
  std::uint64_t asked() const {
    std::lock_guard lock(mutex_);
    return asked_;
  }

 private:
  Options options_;
  mutable std::mutex mutex_;
  std::condition_variable published_signal_;
  std::function<void()> ask_;
  bool asking_ = false;  // a request is outstanding
  std::uint64_t asked_ = 0;
  std::uint64_t published_ = 0;
  std::shared_ptr<const Snapshot> latest_;
  Clock::time_point taken_at_{};
};

}  // namespace cosmicd
