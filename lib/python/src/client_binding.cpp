// cosmic.Client: one libcosmic-client client (cosmic_open) and the channels announced on it.
#include <pybind11/stl.h>

#include <algorithm>
#include <thread>

#include "cosmic/thread_policy.hpp"
#include "binding.hpp"
#include "channel_ref.hpp"

namespace cosmic::python {
namespace {

// The clients not yet closed, for close_all() at exit. Changed with the GIL held.
std::vector<ClientState*>& open_clients() {
  static std::vector<ClientState*> clients;
  return clients;
}

// cosmic_open() and cosmic_announce() return NULL without a code, only a reason; the reasons the
// library gives for bad input (tests/python check them) are told apart from the network's refusals.
int code_of_open_failure(const std::string& why) {
  const bool bad_text =
      why.find("is none of") != std::string::npos || why.find("unknown DDS option") != std::string::npos;
  return bad_text ? COSMIC_E_INVALID : COSMIC_E_TRANSPORT;
}

int code_of_announce_failure(const std::string& why) {
  if (why.rfind("a channel needs", 0) == 0) return COSMIC_E_INVALID;
  if (why.find("GET_ETAG") != std::string::npos) return COSMIC_E_UNBOUND;
  return COSMIC_E_TRANSPORT;
}

}  // namespace

RunningCallback& running_callback() {
  thread_local RunningCallback running;
  return running;
}

ClientState::ClientState(const std::string& segment) : segment_(segment) {
  char error[512] = "";
  {
    py::gil_scoped_release nogil;  // a DDS participant takes a while to start
    handle_ = cosmic_open(segment.c_str(), error, sizeof error);
  }
  if (!handle_) raise_error(code_of_open_failure(error), "cosmic_open('" + segment + "'): " + error);
  open_clients().push_back(this);
}

ClientState::~ClientState() {
  try {
    if (running_callback().client == this) {
      close_from_callback_thread();
    } else {
      close();
    }
  } catch (...) {  // a destructor must not throw; close() raises only from a callback, handled above
  }
}

void ClientState::close() {
  if (running_callback().client == this) {
    raise_error(COSMIC_E_INVALID,
                "close() from inside a callback of the same client (it would wait for itself); "
                "close it from another thread, or after the callback returned");
  }
  if (closed_.exchange(true)) return;
  for (auto& channel : channels_) {  // wake get_event() waiters: they see the client closed
    std::lock_guard lock(channel->queue_mutex);
    channel->queue_changed.notify_all();
  }
  {
    py::gil_scoped_release nogil;  // a callback in progress needs the GIL to finish
    wait_until_idle();
    cosmic_close(handle_);
  }
  handle_ = nullptr;
  for (auto& channel : channels_) channel->callback = py::object();  // no callback runs any more
  auto& clients = open_clients();
  clients.erase(std::remove(clients.begin(), clients.end(), this), clients.end());
}

// The last reference went inside one of our own callbacks, on the receive thread that
// cosmic_close() would join: another thread closes the client once the callback returned. The
// channels go with it (the running callback still uses its ChannelState).
void ClientState::close_from_callback_thread() {
  closed_ = true;
  for (auto& channel : channels_) {
    std::lock_guard lock(channel->queue_mutex);
    channel->queue_changed.notify_all();
    channel->callback = py::object();  // released here, with the GIL: the other thread has none
  }
  auto& clients = open_clients();
  clients.erase(std::remove(clients.begin(), clients.end(), this), clients.end());
  std::thread([handle = handle_, channels = std::move(channels_)]() mutable {
    apply_thread_policy(cosmic::ThreadPolicy{"cosmic-py-close", 0, 0, {}});
    cosmic_close(handle);
    channels.clear();
  }).detach();
  handle_ = nullptr;
}

void ClientState::close_all() {
  const auto clients = open_clients();  // close() edits the list
  for (ClientState* client : clients) {
    try {
      client->close();
    } catch (const py::error_already_set&) {
      PyErr_Clear();
    }
  }
}

void ClientState::wait_until_idle() {
  std::unique_lock lock(idle_mutex_);
  idle_.wait(lock, [this] { return busy_.load() == 0; });
}

std::string ClientState::last_error() const { return handle_ ? cosmic_last_error(handle_) : "the client is closed"; }

ChannelState& ClientState::add_channel(cosmic_channel* handle, std::string name, std::uint32_t payload, int roles) {
  channels_.push_back(std::make_unique<ChannelState>(*this, handle, std::move(name), payload, roles));
  return *channels_.back();
}

ClientState::Use::Use(ClientState& client, const char* what) : client_(client) {
  ++client_.busy_;
  if (client_.closed_) {
    --client_.busy_;  // the destructor does not run for a constructor that throws
    std::lock_guard lock(client_.idle_mutex_);
    client_.idle_.notify_all();
    raise_closed(std::string(what) + " on a closed client ('" + client_.segment_ + "')");
  }
}

ClientState::Use::~Use() {
  if (--client_.busy_ == 0 && client_.closed_) {
    std::lock_guard lock(client_.idle_mutex_);
    client_.idle_.notify_all();
  }
}

namespace {

ChannelRef announce(const std::shared_ptr<ClientState>& client, const std::string& name, std::uint64_t subject, int cls,
                    std::int64_t period_ns, std::int64_t reaction_time_ns, std::int64_t temp_validity_ns,
                    std::uint32_t omission_degree, std::uint32_t payload, int roles, int timeout_ms) {
  if (cls < COSMIC_HRT || cls > COSMIC_NRT) raise_error(COSMIC_E_INVALID, "class must be 0 (hrt), 1 (srt) or 2 (nrt)");
  ClientState::Use use(*client, "announce()");
  const cosmic_channel_desc desc{name.c_str(),    subject,          static_cast<cosmic_class>(cls),
                                 period_ns,       reaction_time_ns, temp_validity_ns,
                                 omission_degree, payload,          roles};
  cosmic_channel* handle = nullptr;
  {
    py::gil_scoped_release nogil;  // CAN waits up to timeout_ms for the gateway's etag
    handle = cosmic_announce(client->handle(), &desc, timeout_ms);
  }
  if (!handle) {
    const std::string why = client->last_error();
    raise_error(code_of_announce_failure(why), "announce('" + name + "') on '" + client->segment() + "': " + why);
  }
  ChannelState& channel = client->add_channel(handle, name, payload, roles);
  if (roles & COSMIC_SUBSCRIBE) {
    py::gil_scoped_release nogil;
    cosmic_subscribe(handle, deliver_to_queue, &channel);
    // What arrived between announce and subscribe waits in the library's own queue: moved over.
    QueuedEvent e;
    e.data.resize(payload);
    while (cosmic_get_event(handle, &e.info, e.data.data(), e.data.size()) == COSMIC_OK) {
      deliver_to_queue(&e.info, e.data.data(), &channel);
    }
  }
  return ChannelRef{client, &channel};
}

}  // namespace

void bind_client(py::module_& m) {
  using namespace py::literals;
  py::class_<ClientState, std::shared_ptr<ClientState>>(m, "Client", R"doc(
A component's attachment to one segment (cosmic_open). Use cosmic.Client, which adds announce()
and the context manager; this is its native base.)doc")
      .def(py::init<const std::string&>(), "segment"_a)
      .def("close", &ClientState::close, R"doc(
Stops the receive threads (waiting for a callback in progress) and frees the client and its
channels; later calls on them raise cosmic.ClosedError. Idempotent. Not from inside one of this
client's callbacks.)doc")
      .def_property_readonly("closed", &ClientState::closed)
      .def_property_readonly("segment", &ClientState::segment)
      .def("_announce", &announce, "name"_a, "subject"_a, "cls"_a, "period_ns"_a, "reaction_time_ns"_a,
           "temp_validity_ns"_a, "omission_degree"_a, "payload"_a, "roles"_a, "timeout_ms"_a);
  m.def("_close_all", &ClientState::close_all, "Closes every open client (atexit).");
}

}  // namespace cosmic::python
