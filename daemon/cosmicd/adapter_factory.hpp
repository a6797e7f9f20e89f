// Builds the adapter of a segment by its type. The only place that knows every transport.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "cosmic/gateway.hpp"

namespace cosmicd {

// Owned by the daemon; make() is called on the control thread (start, reload).
class AdapterFactory {
 public:
  // `state_directory`: where adapters keep what must survive a restart (a CAN segment's SecOC
  // freshness counters: secoc-SEGMENT.json).
  explicit AdapterFactory(std::string state_directory);
  ~AdapterFactory();

  std::unique_ptr<cosmic::SegmentAdapter> make(const cosmic::SegmentSpec& segment, const cosmic::GatewayIdentity& self,
                                               cosmic::Logger& log);

 private:
  struct State;
  std::string state_directory_;
  // A CAN segment's SecOC counters, one per segment name for the life of the process: an adapter
  // that replaces another on a reload continues them (cosmic/can_adapter.hpp).
  std::unique_ptr<State> state_;
};

}  // namespace cosmicd
