// The adapter contract (tests/contract/adapter_contract.hpp) held against the DDS adapter on
// Fast DDS, in the network namespace the DDS suite runs in.
#include "../../contract/adapter_contract.hpp"
#include "cosmic/dds_adapter.hpp"

namespace cosmic::contract {
namespace {

struct DdsTarget {
  static constexpr const char* kName = "dds";
  std::unique_ptr<SegmentAdapter> make() {
    segment.dds.domain = 7;
    return make_dds_adapter(segment, self, log);
  }
  ChannelBinding binding(ChannelId id, const std::string& name, HopRole role) { return plain_binding(id, name, role); }
  // '-' and '.' both become '_' in a topic name: both channels would be topic wheel_speed.
  std::pair<ChannelBinding, ChannelBinding> colliding(ChannelId first, ChannelId second) {
    return {binding(first, "wheel-speed", HopRole::subscriber), binding(second, "wheel.speed", HopRole::subscriber)};
  }
  std::string collision_reason() { return "both map to DDS topic"; }

  SegmentSpec segment = contract_segment("dds0", SegmentType::dds);
  GatewayIdentity self{0x5eed'0001ULL, "gw-contract"};
  QuietLogger log;
};

INSTANTIATE_TYPED_TEST_SUITE_P(contract, AdapterContract, DdsTarget, TargetName);

}  // namespace
}  // namespace cosmic::contract
