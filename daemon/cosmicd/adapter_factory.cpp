#include "adapter_factory.hpp"

#include "cosmic/dds_adapter.hpp"
#include "cosmic/lcm_adapter.hpp"
#if COSMIC_HAS_CAN
#include "cosmic/can_adapter.hpp"
#endif

namespace cosmicd {

std::unique_ptr<cosmic::SegmentAdapter> make_adapter(const cosmic::SegmentSpec& segment,
                                                     const cosmic::GatewayIdentity& self, cosmic::Logger& log,
                                                     const std::string& state_directory) {
  switch (segment.type) {
    case cosmic::SegmentType::dds:
      return cosmic::make_dds_adapter(segment, self, log);
    case cosmic::SegmentType::lcm:
      return cosmic::make_lcm_adapter(segment, self, log);
    case cosmic::SegmentType::can:
#if COSMIC_HAS_CAN
      return cosmic::make_can_adapter(segment, self, log,
                                      cosmic::CanAdapterOptions{state_directory + "/secoc-" + segment.name + ".json"});
#else
      (void)state_directory;
      log.log(cosmic::LogLevel::error, "segment " + segment.name + ": this build has no CAN support");
      return nullptr;
#endif
  }
  return nullptr;
}

}  // namespace cosmicd
