// C++ wrapper of libcosmic-client (cosmic/client.h has the contract: formats, threads, ownership).
// Setup (open, announce) throws std::runtime_error with the reason; the hot path (publish,
// poll) returns COSMIC_* codes and never throws.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "cosmic/client.h"

namespace cosmic::client {

struct Event {
  cosmic_event_info info{};
  std::vector<std::uint8_t> data;
};

using Handler = std::function<void(const cosmic_event_info&, std::span<const std::uint8_t>)>;

// One announced channel; owned by its Client (valid while the Client lives).
class Channel {
 public:
  explicit Channel(cosmic_channel* handle) : handle_(handle) {}

  int publish(std::span<const std::uint8_t> data) { return cosmic_publish(handle_, data.data(), data.size()); }
  // Any trivially copyable value, as its bytes.
  template <typename T>
  int publish_value(const T& value) {
    return cosmic_publish(handle_, &value, sizeof value);
  }
  // Events go to `handler` on the client's receive thread.
  int on_event(Handler handler) {
    auto next = std::make_unique<Handler>(std::move(handler));
    const int rc = cosmic_subscribe(handle_, &Channel::trampoline, next.get());
    if (rc == COSMIC_OK) handler_.swap(next);  // the old one is no longer called once subscribe returned
    return rc;
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
  static void trampoline(const cosmic_event_info* info, const std::uint8_t* data, void* user) {
    (*static_cast<Handler*>(user))(*info, {data, info->size});
  }
  cosmic_channel* handle_;
  std::unique_ptr<Handler> handler_;
};

class Client {
 public:
  explicit Client(const std::string& segment) {
    char error[512] = "";
    client_ = cosmic_open(segment.c_str(), error, sizeof error);
    if (!client_) throw std::runtime_error(std::string("cosmic_open(") + segment + "): " + error);
  }
  ~Client() { cosmic_close(client_); }  // stops the receive threads before the handlers go
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  Channel& announce(const cosmic_channel_desc& desc, int timeout_ms = 5000) {
    cosmic_channel* handle = cosmic_announce(client_, &desc, timeout_ms);
    if (!handle) throw std::runtime_error(std::string("cosmic_announce(") + desc.name + "): " + cosmic_last_error(client_));
    channels_.push_back(std::make_unique<Channel>(handle));
    return *channels_.back();
  }

 private:
  cosmic_client* client_ = nullptr;
  std::vector<std::unique_ptr<Channel>> channels_;
};

// The verdict cosmicd gives `name`, or the reason it could not be asked.
inline std::string check_channel(const std::string& control_socket, const std::string& name) {
  char verdict[256] = "";
  cosmic_check_channel(control_socket.c_str(), name.c_str(), verdict, sizeof verdict);
  return verdict;
}

}  // namespace cosmic::client
