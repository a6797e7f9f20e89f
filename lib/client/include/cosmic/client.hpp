// C++ wrapper of libcosmic-client (cosmic/client.h has the contract: formats, threads, ownership).
// Setup (open, announce, wait_ready) throws std::runtime_error (or TimeoutError, derived from it)
// with the reason; the hot path (publish, poll) returns COSMIC_* codes and never throws.
#pragma once

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/client.h"

namespace cosmic::client {

struct Event {
  cosmic_event_info info{};
  std::vector<std::uint8_t> data;
};

// Channel::wait_ready() ran out of time (COSMIC_E_TIMEOUT): what() names the channel, the
// segment, the role(s) still unmatched and the time waited.
class TimeoutError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using Handler = std::function<void(const cosmic_event_info&, std::span<const std::uint8_t>)>;

class Channel;

// A handler installed by Channel::on_event(). Destroying the Subscription (or cancel()) stops the
// handler: when that returns, the handler is not running and is never called again. Declare it
// after the state its handler uses, so that it goes first:
//     Drive drive;                                              // the handler's state
//     auto on_speed = speed.on_event([&](auto&, auto e) { drive.push(e); });  // stops before drive goes
// Move-only; an empty one (default, moved from, cancelled, or replaced by a newer on_event() of its
// channel) does nothing. It may outlive its Client (closing the client stopped every handler), but
// must not be destroyed while another thread destroys or closes that Client.
class [[nodiscard]] Subscription {
 public:
  Subscription() = default;
  Subscription(Subscription&& other) noexcept { *this = std::move(other); }
  Subscription& operator=(Subscription&& other) noexcept {
    if (this != &other) {
      cancel();
      channel_ = std::move(other.channel_);
      generation_ = other.generation_;
      other.channel_.reset();
    }
    return *this;
  }
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;
  ~Subscription() { cancel(); }
  inline void cancel();
  // Whether this subscription's handler is still the channel's.
  inline bool active() const;

 private:
  friend class Channel;
  Subscription(std::weak_ptr<Channel> channel, std::uint64_t generation)
      : channel_(std::move(channel)), generation_(generation) {}
  std::weak_ptr<Channel> channel_;
  std::uint64_t generation_ = 0;
};

// One announced channel; owned by its Client (valid while the Client lives and is not closed).
// publish(), poll() and wait_ready() from any thread; on_event(), stop_events() and the
// Subscriptions of one channel from one thread at a time (the handler's thread counts as one).
class Channel : public std::enable_shared_from_this<Channel> {
 public:
  explicit Channel(cosmic_channel* handle, cosmic_client* client = nullptr) : handle_(handle), client_(client) {}
  Channel(const Channel&) = delete;
  Channel& operator=(const Channel&) = delete;

  // Waits until the channel is carried (cosmic_wait_ready): every announced role has a matched
  // remote endpoint on DDS; at once on LCM and CAN. Call it after announce and before the first
  // event that must not be lost. Throws TimeoutError when `timeout` passed first (the channel stays
  // usable), std::invalid_argument for a negative timeout. Timeouts beyond INT_MAX ms are cut to it.
  void wait_ready(std::chrono::milliseconds timeout) {
    if (timeout.count() < 0) throw std::invalid_argument("wait_ready: the timeout is negative");
    const auto ms = std::min<std::chrono::milliseconds::rep>(timeout.count(), INT_MAX);
    const int rc = cosmic_wait_ready(handle_, static_cast<int>(ms));
    if (rc == COSMIC_OK) return;
    const std::string why = std::string("cosmic_wait_ready: ") + (client_ ? cosmic_last_error(client_) : "failed");
    if (rc == COSMIC_E_TIMEOUT) throw TimeoutError(why);
    throw std::runtime_error(why);
  }
  int publish(std::span<const std::uint8_t> data) { return cosmic_publish(handle_, data.data(), data.size()); }
  // Any trivially copyable value, as its bytes.
  template <typename T>
  int publish_value(const T& value) {
    return cosmic_publish(handle_, &value, sizeof value);
  }
  // Events go to `handler` on the client's receive thread until the returned Subscription is
  // destroyed or cancelled, another on_event() or stop_events() of this channel returns, or the
  // Client is closed. Replaces the previous handler (which is not running once this returns).
  // Throws std::invalid_argument when the channel was not announced with COSMIC_SUBSCRIBE.
  // Allowed from inside this channel's own handler (the running handler is kept alive until it returns).
  Subscription on_event(Handler handler) {
    auto next = std::make_unique<Installed>(Installed{this, std::move(handler)});
    if (cosmic_subscribe(handle_, &Channel::trampoline, next.get()) != COSMIC_OK) {
      throw std::invalid_argument("on_event: the channel was not announced with COSMIC_SUBSCRIBE");
    }
    release(std::exchange(installed_, std::move(next)));
    return Subscription(weak_from_this(), ++generation_);
  }
  // Stops the handler (see cosmic_unsubscribe): later events are queued for poll().
  void stop_events() {
    cosmic_unsubscribe(handle_);
    release(std::move(installed_));
    ++generation_;
  }
  // The oldest queued event, if any (polling mode: no handler installed).
  std::optional<Event> poll(std::size_t capacity = 65536) {
    Event e;
    e.data.resize(capacity);
    if (cosmic_get_event(handle_, &e.info, e.data.data(), e.data.size()) != COSMIC_OK) return std::nullopt;
    e.data.resize(e.info.size);
    return e;
  }
  cosmic_channel* handle() const { return handle_; }

 private:
  friend class Subscription;
  struct Installed {
    Channel* channel;
    Handler handler;
  };
  // The channel whose handler this thread is running, if any.
  static const Channel*& running() {
    thread_local const Channel* channel = nullptr;
    return channel;
  }
  static void trampoline(const cosmic_event_info* info, const std::uint8_t* data, void* user) {
    auto* installed = static_cast<Installed*>(user);
    const Channel* outer = std::exchange(running(), installed->channel);
    installed->handler(*info, {data, info->size});
    running() = outer;
  }
  // A handler that is no longer installed: freed now, or kept until the next release outside a
  // handler when it may be the one running on this thread.
  void release(std::unique_ptr<Installed> old) {
    if (running() == this) {
      if (old) retired_.push_back(std::move(old));
      return;
    }
    retired_.clear();
  }
  cosmic_channel* handle_;
  cosmic_client* client_;  // for cosmic_last_error(); null: the reasons are not known
  std::unique_ptr<Installed> installed_;
  std::vector<std::unique_ptr<Installed>> retired_;
  std::uint64_t generation_ = 0;  // counts installs and stops; a Subscription stops only its own
};

void Subscription::cancel() {
  if (auto channel = channel_.lock(); channel && channel->generation_ == generation_) channel->stop_events();
  channel_.reset();
}

bool Subscription::active() const {
  const auto channel = channel_.lock();
  return channel && channel->generation_ == generation_;
}

class Client {
 public:
  explicit Client(const std::string& segment) {
    char error[512] = "";
    client_ = cosmic_open(segment.c_str(), error, sizeof error);
    if (!client_) throw std::runtime_error(std::string("cosmic_open(") + segment + "): " + error);
  }
  ~Client() { close(); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  Channel& announce(const cosmic_channel_desc& desc, int timeout_ms = 5000) {
    if (!client_) throw std::runtime_error(std::string("cosmic_announce(") + desc.name + "): the client is closed");
    cosmic_channel* handle = cosmic_announce(client_, &desc, timeout_ms);
    if (!handle)
      throw std::runtime_error(std::string("cosmic_announce(") + desc.name + "): " + cosmic_last_error(client_));
    channels_.push_back(std::make_shared<Channel>(handle, client_));
    return *channels_.back();
  }
  // Stops the receive threads (waiting for a handler in progress), then frees the channels: no
  // handler runs once it returns, and every Channel& of this client is gone. The destructor does it;
  // call it earlier to stop the handlers before state they use goes. Never from inside a handler.
  void close() {
    if (!client_) return;
    cosmic_close(std::exchange(client_, nullptr));
    channels_.clear();
  }

 private:
  cosmic_client* client_ = nullptr;
  std::vector<std::shared_ptr<Channel>> channels_;
};

// The verdict cosmicd gives `name`, or the reason it could not be asked.
inline std::string check_channel(const std::string& control_socket, const std::string& name) {
  char verdict[256] = "";
  cosmic_check_channel(control_socket.c_str(), name.c_str(), verdict, sizeof verdict);
  return verdict;
}

}  // namespace cosmic::client
