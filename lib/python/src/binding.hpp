// The state behind the Python package `cosmic` (lib/python): one ClientState per cosmic.Client,
// one ChannelState per announced channel, shared by the Python objects that refer to them.
//
// Locking, and why nothing deadlocks: libcosmic-client holds a channel's mutex while it runs the
// channel's callback, and our callback needs the GIL. So every call into the C library that may
// take that mutex (publish, subscribe, get_event, announce, close) is made with the GIL released;
// the GIL is never awaited while a mutex of ours is held.
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cosmic/client.h"

namespace cosmic::python {

namespace py = pybind11;

// Raises the cosmic.Error subclass of `code` (cosmic/_errors.py) with `message`.
[[noreturn]] void raise_error(int code, const std::string& message);
// The same for a closed client: cosmic.ClosedError.
[[noreturn]] void raise_closed(const std::string& what);

struct QueuedEvent {
  cosmic_event_info info{};
  std::vector<std::uint8_t> data;
};

// What a Python callback receives and get_event() returns: a copy, safe to keep.
struct Event {
  py::bytes payload;
  std::uint64_t subject = 0;
  std::uint32_t sequence = 0;
  std::int64_t age_ns = 0;
  std::string channel;
};

class ClientState;

// The events a channel's subscribers see: a Python callback, or the queue get_event() reads.
struct ChannelState {
  ChannelState(ClientState& owner, cosmic_channel* channel_handle, std::string channel_name, std::uint32_t max_payload,
               int channel_roles)
      : client(owner),
        handle(channel_handle),
        name(std::move(channel_name)),
        payload(max_payload),
        roles(channel_roles) {}

  ClientState& client;
  cosmic_channel* handle;  // freed by cosmic_close()
  const std::string name;
  const std::uint32_t payload;
  const int roles;

  // Fed on the receive thread (no GIL) while no Python callback is installed; the newest
  // kQueuedEvents are kept, as the C library keeps them.
  static constexpr std::size_t kQueuedEvents = 64;
  std::mutex queue_mutex;
  std::condition_variable queue_changed;  // an event arrived, or the client is closing
  std::deque<QueuedEvent> queue;
  // The installed Python callback; null: events are queued. Read and written with the GIL held.
  py::object callback;
};

// One cosmic_open() and its channels.
class ClientState {
 public:
  explicit ClientState(const std::string& segment);  // GIL held; released while opening
  ~ClientState();                                    // GIL held: closes
  ClientState(const ClientState&) = delete;
  ClientState& operator=(const ClientState&) = delete;

  // Stops the receive threads and frees the C client (GIL held on entry, released while waiting).
  // Raises when called from inside one of this client's callbacks (the C API forbids it).
  void close();
  bool closed() const { return closed_.load(); }
  const std::string& segment() const { return segment_; }
  cosmic_client* handle() const { return handle_; }
  // The reason the C library gives for the last failure of this client.
  std::string last_error() const;

  ChannelState& add_channel(cosmic_channel* handle, std::string name, std::uint32_t payload, int roles);

  // A call into the C library on this client: while one is held, close() waits before it frees
  // the client. Taken with the GIL held; raises cosmic.ClosedError when the client is closed.
  class Use {
   public:
    Use(ClientState& client, const char* what);
    ~Use();
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;

   private:
    ClientState& client_;
  };

  // Closes every open client (registered with atexit: no receive thread may still want the GIL
  // while the interpreter finalizes).
  static void close_all();

 private:
  void wait_until_idle();
  void close_from_callback_thread();

  std::string segment_;
  cosmic_client* handle_ = nullptr;
  std::atomic<bool> closed_{false};
  std::atomic<int> busy_{0};  // Use objects alive
  std::mutex idle_mutex_;
  std::condition_variable idle_;
  std::vector<std::unique_ptr<ChannelState>> channels_;  // changed with the GIL held
};

// The callback this thread is running, if any (set on the receive thread by the trampoline).
struct RunningCallback {
  const ClientState* client = nullptr;
  const ChannelState* channel = nullptr;
};
RunningCallback& running_callback();

// libcosmic-client callbacks: events to the Python callback, or to the get_event() queue.
void deliver_to_python(const cosmic_event_info* info, const std::uint8_t* data, void* user);
void deliver_to_queue(const cosmic_event_info* info, const std::uint8_t* data, void* user);

// Module parts, each in its own file.
void bind_client(py::module_& m);
void bind_channel(py::module_& m);
void bind_model(py::module_& m);

}  // namespace cosmic::python
