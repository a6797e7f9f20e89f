// Builds the adapter of a segment by its type. The only place that knows every transport.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "cosmic/gateway.hpp"
#include "cosmic/wire_tap.hpp"

namespace cosmicd {

// Owned by the daemon; make() is called on the control thread (start, reload).
class AdapterFactory {
 public:
  // The wire tap a segment's adapter is made with (cosmic/wire_tap.hpp), or null; called by make().
  using WireTapSource = std::function<std::shared_ptr<cosmic::WireTap>(const cosmic::SegmentSpec&)>;

  // `state_directory`: where adapters keep what must survive a restart (a CAN segment's SecOC
  // freshness counters: secoc-SEGMENT.json). `taps`: the adapters that offer a tap (CAN) get theirs
  // from it.
  explicit AdapterFactory(std::string state_directory, WireTapSource taps = {});
  ~AdapterFactory();

  std::unique_ptr<cosmic::SegmentAdapter> make(const cosmic::SegmentSpec& segment, const cosmic::GatewayIdentity& self,
                                               cosmic::Logger& log);

 private:
  struct State;
  std::string state_directory_;
  WireTapSource taps_;
  // A CAN segment's SecOC counters, one per segment name for the life of the process: an adapter
  // that replaces another on a reload continues them (cosmic/can_adapter.hpp).
  std::unique_ptr<State> state_;
};

}  // namespace cosmicd
