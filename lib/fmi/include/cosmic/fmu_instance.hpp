// One instance of a co-simulation FMU's binary, loaded and driven through the FMI 2.0 or 3.0 C API
// (issue 38, docs/fmu.md): instantiate, set start values and parameters, initialize, step, read
// outputs, terminate. The binary is dlopen()ed from an FMU that open_fmu() extracted; nothing here
// knows of channels.
//
// Owns the loaded library and the FMU instance: the destructor terminates the instance (when it
// was initialized and has not failed), frees it and closes the library. Never throws; every call
// returns what the FMU answered. The FMU's log messages (its logger callback) are kept, the newest
// kMaxKeptLogLines, for the runner to show when a call fails.
//
// Threads: one thread drives an instance (the FMI standard allows no concurrent calls on one
// instance); the FMU may call the logger from that thread only, and recent_log() is read from it.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>

#include "cosmic/fmi_description.hpp"
#include "cosmic/fmi_values.hpp"
#include "cosmic/fmu_archive.hpp"
#include "cosmic/result.hpp"

namespace cosmic::fmi {

// One message the FMU gave its logger.
struct FmuLogLine {
  std::string status;    // "OK", "Warning", "Discard", "Error", "Fatal", "Pending"
  std::string category;  // as the FMU named it ("logStatusError", ...)
  std::string message;
};
inline constexpr std::size_t kMaxKeptLogLines = 32;
inline constexpr std::size_t kMaxLogLineBytes = 1024;

class FmuInstance {
 public:
  virtual ~FmuInstance() = default;
  FmuInstance(const FmuInstance&) = delete;
  FmuInstance& operator=(const FmuInstance&) = delete;

  // Sets a variable (before initialize(): parameters and start values; after it, inputs). The value
  // must be the variable's (VariableValue's alternative for its type).
  virtual Result<void> set(const Variable& variable, const VariableValue& value) = 0;
  virtual Result<VariableValue> get(const Variable& variable) = 0;
  // Initialization mode entered and left at `start_time` seconds (FMI 2.0: after SetupExperiment).
  virtual Result<void> initialize(double start_time) = 0;
  // One communication step from `time` over `step` seconds. An error names the call and the
  // status; the FMU's own messages are in recent_log().
  virtual Result<void> do_step(double time, double step) = 0;
  // Terminates the instance (once; the destructor does it when nobody did).
  virtual Result<void> terminate() = 0;
  // Whether the FMU asked to end the simulation (FMI 3.0 fmi3DoStep's terminateSimulation): the
  // step it asked in succeeded, and the importer terminates it and stops.
  bool ended() const { return ended_; }

  const std::deque<FmuLogLine>& recent_log() const { return log_; }
  // The kept messages as lines "[Error] logStatusError: ..." (for an error report).
  std::string recent_log_text() const;
  // Called by the FMU's logger callback (the version's own trampoline). The message is kept as
  // valid UTF-8 of at most kMaxLogLineBytes (an FMU may log Latin-1, or be cut inside a character):
  // other bytes become '?'. Never throws (it runs inside the FMU's C frames).
  void keep_log(FmuLogLine line) noexcept;

 protected:
  // "; the FMU said: <its last message>" (or that it logged nothing), for a failed call's error.
  std::string last_words() const;

  FmuInstance() = default;

 protected:
  void mark_ended() { ended_ = true; }

 private:
  std::deque<FmuLogLine> log_;
  bool ended_ = false;
};

struct InstanceOptions {
  std::string instance_name;  // shown in the FMU's own messages
  bool logging_on = true;     // the FMU's loggingOn: whether it sends its messages at all
};

// Loads `fmu.binary` (RTLD_NOW | RTLD_LOCAL), resolves the version's co-simulation functions and
// instantiates it with the FMU's resources. Errors: a library that does not load (dlerror), a
// missing function (named), an fmiGetVersion that is not the description's, an instantiation the
// FMU refused (with its log).
Result<std::unique_ptr<FmuInstance>> instantiate(const OpenedFmu& fmu, const InstanceOptions& options);

}  // namespace cosmic::fmi
