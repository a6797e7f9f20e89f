// One answer line of the control protocol as libcosmic-client reads it when a component checks its
// channel (cosmic_check_channel): whatever a gateway, or something posing as one, sends must give
// an error code or a verdict, never an exception or an abort (issue 22, item 7).
#include <cstdint>
#include <string>
#include <string_view>

#include "control_query.hpp"
#include "cosmic/client.h"
#include "fuzz_input.hpp"

using cosmic::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string out;
  const int rc =
      cosmic::client_detail::parse_verdict_answer(std::string_view(reinterpret_cast<const char*>(data), size), out);
  require(rc == COSMIC_OK || rc == COSMIC_E_UNAVAILABLE);
  require(!out.empty() || rc == COSMIC_OK);
  return 0;
}
