// Fast DDS's log -> the adapters' cosmic::Loggers (internal to the DDS adapter).
// Fast DDS logs through a process-wide singleton that prints to stdout by default. The first
// adapter replaces that with one consumer forwarding to the Loggers of the running adapters
// (each distinct Logger once): the library never prints.
#pragma once

#include "cosmic/log.hpp"

namespace cosmic::dds_detail {

// Threads: attach/detach on the control thread (start/stop); messages arrive on Fast DDS's log
// thread. A Logger must stay alive until detached.
void attach_fastdds_log(Logger& log);
void detach_fastdds_log(Logger& log);

}  // namespace cosmic::dds_detail
