// The adapter contract (tests/contract/adapter_contract.hpp) held against the SocketCAN adapter on
// vcan0, inside scripts/can-vm with the rest of the CAN integration suite.
#include "../../contract/adapter_contract.hpp"
#include "can_test_support.hpp"
#include "cosmic/can_adapter.hpp"

namespace cosmic::contract {
namespace {

struct CanTarget {
  static constexpr const char* kName = "can";
  std::unique_ptr<SegmentAdapter> make() {
    EXPECT_EQ(test::shell("ip link set vcan0 up"), 0) << "needs vcan0: run through scripts/can-vm";
    return make_can_adapter(segment, self, log);
  }
  // Each channel its own etag, as admission plans them; a 4-byte payload is one frame.
  ChannelBinding binding(ChannelId id, const std::string& name, HopRole role) {
    return test::can_binding(id, name, 100 + id, 8, role, 20, static_cast<std::uint16_t>(200 + id), segment);
  }
  // Two channels planned on one etag: the bus cannot tell their frames apart.
  std::pair<ChannelBinding, ChannelBinding> colliding(ChannelId first, ChannelId second) {
    return {test::can_binding(first, "first", 100 + first, 8, HopRole::publisher, 20, 300, segment),
            test::can_binding(second, "second", 100 + second, 8, HopRole::publisher, 20, 300, segment)};
  }
  std::string collision_reason() { return "etag 300 bound twice as publisher"; }

  SegmentSpec segment = test::can_segment("vcan0");
  GatewayIdentity self{0x5eed'0003ULL, "gw-contract"};
  QuietLogger log;
};

INSTANTIATE_TYPED_TEST_SUITE_P(contract, AdapterContract, CanTarget, TargetName);

}  // namespace
}  // namespace cosmic::contract
