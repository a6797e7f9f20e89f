#include "adapter_factory.hpp"

#include <filesystem>

#include "cosmic/dds_adapter.hpp"
#include "cosmic/lcm_adapter.hpp"
#include "cosmic/replay_adapter.hpp"
#if COSMIC_HAS_CAN
#include "cosmic/can_adapter.hpp"
#endif

namespace cosmicd {

struct AdapterFactory::State {
#if COSMIC_HAS_CAN
  std::map<std::string, cosmic::CanSecocState> secoc;
#endif
};

AdapterFactory::AdapterFactory(std::string state_directory, WireTapSource taps)
    : state_directory_(std::move(state_directory)), taps_(std::move(taps)), state_(std::make_unique<State>()) {}

AdapterFactory::~AdapterFactory() = default;

std::unique_ptr<cosmic::SegmentAdapter> AdapterFactory::make(const cosmic::SegmentSpec& segment,
                                                             const cosmic::GatewayIdentity& self, cosmic::Logger& log) {
  switch (segment.type) {
    case cosmic::SegmentType::dds:
      return cosmic::make_dds_adapter(segment, self, log);
    case cosmic::SegmentType::lcm:
      return cosmic::make_lcm_adapter(segment, self, log);
    case cosmic::SegmentType::replay:
      return cosmic::make_replay_adapter(segment, log);
    case cosmic::SegmentType::can: {
#if COSMIC_HAS_CAN
      cosmic::CanSecocState& secoc = state_->secoc[segment.name];
      if (!secoc) {
        const auto file = std::filesystem::path(state_directory_) / ("secoc-" + segment.name + ".json");
        secoc = cosmic::make_can_secoc_state(file.string(), segment.name, log);
      }
      return cosmic::make_can_adapter(segment, self, log,
                                      cosmic::CanAdapterOptions{secoc, taps_ ? taps_(segment) : nullptr});
#else
      log.log(cosmic::LogLevel::error, "segment " + segment.name + ": this build has no CAN support");
      return nullptr;
#endif
    }
  }
  return nullptr;
}

}  // namespace cosmicd
