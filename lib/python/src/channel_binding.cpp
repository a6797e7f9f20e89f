// cosmic.Channel and cosmic.Event: publish, subscribe, unsubscribe and get_event of one announced
// channel, and the two libcosmic-client callbacks behind them.
#include <pybind11/stl.h>

#include <chrono>
#include <climits>
#include <cmath>
#include <optional>
#include <utility>

#include "binding.hpp"
#include "channel_ref.hpp"

namespace cosmic::python {
namespace {

Event make_event(const cosmic_event_info& info, const std::uint8_t* data, const std::string& channel) {
  return Event{py::bytes(reinterpret_cast<const char*>(data), info.size), info.subject, info.sequence, info.age_ns,
               channel};
}

bool interpreter_finalizing() {
#if PY_VERSION_HEX >= 0x030D0000
  return Py_IsFinalizing();
#else
  return _Py_IsFinalizing();
#endif
}

// A C-contiguous view of any buffer-protocol object (bytes, bytearray, memoryview, numpy array):
// its memory is published as it is, without a copy. Released with the GIL held.
class ContiguousBuffer {
 public:
  explicit ContiguousBuffer(py::handle object) {
    if (PyObject_GetBuffer(object.ptr(), &view_, PyBUF_C_CONTIGUOUS) != 0) throw py::error_already_set();
  }
  ~ContiguousBuffer() { PyBuffer_Release(&view_); }
  ContiguousBuffer(const ContiguousBuffer&) = delete;
  ContiguousBuffer& operator=(const ContiguousBuffer&) = delete;
  const void* data() const { return view_.buf; }
  std::size_t size() const { return static_cast<std::size_t>(view_.len); }

 private:
  Py_buffer view_{};
};

void require_role(const ChannelRef& self, int role, const char* call) {
  if (self.channel->roles & role) return;
  const char* has = role == COSMIC_PUBLISH ? "subscribe" : "publish";
  raise_error(COSMIC_E_INVALID, std::string(call) + " on channel '" + self.channel->name +
                                    "', which was announced to " + has + " only (announce it with roles that include " +
                                    (role == COSMIC_PUBLISH ? "PUBLISH" : "SUBSCRIBE") + ")");
}

// The C API forbids changing another channel's callback from inside a callback: two receive
// threads could wait for each other.
void refuse_inside_other_callback(const ChannelRef& self, const char* call) {
  const RunningCallback& running = running_callback();
  if (running.channel && running.channel != self.channel) {
    raise_error(COSMIC_E_INVALID, std::string(call) + " of channel '" + self.channel->name +
                                      "' from inside the callback of channel '" + running.channel->name +
                                      "' (only a callback's own channel may be changed there)");
  }
}

bool publish(const ChannelRef& self, py::handle data) {
  require_role(self, COSMIC_PUBLISH, "publish()");
  ContiguousBuffer buffer(data);
  ClientState::Use use(*self.client, "publish()");
  int rc = COSMIC_OK;
  {
    py::gil_scoped_release nogil;  // a reliable DDS writer may block; the receive thread may want the GIL
    rc = cosmic_publish(self.channel->handle, buffer.data(), buffer.size());
  }
  if (rc == COSMIC_OK) return true;
  if (rc == COSMIC_E_AGAIN) return false;
  raise_error(rc, "publish() on channel '" + self.channel->name + "': " + self.client->last_error());
}

void subscribe(const ChannelRef& self, py::object callback) {
  require_role(self, COSMIC_SUBSCRIBE, "subscribe()");
  if (!PyCallable_Check(callback.ptr())) throw py::type_error("subscribe(): the callback must be callable");
  refuse_inside_other_callback(self, "subscribe()");
  ClientState::Use use(*self.client, "subscribe()");
  self.channel->callback = std::move(callback);            // the next event sees it
  if (running_callback().channel == self.channel) return;  // takes effect when the running callback returns
  py::gil_scoped_release nogil;
  // Waits for a callback in progress (it may be the previous one): once this returns, the
  // previous callback is not running and is never called again.
  cosmic_subscribe(self.channel->handle, deliver_to_python, self.channel);
}

void unsubscribe(const ChannelRef& self) {
  require_role(self, COSMIC_SUBSCRIBE, "unsubscribe()");
  refuse_inside_other_callback(self, "unsubscribe()");
  ClientState::Use use(*self.client, "unsubscribe()");
  self.channel->callback = py::object();  // an event in between is queued by deliver_to_python
  if (running_callback().channel == self.channel) {
    cosmic_subscribe(self.channel->handle, deliver_to_queue, self.channel);  // inside: no waiting
    return;
  }
  py::gil_scoped_release nogil;
  cosmic_subscribe(self.channel->handle, deliver_to_queue, self.channel);
}

// cosmic_wait_ready with the GIL released: the wait is bounded by `timeout`, after which Ctrl-C and
// a close() from another thread take effect. Never inside a callback (the C API's rule: it would
// hold up the receive thread for up to `timeout`).
void wait_ready(const ChannelRef& self, double timeout) {
  if (!(timeout >= 0)) raise_error(COSMIC_E_INVALID, "wait_ready(): timeout must be >= 0 seconds");
  if (running_callback().channel) {
    raise_error(COSMIC_E_INVALID, "wait_ready() of channel '" + self.channel->name +
                                      "' from inside the callback of channel '" + running_callback().channel->name +
                                      "' (it would hold up the receive thread)");
  }
  ClientState::Use use(*self.client, "wait_ready()");
  const double ms = std::round(timeout * 1e3);
  const int timeout_ms = ms >= static_cast<double>(INT_MAX) ? INT_MAX : static_cast<int>(ms);
  int rc = COSMIC_OK;
  {
    py::gil_scoped_release nogil;
    rc = cosmic_wait_ready(self.channel->handle, timeout_ms);
  }
  if (rc != COSMIC_OK) raise_error(rc, "wait_ready(): " + self.client->last_error());
}

std::optional<QueuedEvent> pop(ChannelState& channel) {
  if (channel.queue.empty()) return std::nullopt;
  std::optional<QueuedEvent> e(std::move(channel.queue.front()));
  channel.queue.pop_front();
  return e;
}

// Waits with the GIL released, in slices of at most kSignalCheck so that Ctrl-C (a signal handled
// by the main thread's Python code) interrupts an endless wait.
py::object get_event(const ChannelRef& self, std::optional<double> timeout) {
  using Clock = std::chrono::steady_clock;
  constexpr auto kSignalCheck = std::chrono::milliseconds(100);
  require_role(self, COSMIC_SUBSCRIBE, "get_event()");
  if (timeout && !(*timeout >= 0)) raise_error(COSMIC_E_INVALID, "get_event(): timeout must be >= 0 seconds or None");
  ClientState::Use use(*self.client, "get_event()");
  ChannelState& channel = *self.channel;
  if (timeout && *timeout == 0) {  // a poll per simulation step: the queue's lock is never held long
    std::unique_lock lock(channel.queue_mutex);
    auto e = pop(channel);
    lock.unlock();
    return e ? py::cast(make_event(e->info, e->data.data(), channel.name)) : py::none();
  }
  constexpr double kForever = 1e9;  // s (31 years): longer waits are endless, and the arithmetic cannot overflow
  const auto deadline =
      timeout && *timeout < kForever
          ? Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(*timeout))
          : Clock::time_point::max();
  while (true) {
    std::optional<QueuedEvent> e;
    bool timed_out = false;
    {
      py::gil_scoped_release nogil;
      std::unique_lock lock(channel.queue_mutex);
      const auto slice_end = std::min(deadline, Clock::now() + kSignalCheck);
      channel.queue_changed.wait_until(lock, slice_end,
                                       [&] { return !channel.queue.empty() || self.client->closed(); });
      e = pop(channel);
      timed_out = Clock::now() >= deadline;
    }
    if (e) return py::cast(make_event(e->info, e->data.data(), channel.name));
    if (self.client->closed())
      raise_closed("get_event() on channel '" + channel.name + "': the client was closed while waiting");
    if (timed_out) return py::none();
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

}  // namespace

void deliver_to_queue(const cosmic_event_info* info, const std::uint8_t* data, void* user) {
  auto* channel = static_cast<ChannelState*>(user);
  {
    std::lock_guard lock(channel->queue_mutex);
    if (channel->queue.size() == ChannelState::kQueuedEvents) channel->queue.pop_front();  // the newest matter most
    channel->queue.push_back(QueuedEvent{*info, {data, data + info->size}});
  }
  channel->queue_changed.notify_all();
}

// On the client's receive thread, inside the C library's lock of the channel. An exception of the
// callback goes to sys.unraisablehook (printed by default); the receive thread carries on.
void deliver_to_python(const cosmic_event_info* info, const std::uint8_t* data, void* user) {
  auto* channel = static_cast<ChannelState*>(user);
  if (interpreter_finalizing()) return;  // no thread may take the GIL any more (atexit closed the clients)
  py::gil_scoped_acquire gil;
  py::object callback = channel->callback;  // our own reference: the callback may replace itself
  if (!callback) {
    deliver_to_queue(info, data, user);  // unsubscribe() is switching the channel to the queue
    return;
  }
  const RunningCallback outer = std::exchange(running_callback(), RunningCallback{&channel->client, channel});
  try {
    callback(make_event(*info, data, channel->name));
  } catch (py::error_already_set& e) {
    e.discard_as_unraisable(callback);
  } catch (const std::exception& e) {  // e.g. out of memory while building the event
    PyErr_SetString(PyExc_RuntimeError, e.what());
    PyErr_WriteUnraisable(callback.ptr());
  }
  running_callback() = outer;
}

void bind_channel(py::module_& m) {
  using namespace py::literals;
  py::class_<Event>(m, "Event", "One event of a channel: a copy, safe to keep after the callback returned.")
      .def_readonly("payload", &Event::payload, "The event's bytes.")
      .def_readonly("subject", &Event::subject, "The channel's 64-bit subject.")
      .def_readonly("sequence", &Event::sequence, "Per publisher, counting from 1; 0 where the source has none (CAN).")
      .def_readonly("age_ns", &Event::age_ns, "Time in transit before the last gateway forwarded it, in nanoseconds.")
      .def_property_readonly(
          "age", [](const Event& e) { return static_cast<double>(e.age_ns) * 1e-9; }, "age_ns in seconds.")
      .def_readonly("channel", &Event::channel, "The channel's name.")
      .def("__repr__", [](const Event& e) {
        return "<cosmic.Event channel='" + e.channel + "' subject=" + std::to_string(e.subject) +
               " sequence=" + std::to_string(e.sequence) +
               " size=" + std::to_string(PyBytes_GET_SIZE(e.payload.ptr())) + ">";
      });

  py::class_<ChannelRef>(m, "Channel",
                         "An announced channel; returned by Client.announce(). Valid until its client is closed.")
      .def_property_readonly("name", [](const ChannelRef& c) { return c.channel->name; })
      .def_property_readonly(
          "payload", [](const ChannelRef& c) { return c.channel->payload; }, "Largest event in bytes.")
      .def_property_readonly(
          "roles", [](const ChannelRef& c) { return c.channel->roles; }, "PUBLISH | SUBSCRIBE bits.")
      .def_property_readonly("segment", [](const ChannelRef& c) { return c.client->segment(); })
      .def("publish", &publish, "data"_a, R"doc(
Publishes one event: bytes or any C-contiguous buffer-protocol object (bytearray, memoryview, a
numpy array), read in place without a copy; at most `payload` bytes. Returns True when sent,
False when the transport asks to try again (its queue is full). The GIL is released meanwhile.
Raises cosmic.TooLargeError, cosmic.InvalidError (a channel announced to subscribe only),
cosmic.TransportError, cosmic.ClosedError.)doc")
      .def("subscribe", &subscribe, "callback"_a, R"doc(
Calls callback(event) on the client's receive thread for every event, with the GIL taken, until
unsubscribe(), another subscribe() or the client's close() returns: each waits for a callback in
progress. Replaces the previous callback. An exception the callback raises goes to
sys.unraisablehook; the receive thread carries on. Keep callbacks short: they delay the next event.)doc")
      .def("unsubscribe", &unsubscribe, R"doc(
Stops the callback: when this returns it is not running (unless called from inside it) and is
never called again; later events are queued for get_event().)doc")
      .def("wait_ready", &wait_ready, "timeout"_a, R"doc(
Waits up to `timeout` seconds (rounded to whole milliseconds) until the channel is carried: on
DDS, until every announced role has a matched remote endpoint (publish: a reader, the gateway's or
another component's, matched this component's writer; subscribe: a writer matched its reader).
Events published before a reader matched are lost to it. Returns at once on LCM (no discovery)
and on CAN (announce already got the gateway's etag). Raises cosmic.NotReadyError (a TimeoutError)
naming the channel, the segment, the unmatched role(s) and the time waited; the channel stays
usable; cosmic.InvalidError for a negative timeout or a call from inside a callback. The GIL is
released meanwhile; Ctrl-C and close() from another thread take effect when it returns.)doc")
      .def("get_event", &get_event, "timeout"_a = 0.0, R"doc(
The oldest queued event, or None when none arrived within `timeout` seconds (0: do not wait, the
polling of a fixed-step loop; None: wait until one arrives). Events are queued while no callback
is subscribed; the newest 64 are kept. The GIL is released while waiting.)doc")
      .def("__repr__", [](const ChannelRef& c) {
        return "<cosmic.Channel '" + c.channel->name + "' on '" + c.client->segment() + "'" +
               (c.client->closed() ? " (closed)" : "") + ">";
      });
}

}  // namespace cosmic::python
