// The adapter contract (tests/contract/adapter_contract.hpp) held against the in-memory adapter
// the router and gateway tests stand on.
#include "../contract/adapter_contract.hpp"
#include "cosmic/memory_adapter.hpp"

namespace cosmic::contract {
namespace {

struct MemoryTarget {
  static constexpr const char* kName = "memory";
  std::unique_ptr<SegmentAdapter> make() {
    auto adapter = std::make_unique<MemoryAdapter>("mem");
    // The memory segment's own namespace is the test's word: it refuses what it is told to.
    adapter->refuse_channel("collides", "its name collides with channel first");
    return adapter;
  }
  ChannelBinding binding(ChannelId id, const std::string& name, HopRole role) { return plain_binding(id, name, role); }
  std::pair<ChannelBinding, ChannelBinding> colliding(ChannelId first, ChannelId second) {
    return {binding(first, "first", HopRole::subscriber), binding(second, "collides", HopRole::subscriber)};
  }
  std::string collision_reason() { return "collides with channel first"; }
};

INSTANTIATE_TYPED_TEST_SUITE_P(contract, AdapterContract, MemoryTarget, TargetName);

}  // namespace
}  // namespace cosmic::contract
