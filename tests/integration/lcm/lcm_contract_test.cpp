// The adapter contract (tests/contract/adapter_contract.hpp) held against the LCM adapter on UDP
// multicast, in the network namespace the LCM suite runs in.
#include "../../contract/adapter_contract.hpp"
#include "cosmic/lcm_adapter.hpp"

namespace cosmic::contract {
namespace {

struct LcmTarget {
  static constexpr const char* kName = "lcm";
  std::unique_ptr<SegmentAdapter> make() {
    segment.lcm.url = "udpm://239.255.76.67:7667?ttl=0";
    return make_lcm_adapter(segment, self, log);
  }
  ChannelBinding binding(ChannelId id, const std::string& name, HopRole role) { return plain_binding(id, name, role); }
  // The first channel is carried raw on LCM channel POSE, which is the second channel's name.
  std::pair<ChannelBinding, ChannelBinding> colliding(ChannelId first, ChannelId second) {
    ChannelBinding native = binding(first, "pose", HopRole::subscriber);
    native.spec.native.push_back(NativeBinding{segment.name, std::nullopt, std::string("POSE"), std::nullopt});
    return {native, binding(second, "POSE", HopRole::subscriber)};
  }
  std::string collision_reason() { return "LCM channel 'POSE' is already bound"; }

  SegmentSpec segment = contract_segment("lcm0", SegmentType::lcm);
  GatewayIdentity self{0x5eed'0002ULL, "gw-contract"};
  QuietLogger log;
};

INSTANTIATE_TYPED_TEST_SUITE_P(contract, AdapterContract, LcmTarget, TargetName);

}  // namespace
}  // namespace cosmic::contract
