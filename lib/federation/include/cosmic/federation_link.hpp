// The transport of a federation (docs/federation.md): carries this gateway's encoded announcement
// to the other gateways and theirs, with whether each is still there, to it. The DDS implementation is
// make_dds_federation_link() (lib/adapters/dds); tests may use their own.
//
// Threads: start(), publish(), withdraw() and take() are called by the owner's one control thread;
// the implementation's own threads (DDS listeners) only queue messages for take().
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosmic/federation_view.hpp"

namespace cosmic {

struct FederationLinkCounters {
  std::uint64_t published = 0;  // announcements written
  std::uint64_t publish_errors = 0;
  std::uint64_t received = 0;  // messages queued for take()
  std::uint64_t dropped = 0;   // messages dropped because the queue was full (a flood)
};

class FederationLink {
 public:
  virtual ~FederationLink() = default;
  // Joins the federation; an error text when it cannot (nothing else works then).
  virtual std::string start() = 0;
  // Replaces this gateway's announcement (filed under `gateway`); false when the write failed.
  virtual bool publish(std::uint64_t gateway, const std::string& body) = 0;
  // Takes back this gateway's announcement (a clean leave: peers release its reservations now).
  virtual void withdraw() = 0;
  // Messages received since the last call, oldest first; at most one announcement per gateway
  // (the newest: a flood of revisions costs one decode per take()).
  virtual std::vector<FederationMessage> take() = 0;
  virtual FederationLinkCounters counters() const = 0;
};

}  // namespace cosmic
