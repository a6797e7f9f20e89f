// Frames seen on a CAN bus at run time that admission did not know (issue 19, item 2): an
// unexplained identifier that wins arbitration over a bound HRT channel's frames makes that
// channel's response-time analysis invalid. Pure function, no I/O: the gateway's control thread
// calls it with its adapters' statistics.
#pragma once

#include <map>
#include <span>
#include <string>

#include "cosmic/admission.hpp"
#include "cosmic/segment_adapter.hpp"

namespace cosmic {

// For every HRT channel of `report` with a hop on `segment` whose identifier loses arbitration to
// one of `unexplained` (rate > 0): channel name -> the reason, with the numbers ("undeclared frame
// 0x0A0 at 100 Hz beats its identifier 0x1000C001 on body: its analysis did not count it").
std::map<std::string, std::string> undeclared_interference(const AdmissionReport& report, const std::string& segment,
                                                           std::span<const UnexplainedFrames> unexplained);

}  // namespace cosmic
