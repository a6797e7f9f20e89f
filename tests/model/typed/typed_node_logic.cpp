// The user's logic of typed_gen.yaml's component typed_node (gen_typed_test.sh puts it in place
// before generating: cosmicctl gen keeps it). It uses the typed API as a user would, so the
// skeleton's build proves the handlers take and give the generated structs.
#include "typed_node.hpp"

struct TypedNode::State {
  std::uint16_t last_dtc = 0;
  std::size_t plain_bytes = 0;
};

TypedNode::State* TypedNode::new_state() { return new State(); }
void TypedNode::destroy_state(State* state) { delete state; }

void TypedNode::refresh_diagnostics(const types::diagnostics::Event& event) {
  if (event.Dtc) state_->last_dtc = *event.Dtc;
  if (event.Ignition == types::diagnostics::Event::Ignition_::class_) state_->last_dtc = 0;
}

void TypedNode::refresh_plain(std::span<const std::uint8_t> event) { state_->plain_bytes += event.size(); }

void TypedNode::scan_period() {
  types::scan::Event event;
  event.distance = 1.5f;
  event.state = types::scan::Event::State::ON;
  event.label = "dtc";
  event.ranges.assign(types::scan::Event::ranges_max_size, 2.0f);
  event.pose.mode = types::scan::Event::Pose_::Mode::MOVING;
  event.track.push_back({0.5, {state_->last_dtc}});
  publish_scan(event);
}
