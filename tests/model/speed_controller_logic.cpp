// The paper's speed controller (Kaiser et al., Fig. 8) filled into the skeleton that
// `cosmicctl gen config/robot.yaml --component speed_controller` generates. Speeds are 32-bit
// little-endian integers; an obstacle event is one byte, non-zero = obstacle ahead.
//
//   controlPeriod():  if (as != ns) publish(speedCh, ns);   (visualization subscribes
//                     actual_speed itself in config/robot.yaml, so visSpeedCh is not needed)
//   refresh_as(p_as): as = p_as;
//   refresh_ns(p_ns): if (!od) ns = p_ns; else ns = 0;
#include <cstring>

#include "speed_controller.hpp"

struct SpeedController::State {
  std::int32_t as = 0;  // actual speed
  std::int32_t ns = 0;  // nominal speed
  bool od = false;      // obstacle detected
};

SpeedController::State* SpeedController::new_state() { return new State(); }
void SpeedController::destroy_state(State* state) { delete state; }

namespace {
bool read_speed(std::span<const std::uint8_t> event, std::int32_t& out) {
  if (event.size() != sizeof out) return false;
  std::memcpy(&out, event.data(), sizeof out);
  return true;
}
}  // namespace

void SpeedController::refresh_actual_speed(std::span<const std::uint8_t> event) { read_speed(event, state_->as); }

void SpeedController::refresh_command(std::span<const std::uint8_t> event) {
  std::int32_t p_ns = 0;
  if (read_speed(event, p_ns)) state_->ns = state_->od ? 0 : p_ns;
}

void SpeedController::refresh_obstacle(std::span<const std::uint8_t> event) {
  if (!event.empty()) state_->od = event[0] != 0;
}

void SpeedController::speed_period() {
  if (state_->as == state_->ns) return;
  std::uint8_t bytes[sizeof state_->ns];
  std::memcpy(bytes, &state_->ns, sizeof bytes);
  publish_speed(bytes);
}
